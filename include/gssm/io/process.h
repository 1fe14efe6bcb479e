#pragma once
// The offline dataset processor as a library call (what gssm-process and
// gssm.process run): a dataset folder in, every chosen estimator run in
// streaming order, estimates-<method>.csv and metrics.json written, the
// runs and their metrics returned. Figures are the caller's (gssm::plot).
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gssm/analysis/metrics.h"
#include "gssm/analysis/offline.h"
#include "gssm/estimator/method.h"
#include "gssm/io/dataset.h"
#include "gssm/io/ini.h"
#include "gssm/io/metrics_json.h"
#include "gssm/learn/noise_learning.h"

namespace gssm::io {

struct ProcessOptions {
  std::string data_dir;           ///< the dataset folder
  std::string out_dir;            ///< where the files go (created)
  std::string config;             ///< an INI file to use instead of data_dir/scenario.ini
  /// The methods to run, in order; empty: every method, or with `resume`
  /// alone the checkpoint's.
  std::vector<Method> methods;
  std::optional<int> window;      ///< fixed-lag and paper-window states (overrides the INI)
  std::size_t checkpoint_every = 0;  ///< streaming methods: a checkpoint every N measurements (0: none)
  std::string resume;             ///< continue the run that wrote this checkpoint
  bool skip_bad_rows = false;     ///< skip malformed measurement rows instead of stopping at the first
  /// Learn the noise first (true), or not (false), whatever [learn] enabled
  /// says; unset: as [learn] enabled says. The learnt scenario.ini and
  /// learn.json go to out_dir, and every method runs on the learnt model.
  std::optional<bool> learn;
  /// Methods run at the same time (each on its own thread; the slowest, the
  /// paper window, started first). 1: one after another. The estimates and
  /// metrics are the same either way; per-update latencies share the cores.
  /// Progress callbacks are then called from the worker threads, one at a
  /// time; `finished` after all have run, in the methods' order.
  std::size_t threads = 1;
  /// Empty when usable; otherwise says which field is wrong.
  bool validate(std::string* why = nullptr) const;
};

struct ProcessResult {
  std::shared_ptr<const Model> model;
  IniDocument config;              ///< the scenario.ini used
  Dataset dataset;
  DatasetStatus status;            ///< rows skipped, or where a bad row stopped it (partial)
  /// The noise learning, when it ran (config and model are then the learnt ones).
  std::optional<NoiseLearningReport> learnt;
  /// The batch's own noise ([learn] batch_likelihood_spacing), when learnt;
  /// it runs with `[batch.section]` over `[section]` (IniDocument::overriddenBy).
  std::optional<NoiseLearningReport> learnt_batch;
  std::vector<OfflineRun> runs;    ///< one per method, in order
  std::vector<RunMetrics> metrics; ///< of each run
  /// Rows at inputs on a model with px, py: the EKF on the inputs alone.
  std::optional<OfflineRun> dead_reckoning;
  std::string label;               ///< [scenario] name, or the folder's name
  std::string metrics_json;        ///< the text of metrics.json
  std::vector<std::string> files;  ///< what was written
};

struct ProcessCallbacks {
  /// Before each method: (method, measurements); then every 1% (done, total).
  std::function<void(Method, std::size_t done, std::size_t total)> progress;
  /// After each method's run, with its metrics.
  std::function<void(const OfflineRun&, const RunMetrics&)> finished;
  /// After the noise learning, when it ran (before the first method).
  std::function<void(const NoiseLearningReport&)> learnt;
  /// A skipped row (skip_bad_rows).
  std::function<void(const std::string&)> skipped;
};

/// Runs options.methods over options.data_dir into options.out_dir. Throws
/// InvalidArgument for bad options, InputError (file:line:column) for a bad
/// dataset with nothing before the first bad row, CheckpointError for a
/// checkpoint that cannot be resumed. A bad row after good ones stops the
/// run there (status.partial) unless skip_bad_rows: what came before is
/// processed and written.
ProcessResult processDataset(const ProcessOptions& options, const ProcessCallbacks& callbacks = {});

}  // namespace gssm::io
