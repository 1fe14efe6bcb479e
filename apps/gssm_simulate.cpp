// gssm-simulate: writes a dataset folder for a built-in scenario, with MRPT's
// seeded random generator (same seed, same bytes).
#include <mrpt/random/RandomGenerators.h>

#include <iostream>

#include "cli.h"
#include "gssm/io/config.h"
#include "gssm/io/dataset.h"

int main(int argc, char** argv) {
  return gssm::apps::runApp("gssm-simulate", [&] {
    gssm::apps::CommandLine cli("gssm-simulate",
                                "Simulates a built-in scenario and writes measurements.csv, "
                                "truth.csv and scenario.ini to a dataset folder.");
    std::string names;
    for (const auto& n : gssm::io::scenarioNames()) names += (names.empty() ? "" : "|") + n;
    cli.option("scenario", names, "scenario to simulate", "paper");
    cli.option("seed", "S", "random seed (same seed, same files)", "1");
    cli.option("steps", "N", "number of measurement steps", "400");
    cli.option("out", "DIR", "dataset folder to write");
    cli.parse(argc, argv);
    const auto seed = static_cast<unsigned>(cli.getInt("seed", 0, 4294967295LL));
    const int steps = static_cast<int>(cli.getInt("steps", 1, 100000000));
    const std::string out = cli.require("out");

    const gssm::io::IniDocument scenario =
        gssm::io::builtinScenario(cli.get("scenario"), seed, steps);
    const auto model = gssm::io::makeModel(scenario);
    mrpt::random::CRandomGenerator rng(seed);
    const gssm::SimulatedRun run =
        gssm::simulate(*model, gssm::io::simulationSpec(scenario, *model),
                       [&rng] { return rng.drawGaussian1D_normalized(); });
    gssm::io::writeDataset(out, *model, run, scenario);
    std::cout << "gssm-simulate: scenario '" << cli.get("scenario") << "', seed " << seed << ", "
              << steps << " steps -> " << out << "\n";
    return 0;
  });
}
