// gssm-analyze: for a dataset's scenario, the Cramér–Rao bound, consistency,
// identifiability of the constants and whether the GSSM helps over the EKF;
// writes analysis.md and fig-bound-<state>.png (RMSE of every method over time
// against the bound).
#include <mrpt/random/RandomGenerators.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <thread>

#include "cli.h"
#include "gssm/analysis/scenario_analysis.h"
#include "gssm/io/config.h"
#include "gssm/io/dataset.h"
#include "gssm/plot/figure.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  return gssm::apps::runApp("gssm-analyze", [&] {
    gssm::apps::CommandLine cli("gssm-analyze",
                                "Analyzes a dataset's scenario (DIR as gssm-simulate writes it): Cramér–Rao "
                                "bound vs each estimator over RUNS simulated runs, consistency, identifiability "
                                "of the constants, and whether the GSSM improves on the EKF. Writes analysis.md "
                                "and figures to OUTDIR.");
    cli.option("data", "DIR", "dataset folder (scenario.ini, measurements.csv, truth.csv)");
    cli.option("runs", "S", "Monte Carlo runs", "50");
    cli.option("window", "W", "fixed-lag and paper-window length", "10");
    cli.option("out", "OUTDIR", "output folder");
    cli.parse(argc, argv);
    const std::string data = cli.require("data"), out = cli.require("out");
    const gssm::io::IniDocument scenario = gssm::io::readScenario(data);
    gssm::io::LoadedScenario loaded = gssm::io::loadScenario(scenario);
    if (!scenario.has("scenario", "name")) loaded.scenario.name = data;
    const int window = static_cast<int>(cli.getInt("window", 1, 100000));
    loaded.scenario.options.fixed_lag.window = loaded.scenario.options.paper_window.window = window;
    gssm::io::Dataset ds;
    gssm::io::readDatasetData(data, *loaded.truth, ds, gssm::io::BadRows::Throw, &scenario);
    gssm::MonteCarloOptions o;
    o.seeds = static_cast<int>(cli.getInt("runs", 2, 100000));
    o.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    o.first_seed = 1000;  // independent of the dataset's own seed
    const gssm::ScenarioAnalysis a = gssm::analyzeScenario(loaded.scenario, gssm::io::recordedRun(*loaded.truth, ds), o,
                                                           [](unsigned seed) {
      auto rng = std::make_shared<mrpt::random::CRandomGenerator>(seed);
      return gssm::NormalSampler([rng] { return rng->drawGaussian1D_normalized(); });
    });
    fs::create_directories(out);
    const std::string report = a.markdown();
    std::ofstream(fs::path(out) / "analysis.md") << report;
    std::cout << report;
    for (std::size_t i = 0; i < a.state_names.size(); ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      gssm::plot::Figure f;
      f.title = "RMSE of " + a.state_names[i] + " vs the Cramer-Rao bound (" + a.scenario + ")";
      f.xlabel = "time t (s)";
      f.ylabel = "RMSE / bound sd, " + a.state_names[i];
      for (std::size_t m = 0; m < a.montecarlo.methods.size(); ++m) {
        const auto& ms = a.montecarlo.methods[m];
        gssm::plot::Series s{gssm::methodName(ms.method), ms.times, {}, gssm::plot::paletteColor(m), 2, false};
        for (const auto& v : ms.rmse_over_time) s.y.push_back(v[ii]);
        f.series.push_back(std::move(s));
      }
      gssm::plot::Series fb{"filtering bound", {}, {}, {0, 0, 0}, 2, true};
      gssm::plot::Series sb{"smoothing bound", {}, {}, {120, 120, 120}, 1, true};
      for (std::size_t k = 0; k < a.bound.times.size(); ++k) {
        if (a.bound.filtering[k].size()) {
          fb.x.push_back(a.bound.times[k]);
          fb.y.push_back(std::sqrt(a.bound.filtering[k](ii, ii)));
        }
        sb.x.push_back(a.bound.times[k]);
        sb.y.push_back(std::sqrt(a.bound.smoothing[k](ii, ii)));
      }
      f.series.push_back(std::move(fb));
      f.series.push_back(std::move(sb));
      const std::string path = (fs::path(out) / ("fig-bound-" + a.state_names[i] + ".png")).string();
      gssm::plot::savePng(f, path);
      std::cout << "figure: " << path << "\n";
    }
    return 0;
  });
}
