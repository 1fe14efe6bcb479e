#include "gssm/io/process.h"

#include <algorithm>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <numeric>
#include <sstream>

#include "gssm/checkpoint/checkpoint.h"
#include "gssm/core/error.h"
#include "gssm/core/parallel.h"
#include "gssm/io/config.h"
#include "gssm/io/learn_config.h"
#include "gssm/io/point_errors_csv.h"
#include "gssm/io/run_files.h"
#include "gssm/io/track_pos.h"

namespace gssm::io {

namespace fs = std::filesystem;

bool ProcessOptions::validate(std::string* why) const {
  auto fail = [&](const std::string& w) {
    if (why) *why = "process: " + w;
    return false;
  };
  if (data_dir.empty()) return fail("no dataset folder (data_dir)");
  if (out_dir.empty()) return fail("no output folder (out_dir)");
  if (window && (*window < 1 || *window > 1000000)) return fail("window = " + std::to_string(*window) + ": expected 1..10^6");
  if (checkpoint_every > 1000000000) return fail("checkpoint_every is out of range");
  if (threads < 1 || threads > 256) return fail("threads = " + std::to_string(threads) + ": expected 1..256");
  return true;
}

namespace {
// A run resumed into another output folder continues the files its
// checkpoint's folder holds: copied here first (the checkpoint records how
// far they got; RunFiles cuts them there).
void continueOutputsIn(const std::string& out, const std::string& checkpoint, Method method) {
  const fs::path from = fs::absolute(checkpoint).parent_path();
  if (fs::equivalent(from, fs::absolute(out))) return;
  for (const auto& name : {RunFiles::estimatesName(method), RunFiles::recordsName(method)}) {
    if (!fs::exists(from / name))
      throw CheckpointError(checkpoint + ": cannot resume: " + (from / name).string() +
                            " (the output written up to the checkpoint) is missing");
    fs::copy_file(from / name, fs::path(out) / name, fs::copy_options::overwrite_existing);
  }
}

// The methods to run: as asked, or every one; with resume, the checkpoint's
// one streaming method.
// Every method, or those [scenario] methods names (a scenario whose model a
// method cannot run says so there, with why).
std::vector<Method> allMethods(const IniDocument& config) {
  std::vector<Method> methods;
  if (!config.has("scenario", "methods")) {
    for (const auto& info : gssm::methods()) methods.push_back(info.method);
    return methods;
  }
  std::istringstream words(config.getString("scenario", "methods"));
  for (std::string w; words >> w;) {
    const std::optional<Method> m = methodNamed(w);
    if (!m)
      throw InputError(config.where("scenario", "methods") + ": '" + w + "' is not a method (" + methodNameList() + ")");
    methods.push_back(*m);
  }
  if (methods.empty()) throw InputError(config.where("scenario", "methods") + ": names no method");
  return methods;
}

std::vector<Method> methodsToRun(const ProcessOptions& o, const Model& model, const IniDocument& config) {
  std::vector<Method> methods = o.methods;
  if (methods.empty() && o.resume.empty()) methods = allMethods(config);
  if (o.resume.empty()) return methods;
  CheckpointInfo info;
  restoreCheckpoint(model, o.resume, &info);  // throws a clear error if unusable
  if (methods.empty()) methods = {info.method};
  if (methods.size() != 1 || !methodInfo(methods[0]).streaming)
    throw InvalidArgument(std::string("resume: resumes one streaming method; the checkpoint's is '") +
                          methodName(info.method) + "'");
  if (methods[0] != info.method)
    throw CheckpointError(o.resume + ": cannot resume this run: it was written by method '" +
                          methodName(info.method) + "', this run is '" + methodName(methods[0]) + "'");
  return methods;
}

// The dataset, and what its bad rows did (skipped, or stopped the reading).
void readData(const ProcessOptions& o, const Model& model, ProcessResult& r, const ProcessCallbacks& cb) {
  readDatasetData(o.data_dir, model, r.dataset, o.skip_bad_rows ? BadRows::Skip : BadRows::Stop, &r.config);
  if (o.skip_bad_rows) r.status.skipped = r.dataset.row_errors;
  else if (!r.dataset.row_errors.empty()) r.status = {true, r.dataset.row_errors.front(), {}};
  r.status.late_rows = r.dataset.late_rows;
  r.status.max_lateness = r.dataset.max_lateness;
  // Non-physical values the dataset drops by its own rule: skipped, listed.
  r.status.skipped.insert(r.status.skipped.end(), r.dataset.dropped.begin(), r.dataset.dropped.end());
  if (cb.skipped)
    for (const auto& e : r.status.skipped) cb.skipped(e);
  if (r.dataset.measurements.empty())
    throw InputError(r.status.partial ? r.status.stopped_at : o.data_dir + ": no measurements");
}

// What a method runs with: the scenario's model and options, or for a
// method with its own values ([<method>.<section>]) those made from the
// scenario as it reads it; the batch's own noise ([learn]
// batch_likelihood_spacing) is learnt in its job, beside the other methods.
struct MethodSetup {
  std::shared_ptr<const Model> model;
  EstimatorOptions options;
  /// Where a batch starts: learning's last E-step (a batch solve under σ
  /// within the learning tolerance), when it ran one; null: the EKF pass.
  /// It may point into `learnt`: the setups are complete before any job
  /// runs and are not moved while they run.
  const Values* start = nullptr;
  std::optional<NoiseLearningOptions> own_noise;  ///< learnt first with these, into `learnt`
  std::optional<LearnResult> learnt;
};

EstimatorOptions runOptions(const ProcessOptions& o, const ProcessResult& r, const IniDocument& config,
                            const Model& model) {
  EstimatorOptions options = estimatorOptions(config, model);
  options.t0 = r.dataset.t0;
  if (o.window) options.fixed_lag.window = options.paper_window.window = *o.window;
  // The batch linearizes on every thread even beside the other methods: the
  // OS shares the cores while they run, and its second half takes the core
  // they leave (the drive: its batch is the last to finish, 0.89x the
  // methods' wall time). The same bits on one thread or two.
  options.batch.threads = static_cast<int>(o.threads);
  return options;
}

// A method's own values change the model's numbers, not its states or
// channels: the dataset was read for the scenario's model (a channel's
// regressors, the rows' layout), and the methods' outputs are compared.
void requireSameStructure(const Model& own, const Model& shared, const std::string& method) {
  const auto layout = [](const Model& m) {
    std::vector<int> v{m.dims().nc, m.dims().nb, m.dims().nu, m.dims().ny};
    for (int c = 0; c < m.numChannels(); ++c) v.push_back(m.channel(c).dim()), v.push_back(m.channel(c).regressors);
    return v;
  };
  if (layout(own) != layout(shared))
    throw InputError("[" + method + ".*]: a method's own values may change the model's numbers, not its states or "
                     "channels (with them " + method + "'s model has " + std::to_string(own.dims().nb) +
                     " constants and " + std::to_string(own.dims().nc) + " states, the scenario's " +
                     std::to_string(shared.dims().nb) + " and " + std::to_string(shared.dims().nc) +
                     ", or its channels differ)");
}

// Every method's own values ([<method>.<section>]) checked before anything
// runs, whether its method runs or not: a misspelt section, or values
// that change the model's structure, refused.
void checkMethodOverrides(const IniDocument& config, const Model& shared, const std::string& data_dir) {
  for (const auto& info : gssm::methods()) {
    const std::string name = methodName(info.method);
    if (config.hasOverrides(name)) requireSameStructure(*makeModel(config.overriddenBy(name), data_dir), shared, name);
  }
}

// Their structure was checked before the run (checkMethodOverrides).
std::vector<MethodSetup> methodSetups(const ProcessOptions& o, const ProcessResult& r, const std::vector<Method>& methods,
                                      const std::optional<NoiseLearningOptions>& batch_noise) {
  std::vector<MethodSetup> setups;
  for (const Method method : methods) {
    const std::string name = methodName(method);
    MethodSetup m{r.model, {}, r.learnt && !r.learnt->posterior.empty() ? &r.learnt->posterior : nullptr, {}, {}};
    const bool own = r.config.hasOverrides(name);
    const IniDocument config = own ? r.config.overriddenBy(name) : r.config;
    if (own) m.model = makeModel(config, o.data_dir);
    m.options = runOptions(o, r, config, *m.model);
    if (method == Method::Batch && batch_noise) m.own_noise = batch_noise, m.start = nullptr;
    setups.push_back(std::move(m));
  }
  return setups;
}

// The batch's own noise, learnt from the scenario as learnt for the others
// (OUT/scenario.ini gets its [batch.<section>]); the setup then runs it.
void learnOwnNoise(const ProcessOptions& o, const ProcessResult& r, MethodSetup& m) {
  if (!m.own_noise) return;
  m.learnt = learnBatchNoiseAndWrite(r.config, r.dataset, o.out_dir, *m.own_noise);
  m.model = m.learnt->report.model;
  m.options = runOptions(o, r, m.learnt->config.overriddenBy(methodName(Method::Batch)), *m.model);
  m.start = m.learnt->report.posterior.empty() ? nullptr : &m.learnt->report.posterior;
}

// One method's run, its estimates written as it goes (with checkpoints, the
// records the metrics need too).
OfflineRun runMethod(const ProcessOptions& o, const MethodSetup& setup, const ProcessResult& r, Method method,
                     const ProcessCallbacks& cb) {
  const Model& model = *setup.model;
  EstimatorOptions options = setup.options;
  options.method = method;
  const bool streaming = methodInfo(method).streaming;
  RunFiles files(o.out_dir, model, method, streaming && (o.checkpoint_every > 0 || !o.resume.empty()));
  StreamingCheckpoints checkpoints;
  if (streaming) {
    checkpoints = {o.checkpoint_every
                       ? (fs::path(o.out_dir) / ("checkpoint-" + std::string(methodName(method)) + ".ckpt")).string()
                       : "",
                   o.checkpoint_every, o.resume, &files};
    if (!o.resume.empty()) continueOutputsIn(o.out_dir, o.resume, method);
  }
  std::function<void(std::size_t, std::size_t)> progress;
  if (cb.progress) progress = [&cb, method](std::size_t done, std::size_t total) { cb.progress(method, done, total); };
  OfflineRun run = runOffline(model, options, r.dataset.measurements, r.dataset.inputs, progress, checkpoints,
                              r.dataset.rows, setup.start);
  if (!streaming)
    for (const auto& row : run.rows) files.row(row);
  files.finish();
  return run;
}

// A run's last constants, in the reference's terms, against the reference.
void compareToReference(const Model& model, const ProcessResult& r, const OfflineRun& run, RunMetrics& m) {
  const int nb = model.dims().nb;
  const EstimateRow& last = run.rows.back();
  const Gaussian xb{last.mean.tail(nb), last.covariance.bottomRightCorner(nb, nb)};
  const Gaussian compared = r.dataset.truth ? model.comparableConstants(xb, *r.dataset.truth) : xb;
  compareConstants(m, *r.dataset.constants_reference, &compared);
}

// Errors at the withheld measurements (inside a log's GNSS outages) and at
// the used ones of their channel (outside).
void scoreWithheld(const Model& model, const Dataset& d, const OfflineRun& run, RunMetrics& m) {
  m.withheld_errors = predictionErrorSeries(model, run, d.inputs, d.withheld);
  m.withheld = summarizePointErrors(m.withheld_errors);
  m.used = predictionErrors(model, run, d.inputs, usedOnWithheldChannel(d));
}

// A method's run and its metrics (against the reference too, if any).
struct MeasuredRun {
  OfflineRun run;
  RunMetrics metrics;
};
MeasuredRun runAndMeasure(const ProcessOptions& o, MethodSetup& setup, const ProcessResult& r, Method method,
                          const ProcessCallbacks& cb) {
  learnOwnNoise(o, r, setup);
  const Model& model = *setup.model;
  MeasuredRun m{runMethod(o, setup, r, method, cb), {}};
  m.metrics = computeMetrics(model, m.run, r.dataset.truth ? &*r.dataset.truth : nullptr);
  if (r.dataset.constants_reference) compareToReference(model, r, m.run, m.metrics);
  if (!r.dataset.withheld.empty()) scoreWithheld(model, r.dataset, m.run, m.metrics);
  return m;
}

// Every method's run and metrics, `threads` at a time, the costliest first
// (MethodInfo::cost_rank: the cheap ones fill in at the end); a job that
// learns its own noise first (the batch's) runs a learning's filter passes
// before its run, and goes before the rest (the drive: started third, its
// job was the last to end by 1 s). A method that throws lets the others
// finish; the first error, in the methods' order, is rethrown.
std::vector<MeasuredRun> runConcurrently(const ProcessOptions& o, std::vector<MethodSetup>& setups,
                                         const ProcessResult& r, const std::vector<Method>& methods,
                                         const ProcessCallbacks& cb) {
  std::vector<std::size_t> queue(methods.size());
  std::iota(queue.begin(), queue.end(), std::size_t{0});
  const auto cost = [&](std::size_t k) {
    return std::make_pair(setups[k].own_noise.has_value(), methodInfo(methods[k]).cost_rank);
  };
  std::stable_sort(queue.begin(), queue.end(), [&](std::size_t a, std::size_t b) { return cost(a) > cost(b); });
  std::mutex mutex;
  ProcessCallbacks serialized = cb;
  if (cb.progress)
    serialized.progress = [&](Method m, std::size_t done, std::size_t total) {
      const std::lock_guard<std::mutex> lock(mutex);
      cb.progress(m, done, total);
    };
  std::vector<MeasuredRun> runs(methods.size());
  std::vector<std::exception_ptr> errors(methods.size());
  const auto failed = runJobs(queue.size(), o.threads, [&](std::size_t k) {
    runs[queue[k]] = runAndMeasure(o, setups[queue[k]], r, methods[queue[k]], serialized);
  });
  for (std::size_t k = 0; k < queue.size(); ++k) errors[queue[k]] = failed[k];  // back in the methods' order
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
  return runs;
}

// Rows at inputs on a planar model: the filter with no measurements.
std::optional<OfflineRun> deadReckoning(const Model& model, const ProcessResult& r, EstimatorOptions options) {
  const auto names = model.stackedStateNames();
  const bool planar = std::count(names.begin(), names.end(), "px") && std::count(names.begin(), names.end(), "py");
  if (!planar || r.dataset.rows != RowTimes::Inputs) return std::nullopt;
  options.method = Method::Ekf;
  return runOffline(model, options, {}, r.dataset.inputs, {}, {}, RowTimes::Inputs);
}
}  // namespace

ProcessResult processDataset(const ProcessOptions& o, const ProcessCallbacks& cb) {
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument(why);
  ProcessResult r;
  r.config = readScenario(o.data_dir, o.config);
  std::shared_ptr<const Model> model(makeModel(r.config, o.data_dir));
  r.model = model;
  const std::vector<Method> methods = methodsToRun(o, *model, r.config);
  checkMethodOverrides(r.config, *model, o.data_dir);
  readData(o, *model, r, cb);
  std::optional<NoiseLearningOptions> batch_noise;  // learnt in the batch's job, beside the other methods
  if (LearnSettings learn = learnSettings(r.config); o.learn.value_or(learn.enabled)) {
    // learning runs alone: its passes and batch solves may use every thread
    learn.options.threads = learn.options.batch.threads = static_cast<int>(o.threads);
    batch_noise = batchNoiseOptions(learn);
    learn.batch_likelihood_spacing.reset();
    LearnResult learnt = learnScenarioNoise(*model, r.config, r.dataset, o.out_dir, learn);
    r.config = std::move(learnt.config);
    model = r.model = learnt.report.model;
    r.files.insert(r.files.end(), learnt.files.begin(), learnt.files.end());
    r.learnt = std::move(learnt.report);
    if (cb.learnt) cb.learnt(*r.learnt);
  }
  fs::create_directories(o.out_dir);
  std::vector<MethodSetup> setups = methodSetups(o, r, methods, batch_noise);
  std::vector<MeasuredRun> concurrent;
  if (o.threads > 1 && methods.size() > 1) concurrent = runConcurrently(o, setups, r, methods, cb);
  for (std::size_t i = 0; i < methods.size(); ++i) {
    const Method method = methods[i];
    MeasuredRun m = concurrent.empty() ? runAndMeasure(o, setups[i], r, method, cb) : std::move(concurrent[i]);
    if (setups[i].learnt) {  // the batch's own noise: OUT/scenario.ini holds it now
      r.config = setups[i].learnt->config;
      r.files.push_back(setups[i].learnt->files.back());
      r.learnt_batch = setups[i].learnt->report;
      if (cb.learnt) cb.learnt(*r.learnt_batch);
    }
    r.runs.push_back(std::move(m.run));
    r.metrics.push_back(std::move(m.metrics));
    r.files.push_back((fs::path(o.out_dir) / RunFiles::estimatesName(method)).string());
    if (!r.metrics.back().withheld_errors.empty()) {  // each withheld measurement's error, to score any part
      r.files.push_back((fs::path(o.out_dir) / ("withheld-" + std::string(methodName(method)) + ".csv")).string());
      writePointErrorsCsv(r.files.back(), r.metrics.back().withheld_errors);
    }
    if (method == Method::Batch && reportsGeodeticTrack(*model)) {  // the smoothed track, for RTKPLOT
      r.files.push_back((fs::path(o.out_dir) / "track-batch.pos").string());
      writeTrackPos(r.files.back(), *model, r.runs.back());
    }
    if (cb.finished) cb.finished(r.runs.back(), r.metrics.back());
  }
  const std::string json = (fs::path(o.out_dir) / "metrics.json").string();
  r.metrics_json = metricsJson(r.metrics, o.data_dir, r.status);
  std::ofstream(json) << r.metrics_json;
  r.files.push_back(json);
  r.label = r.config.getString("scenario", "name", fs::path(o.data_dir).filename().string());
  EstimatorOptions options = estimatorOptions(r.config, *model);
  options.t0 = r.dataset.t0;
  r.dead_reckoning = deadReckoning(*model, r, options);
  return r;
}

}  // namespace gssm::io
