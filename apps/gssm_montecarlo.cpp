// gssm-montecarlo: runs a scenario over many seeds with every estimator, in
// parallel, and writes a Markdown table and RMSE-over-time plots.
#include <mrpt/random/RandomGenerators.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <thread>

#include "cli.h"
#include "gssm/io/config.h"
#include "gssm/analysis/montecarlo.h"
#include "gssm/plot/figure.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  return gssm::apps::runApp("gssm-montecarlo", [&] {
    gssm::apps::CommandLine cli("gssm-montecarlo",
                                "Simulates a scenario over S seeds, runs every estimator on each, and "
                                "writes montecarlo.md and fig-mc-rmse-<state>.png to OUTDIR.");
    cli.option("scenario", "paper|consistent", "built-in scenario", "paper");
    cli.option("seeds", "S", "number of seeds", "100");
    cli.option("first-seed", "N", "first seed", "1");
    cli.option("steps", "N", "steps per run", "400");
    cli.option("window", "W", "fixed-lag and paper-window length", "10");
    cli.option("threads", "T", "worker threads", std::to_string(std::max(1u, std::thread::hardware_concurrency())));
    cli.option("out", "OUTDIR", "output folder");
    cli.parse(argc, argv);
    const std::string out = cli.require("out");
    gssm::MonteCarloOptions o;
    o.seeds = static_cast<int>(cli.getInt("seeds", 1, 1000000));
    o.first_seed = static_cast<unsigned>(cli.getInt("first-seed", 0, 4000000000LL));
    const int window = static_cast<int>(cli.getInt("window", 1, 100000));
    o.threads = static_cast<int>(cli.getInt("threads", 1, 256));
    const int steps = static_cast<int>(cli.getInt("steps", 1, 10000000));
    gssm::io::LoadedScenario loaded =
        gssm::io::loadScenario(gssm::io::builtinScenario(cli.get("scenario"), o.first_seed, steps));
    loaded.scenario.options.fixed_lag.window = loaded.scenario.options.paper_window.window = window;
    const bool tty = isatty(STDERR_FILENO);
    std::mutex io;
    o.progress = [&](int done, int total) {
      std::lock_guard<std::mutex> lock(io);
      if (tty) {
        const int w = 40, filled = w * done / total;
        std::cerr << "\r[" << std::string(static_cast<std::size_t>(filled), '#')
                  << std::string(static_cast<std::size_t>(w - filled), ' ') << "] " << done << "/" << total
                  << (done == total ? "\n" : "") << std::flush;
      }
    };
    const gssm::MonteCarloResult res = gssm::runMonteCarlo(loaded.scenario, o, [](unsigned seed) {
      auto rng = std::make_shared<mrpt::random::CRandomGenerator>(seed);
      return gssm::NormalSampler([rng] { return rng->drawGaussian1D_normalized(); });
    });
    fs::create_directories(out);
    const std::string table = res.markdown();
    std::ofstream(fs::path(out) / "montecarlo.md")
        << "# Monte Carlo: " << res.scenario << "\n\nCommand: `gssm-montecarlo --scenario " << cli.get("scenario")
        << " --seeds " << o.seeds << " --steps " << steps << " --window " << window << "`\n\n" << table;
    std::cout << table << "\n(" << res.seconds << " s)\n";
    for (std::size_t i = 0; i < res.state_names.size(); ++i) {
      gssm::plot::Figure f;
      f.title = "RMSE of " + res.state_names[i] + " over " + std::to_string(res.seeds) + " seeds (" + res.scenario + ")";
      f.xlabel = "time t (s)";
      f.ylabel = "RMSE " + res.state_names[i];
      for (std::size_t m = 0; m < res.methods.size(); ++m) {
        const auto& ms = res.methods[m];
        gssm::plot::Series s{gssm::methodName(ms.method), ms.times, {}, gssm::plot::paletteColor(m), 2,
                             !gssm::methodInfo(ms.method).streaming};
        for (const auto& v : ms.rmse_over_time) s.y.push_back(v[static_cast<Eigen::Index>(i)]);
        f.series.push_back(std::move(s));
      }
      const std::string path = (fs::path(out) / ("fig-mc-rmse-" + res.state_names[i] + ".png")).string();
      gssm::plot::savePng(f, path);
      std::cout << "figure: " << path << "\n";
    }
    return 0;
  });
}
