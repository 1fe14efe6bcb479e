// gssm-process: the offline dataset processor. Reads a dataset folder, runs
// the chosen estimators in streaming order and writes estimates, metrics.json
// and a summary.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <functional>
#include <iostream>
#include <thread>
#include <sstream>
#include <unistd.h>

#include "cli.h"
#include "gssm/analysis/causal_map.h"
#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/io/point_errors_csv.h"
#include "gssm/io/process.h"
#include "plot_library.h"

namespace {

// --method: one name, or "all" (empty: every method, or with --resume the
// checkpoint's; "all" given with --resume asks for all, which is refused).
std::vector<gssm::Method> methodsAsked(const gssm::apps::CommandLine& cli) {
  if (cli.get("method") != "all") return {gssm::io::parseMethod(cli.get("method"), "option --method")};
  std::vector<gssm::Method> all;
  if (cli.given("method") && cli.given("resume"))
    for (const auto& info : gssm::methods()) all.push_back(info.method);
  return all;
}

gssm::io::ProcessOptions processOptions(const gssm::apps::CommandLine& cli) {
  gssm::io::ProcessOptions o;
  o.data_dir = cli.require("data");
  o.out_dir = cli.require("out");
  o.config = cli.get("config");
  o.methods = methodsAsked(cli);
  if (cli.given("window")) o.window = static_cast<int>(cli.getInt("window", 1, 1000000));
  if (cli.given("checkpoint-every"))
    o.checkpoint_every = static_cast<std::size_t>(cli.getInt("checkpoint-every", 1, 1000000000));
  o.resume = cli.given("resume") ? cli.get("resume") : "";
  o.skip_bad_rows = cli.given("skip-bad-rows");
  if (cli.given("learn")) o.learn = true;
  // Every core by default: the methods are independent (the output is the same).
  o.threads = cli.given("threads") ? static_cast<std::size_t>(cli.getInt("threads", 1, 256))
                                   : std::max(1u, std::thread::hardware_concurrency());
  return o;
}

// Progress on stderr, only when it is a terminal and the run is long; each
// method's final constants and summary on stdout as it finishes.
gssm::io::ProcessCallbacks consoleCallbacks() {
  gssm::io::ProcessCallbacks cb;
  if (isatty(STDERR_FILENO))
    cb.progress = [](gssm::Method m, std::size_t done, std::size_t total) {
      if (total < 20000) return;
      std::cerr << "\r" << gssm::methodName(m) << ": " << 100 * done / total << "% (" << done << "/" << total << ")"
                << (done == total ? "\n" : "") << std::flush;
    };
  cb.learnt = [](const gssm::NoiseLearningReport& r) { std::cout << r.toString(); };
  cb.skipped = [](const std::string& e) { std::cerr << "gssm-process: skipped " << e << "\n"; };
  cb.finished = [](const gssm::OfflineRun& run, const gssm::RunMetrics& m) {
    const auto& last = run.rows.back();
    std::ostringstream line;  // its own stream: the constants' fixed 3 decimals do not leak into the next time
    line << std::left << std::setw(7) << gssm::methodName(run.method) << " final (t = " << last.t << "):";
    line << std::fixed << std::setprecision(3);
    for (std::size_t i = 0; i < m.constant_names.size(); ++i) {
      const auto j = static_cast<Eigen::Index>(last.mean.size() - static_cast<Eigen::Index>(m.constant_names.size()) +
                                               static_cast<Eigen::Index>(i));
      line << "  " << m.constant_names[i] << " = " << last.mean[j] << " ± " << std::sqrt(last.covariance(j, j));
    }
    if (m.withheld.count)
      line << "\n        withheld fixes (" << m.withheld.count << "): horizontal RMS " << m.withheld.horizontal_rms
           << " m, max " << m.withheld.horizontal_max << " m; used fixes (" << m.used.count << "): horizontal RMS "
           << m.used.horizontal_rms << " m";
    std::cout << line.str() << "\n        " << run.summary << "\n";
  };
  return cb;
}

// --causal-map: at each withheld measurement, the batch MAP of the data
// at or before it (what an online smoother that relinearized everything
// at every step would give), into OUTDIR/causal-map.csv and one line.
void writeCausalMap(const gssm::io::ProcessResult& r, const gssm::io::ProcessOptions& o) {
  if (r.dataset.withheld.empty()) throw gssm::InputError("--causal-map: the dataset withholds nothing to score");
  gssm::EstimatorOptions options = gssm::io::estimatorOptions(r.config, *r.model);
  options.t0 = r.dataset.t0;
  const gssm::CausalMapErrors c =
      gssm::causalMapErrors(*r.model, options, r.dataset.measurements, r.dataset.inputs, r.dataset.withheld,
                            r.dataset.rows, static_cast<int>(o.threads));
  const std::string path = (std::filesystem::path(o.out_dir) / "causal-map.csv").string();
  gssm::io::writePointErrorsCsv(path, c.errors);
  const gssm::PointErrors s = gssm::summarizePointErrors(c.errors);
  std::cout << "causal MAP at " << s.count << " of " << r.dataset.withheld.size()
            << " withheld measurements: horizontal RMS " << s.horizontal_rms << " m, max " << s.horizontal_max
            << " m (" << path << ")\n";
  for (const auto& [t, why] : c.failed) std::cout << "  not solved at t = " << std::setprecision(17) << t << ": " << why << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  return gssm::apps::runApp("gssm-process", [&] {
    gssm::apps::CommandLine cli("gssm-process",
                                "Runs estimators over a dataset folder (measurements.csv, "
                                "scenario.ini, optional truth.csv) and writes "
                                "estimates-<method>.csv, metrics.json and figures to OUTDIR.");
    cli.option("data", "DIR", "dataset folder");
    cli.option("method", gssm::methodNameList() + ", or all", "estimator to run", "all");
    cli.option("window", "W", "states kept by fixed-lag and paper-window (overrides [fixed_lag] / [paper_window] window)");
    cli.option("config", "FILE", "INI file to use instead of DIR/scenario.ini");
    cli.option("out", "OUTDIR", "output folder");
    cli.option("checkpoint-every", "N",
               "streaming methods: write OUTDIR/checkpoint-<method>.ckpt every N measurements");
    cli.option("resume", "FILE",
               "continue the streaming run that wrote checkpoint FILE (its method, unless --method says "
               "the same); the output equals an uninterrupted run's");
    cli.flag("learn", "learn the noise from the log first ([learn] of the INI); writes OUTDIR/scenario.ini, learn.json");
    cli.flag("skip-bad-rows", "skip malformed measurement rows (listed in metrics.json) instead of stopping at the first");
    cli.option("threads", "N", "methods run at the same time (default: one per core; 1: one after another)");
    cli.flag("causal-map", "also solve the batch of the data up to each withheld measurement (the exact causal MAP, "
                           "an online method's optimum): OUTDIR/causal-map.csv; one solve each, slow");
    cli.parse(argc, argv);
    gssm::apps::PlotLibrary plot;  // loads while the dataset is read and run
    const gssm::io::ProcessOptions options = processOptions(cli);
    const gssm::io::ProcessResult r = gssm::io::processDataset(options, consoleCallbacks());
    if (r.status.late_rows > 0)
      std::cout << "gssm-process: " << r.status.late_rows << " measurement rows came after later ones (up to "
                << r.status.max_lateness << " s late): processed in time order\n";
    for (const auto& p : plot.functions().write_process_figures(r, options.out_dir, static_cast<int>(options.threads)))
      std::cout << "figure: " << p << "\n";
    std::cout << "gssm-process: wrote " << options.out_dir << "/metrics.json and estimates-*.csv\n";
    if (cli.given("causal-map")) writeCausalMap(r, options);
    if (r.status.partial) {
      // Everything before the bad row was processed and written; say where it stopped.
      std::cerr << "gssm-process: error: " << r.status.stopped_at << " (processed the "
                << r.dataset.measurements.size()
                << " rows before it; metrics.json is marked partial; --skip-bad-rows to go on)\n";
      return 3;
    }
    return 0;
  });
}
