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
#include <unistd.h>

#include "cli.h"
#include "gssm/checkpoint/checkpoint.h"
#include "gssm/io/config.h"
#include "gssm/io/csv.h"
#include "gssm/io/dataset.h"
#include "gssm/io/metrics_json.h"
#include "gssm/io/run_files.h"
#include "gssm/analysis/metrics.h"
#include "gssm/plot/run_figures.h"

namespace fs = std::filesystem;

namespace {

// A run resumed into another output folder continues the files its
// checkpoint's folder holds: copied here first (the checkpoint records how
// far they got; RunFiles cuts them there).
void continueOutputsIn(const std::string& out, const std::string& checkpoint, gssm::Method method) {
  const fs::path from = fs::absolute(checkpoint).parent_path();
  if (fs::equivalent(from, fs::absolute(out))) return;
  for (const auto& name : {gssm::io::RunFiles::estimatesName(method), gssm::io::RunFiles::recordsName(method)}) {
    if (!fs::exists(from / name))
      throw std::runtime_error(checkpoint + ": cannot resume: " + (from / name).string() +
                               " (the output written up to the checkpoint) is missing");
    fs::copy_file(from / name, fs::path(out) / name, fs::copy_options::overwrite_existing);
  }
}

}  // namespace

int main(int argc, char** argv) {
  return gssm::apps::runApp("gssm-process", [&] {
    gssm::apps::CommandLine cli("gssm-process",
                                "Runs estimators over a dataset folder (measurements.csv, "
                                "scenario.ini, optional truth.csv) and writes "
                                "estimates-<method>.csv and metrics.json to OUTDIR.");
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
    cli.flag("skip-bad-rows", "skip malformed measurement rows (listed in metrics.json) instead of stopping at the first");
    cli.parse(argc, argv);
    const std::string data = cli.require("data"), out = cli.require("out");
    const std::string resume = cli.given("resume") ? cli.get("resume") : "";
    std::vector<gssm::Method> methods;  // empty with --resume alone: the checkpoint's
    if (cli.get("method") == "all" && (resume.empty() || cli.given("method"))) {
      for (const auto& info : gssm::methods()) methods.push_back(info.method);
    } else if (cli.given("method") || resume.empty()) {
      methods = {gssm::io::parseMethod(cli.get("method"), "option --method")};
    }

    const gssm::io::IniDocument config = gssm::io::readScenario(data, cli.get("config"));
    const auto model = gssm::io::makeModel(config, data);
    if (!resume.empty()) {
      gssm::CheckpointInfo info;
      gssm::restoreCheckpoint(*model, resume, &info);  // throws a clear error if unusable
      if (methods.empty()) methods = {info.method};
      if (methods.size() != 1 || !gssm::methodInfo(methods[0]).streaming)
        throw std::invalid_argument(std::string("option --resume: resumes one streaming method; the checkpoint's is '") +
                                    gssm::methodName(info.method) + "'");
      if (methods[0] != info.method)
        throw std::invalid_argument(resume + ": cannot resume this run: it was written by method '" +
                                    gssm::methodName(info.method) + "', this run is '" +
                                    gssm::methodName(methods[0]) + "'");
    }
    const std::size_t checkpoint_every =
        cli.given("checkpoint-every") ? static_cast<std::size_t>(cli.getInt("checkpoint-every", 1, 1000000000)) : 0;
    gssm::io::Dataset ds;
    const bool skip = cli.given("skip-bad-rows");
    gssm::io::readDatasetData(data, *model, ds, skip ? gssm::io::BadRows::Skip : gssm::io::BadRows::Stop, &config);
    gssm::io::DatasetStatus status;
    if (skip) status.skipped = ds.row_errors;
    else if (!ds.row_errors.empty()) status = {true, ds.row_errors.front(), {}};
    for (const auto& e : status.skipped) std::cerr << "gssm-process: skipped " << e << "\n";
    if (ds.measurements.empty()) throw std::runtime_error(status.partial ? status.stopped_at : "no measurements");
    fs::create_directories(out);

    // Progress on stderr, only when it is a terminal and the run is long.
    const bool tty = isatty(STDERR_FILENO) && ds.measurements.size() >= 20000;
    auto progress = [tty](const std::string& m) -> std::function<void(std::size_t, std::size_t)> {
      if (!tty) return {};
      return [m](std::size_t done, std::size_t total) {
        std::cerr << "\r" << m << ": " << 100 * done / total << "% (" << done << "/" << total << ")"
                  << (done == total ? "\n" : "") << std::flush;
      };
    };
    std::vector<gssm::RunMetrics> metrics;
    std::vector<gssm::OfflineRun> runs;
    gssm::EstimatorOptions options = gssm::io::estimatorOptions(config, *model);
    options.t0 = ds.t0;
    const gssm::RowTimes rows = ds.rows_at_inputs ? gssm::RowTimes::Inputs : gssm::RowTimes::Measurements;
    if (cli.given("window"))
      options.fixed_lag.window = options.paper_window.window = static_cast<int>(cli.getInt("window", 1, 1000000));
    for (const gssm::Method method : methods) {
      options.method = method;
      const std::string m = gssm::methodName(method);
      const bool streaming = gssm::methodInfo(method).streaming;
      // Estimates are written as the run goes; with checkpoints also the
      // records the metrics need, so that a checkpoint holds only the
      // estimator and how far these files got.
      gssm::io::RunFiles files(out, *model, method, streaming && (checkpoint_every > 0 || !resume.empty()));
      gssm::StreamingCheckpoints checkpoints;
      if (streaming) {
        checkpoints = {checkpoint_every ? (fs::path(out) / ("checkpoint-" + m + ".ckpt")).string() : "",
                       checkpoint_every, resume, &files};
        if (!resume.empty()) continueOutputsIn(out, resume, method);
      }
      gssm::OfflineRun run =
          gssm::runOffline(*model, options, ds.measurements, ds.inputs, progress(m), checkpoints, rows);
      if (!streaming)
        for (const auto& r : run.rows) files.row(r);
      files.finish();
      metrics.push_back(gssm::computeMetrics(*model, run, ds.truth ? &*ds.truth : nullptr));
      const auto& last = run.rows.back();
      std::cout << std::left << std::setw(7) << m << " final (t = " << last.t << "):";
      const auto names = model->stackedStateNames();
      for (std::size_t i = model->dims().nc; i < names.size(); ++i) {
        const auto j = static_cast<Eigen::Index>(i);
        std::cout << "  " << names[i] << " = " << std::fixed << std::setprecision(3) << last.mean[j]
                  << " ± " << std::sqrt(last.covariance(j, j)) << std::defaultfloat;
      }
      std::cout << "\n        " << run.summary << "\n";
      runs.push_back(std::move(run));
    }
    std::ofstream((fs::path(out) / "metrics.json").string()) << gssm::io::metricsJson(metrics, data, status);
    const std::string label = config.getString("scenario", "name", fs::path(data).filename().string());
    std::optional<gssm::plot::PlanView> plan;
    const auto names = model->stackedStateNames();
    const auto px = std::find(names.begin(), names.end(), "px"), py = std::find(names.begin(), names.end(), "py");
    if (px != names.end() && py != names.end()) {
      plan = gssm::plot::PlanView{px - names.begin(), py - names.begin(), model->landmarks(), "beacons", {}};
      if (rows == gssm::RowTimes::Inputs) {  // dead reckoning: the filter with no measurements
        gssm::EstimatorOptions dr = options;
        dr.method = gssm::Method::Ekf;
        const gssm::OfflineRun odo = gssm::runOffline(*model, dr, {}, ds.inputs, {}, {}, rows);
        std::vector<Eigen::Vector2d> path;
        for (const auto& r : odo.rows) path.emplace_back(r.mean[plan->x], r.mean[plan->y]);
        plan->paths.emplace_back("dead reckoning", std::move(path));
      }
    }
    for (const auto& p : gssm::plot::writeRunFigures(*model, runs, ds.truth ? &*ds.truth : nullptr, out, label, plan))
      std::cout << "figure: " << p << "\n";
    std::cout << "gssm-process: wrote " << out << "/metrics.json and estimates-*.csv\n";
    if (status.partial) {
      // Everything before the bad row was processed and written; say where it stopped.
      std::cerr << "gssm-process: error: " << status.stopped_at << " (processed the " << ds.measurements.size()
                << " rows before it; metrics.json is marked partial; --skip-bad-rows to go on)\n";
      return 3;
    }
    return 0;
  });
}
