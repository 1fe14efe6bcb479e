#include "gssm/analysis/offline.h"

#include <algorithm>
#include <chrono>
#include <limits>

#include "core/byte_stream.h"
#include "gssm/checkpoint/checkpoint.h"
#include "gssm/core/error.h"
#include "gssm/factors/problem.h"

namespace gssm {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
}  // namespace

namespace {
// The variables of a stacked estimate: x_c at its step and, if any, x_b.
Values stateValues(const Model& model, const StateEstimate& e) {
  Values x;
  x.insert(Key::state(e.step), e.mean.head(model.dims().nc));
  if (model.dims().nb > 0) x.insert(Key::constants(), e.mean.tail(model.dims().nb));
  return x;
}

// A checkpoint's user data: where the run is and its counters, then the
// recorder's mark (v3; v1/v2 held every row inline and are refused with a
// message: the run is restarted).
constexpr const char* kRunTag = "gssm offline run v3";

// Fingerprint of the measurements a checkpoint has consumed (folded in one
// at a time), so a run is not resumed on another dataset.
std::uint64_t foldMeasurement(std::uint64_t h, const Measurement& m) {
  h = internal::fnv1a64(reinterpret_cast<const char*>(&m.t), sizeof m.t, h);
  if (m.channel != 0) h = internal::fnv1a64(reinterpret_cast<const char*>(&m.channel), sizeof m.channel, h);
  return internal::fnv1a64(reinterpret_cast<const char*>(m.y.data()),
                           static_cast<std::size_t>(m.y.size()) * sizeof(double), h);
}

struct RunProgress {
  std::size_t next_measurement = 0, next_input = 0;
  std::uint64_t data_fingerprint = 0;
  bool row_due = false;
};

std::string encodeRun(const OfflineRun& run, const RunProgress& p, const std::string& mark) {
  internal::ByteWriter w;
  w.str(kRunTag);
  w.str(methodName(run.method));
  w.u64(p.next_measurement);
  w.u64(p.next_input);
  w.u64(p.data_fingerprint);
  w.boolean(p.row_due);
  w.u64(run.downweighted);
  w.i64(run.rejected);
  w.i32(run.iterations);
  w.f64(run.total_seconds);
  w.str(mark);
  return w.bytes();
}

OfflineRun decodeRun(const std::string& bytes, const std::string& source, RunProgress& p, std::string& mark) {
  internal::ByteReader r(bytes, source + " (run progress)");
  const std::string tag = r.str("run tag");
  if (tag == "gssm offline run v1" || tag == "gssm offline run v2")
    r.fail("written by an older gssm-process (" + tag + ", every row inline); start the run again");
  if (tag != kRunTag) r.fail("not the checkpoint of an offline run (gssm-process)");
  OfflineRun run;
  const std::string method = r.str("method");
  if (!methodNamed(method)) r.fail("unknown method '" + method + "'");
  run.method = *methodNamed(method);
  p.next_measurement = r.u64("measurements consumed");
  p.next_input = r.u64("inputs consumed");
  p.data_fingerprint = r.u64("data fingerprint");
  p.row_due = r.boolean("row due");
  run.downweighted = r.u64("down-weighted count");
  run.rejected = r.i64("gated count");
  run.iterations = r.i32("iterations");
  run.total_seconds = r.f64("seconds");
  mark = r.str("recorder mark");
  if (!r.atEnd()) r.fail("unexpected bytes after the run progress");
  return run;
}

// The recorder of a run without one: its mark is every record so far.
class InlineRecorder final : public RunRecorder {
 public:
  explicit InlineRecorder(const OfflineRun& run) : run_(run) {}
  void row(const EstimateRow&) override {}
  void update(double, std::optional<double>) override {}
  std::string mark() override {
    internal::ByteWriter w;
    w.u64(run_.rows.size());
    for (const auto& r : run_.rows) {
      w.f64(r.t);
      w.vec(r.mean);
      w.mat(r.covariance);
    }
    w.u64(run_.update_seconds.size());
    for (double s : run_.update_seconds) w.f64(s);
    w.u64(run_.nis.size());
    for (double v : run_.nis) w.f64(v);
    return w.bytes();
  }
  void resume(const std::string& mark, OfflineRun& run) override {
    internal::ByteReader r(mark, "checkpoint (rows)");
    run.rows.resize(r.count("rows", 24));
    for (auto& row : run.rows) {
      row.t = r.f64("row time");
      row.mean = r.vec("row mean");
      row.covariance = r.mat("row covariance");
    }
    run.update_seconds.resize(r.count("latencies", 8));
    for (double& s : run.update_seconds) s = r.f64("latency");
    run.nis.resize(r.count("NIS values", 8));
    for (double& v : run.nis) v = r.f64("NIS", true);
    if (!r.atEnd()) r.fail("unexpected bytes after the rows");
  }

 private:
  const OfflineRun& run_;
};
}  // namespace

OfflineRun runStreaming(const Model& model, const EstimatorOptions& options,
                        const std::vector<Measurement>& measurements,
                        const std::vector<Input>& inputs,
                        const std::function<void(std::size_t, std::size_t)>& progress,
                        const StreamingCheckpoints& checkpoints, RowTimes rows) {
  if (!checkpoints.path.empty() && checkpoints.every == 0)
    throw InvalidArgument("runStreaming: a checkpoint path needs checkpoints.every >= 1");
  OfflineRun out;
  out.method = options.method;
  const std::size_t every = std::max<std::size_t>(1, measurements.size() / 100);
  const auto start = Clock::now();
  InlineRecorder inline_recorder(out);
  RunRecorder& recorder = checkpoints.recorder ? *checkpoints.recorder : inline_recorder;
  std::unique_ptr<Estimator> est;
  RunProgress at;  // where the run is (what a checkpoint stores)
  at.data_fingerprint = internal::kFnv1a64Basis;
  double seconds_before = 0;
  if (!checkpoints.resume_from.empty()) {
    CheckpointInfo info;
    est = restoreCheckpoint(model, checkpoints.resume_from, &info);
    RunProgress saved;
    std::string mark;
    out = decodeRun(info.user_data, checkpoints.resume_from, saved, mark);
    const auto fail = [&](const std::string& why) {
      throw CheckpointError(checkpoints.resume_from + ": cannot resume this run: " + why);
    };
    if (info.method != options.method || out.method != options.method)
      fail(std::string("it was written by method '") + methodName(info.method) + "', this run is '" +
           methodName(options.method) + "'");
    if (est->report().window != options.window())
      fail("it was written with window " + std::to_string(est->report().window) + ", this run asks for " +
           std::to_string(options.window()));
    if (saved.next_measurement <= measurements.size())
      for (std::size_t i = 0; i < saved.next_measurement; ++i)
        at.data_fingerprint = foldMeasurement(at.data_fingerprint, measurements[i]);
    if (saved.next_measurement > measurements.size() || saved.next_input > inputs.size() ||
        at.data_fingerprint != saved.data_fingerprint)
      fail("its first " + std::to_string(saved.next_measurement) +
           " measurements differ from this dataset's (another dataset?)");
    recorder.resume(mark, out);
    if (out.update_seconds.size() != saved.next_measurement)
      fail("its records hold " + std::to_string(out.update_seconds.size()) + " updates, its progress says " +
           std::to_string(saved.next_measurement));
    at = saved;
    seconds_before = out.total_seconds;
  } else {
    est = makeEstimator(model, options);
  }
  out.rows.reserve(measurements.size());
  out.update_seconds.reserve(measurements.size());
  // Events in time order: an input at t makes the state at t (when after
  // the newest), a measurement at t attaches to it or makes it. With rows
  // at inputs, the row of a state an input made is taken just before the
  // first later event, so it holds every measurement at its time.
  const bool at_inputs = rows == RowTimes::Inputs;
  // The recorder gets the records at each checkpoint and at the end, not
  // inside the loop: writing output files is not the estimator's time (left
  // out of total_seconds) and costs the loop nothing.
  double recording = 0;
  std::size_t rows_sent = out.rows.size(), updates_sent = out.update_seconds.size();  // resumed: already there
  const auto sendRecords = [&] {
    for (; rows_sent < out.rows.size(); ++rows_sent) recorder.row(out.rows[rows_sent]);
    for (; updates_sent < out.update_seconds.size(); ++updates_sent)
      recorder.update(out.update_seconds[updates_sent],
                      options.compute_nis ? std::optional<double>(out.nis[updates_sent]) : std::nullopt);
  };
  const auto addRow = [&](const StateEstimate& e) { out.rows.push_back({e.t, e.mean, e.covariance}); };
  // at.row_due, with rows at inputs: the newest state, made by an input, has no row yet.
  auto feedInputsBefore = [&](double t) {
    for (; at.next_input < inputs.size() && inputs[at.next_input].t < t; ++at.next_input) {
      const double ti = std::max(inputs[at.next_input].t, est->time());
      if (at_inputs && at.row_due && ti > est->time()) addRow(est->current());
      const bool advances = ti > est->time();
      est->addInput(ti, inputs[at.next_input].u);
      if (at_inputs && advances) at.row_due = true;
    }
  };
  for (std::size_t i = at.next_measurement; i < measurements.size(); ++i) {
    const Measurement& m = measurements[i];
    feedInputsBefore(m.t);
    if (at_inputs && at.row_due && m.t > est->time()) {
      addRow(est->current());
      at.row_due = false;
    }
    const auto t0 = Clock::now();
    est->addMeasurement(m);
    const double seconds = since(t0);
    out.update_seconds.push_back(seconds);
    at.data_fingerprint = foldMeasurement(at.data_fingerprint, m);
    if (options.compute_nis) out.nis.push_back(est->reportNumbers().nis);
    // The EKF gates instead of weighting; the others' weight is the
    // measurement factor's own, at the estimate after its update.
    const bool weigh = model.channel(m.channel).loss.robust() && options.method != Method::Ekf;
    if (!at_inputs || weigh) {
      const StateEstimate e = est->current();
      if (!at_inputs) addRow(e);
      if (weigh && MeasurementFactor(model, e.step, m).weight(stateValues(model, e)) < 1.0) ++out.downweighted;
    }
    out.rejected = est->reportNumbers().rejected;  // not report(): formatting its line costs ~15% of an EKF update
    out.iterations = std::max(out.iterations, est->reportNumbers().iterations);
    if (progress && ((i + 1) % every == 0 || i + 1 == measurements.size())) progress(i + 1, measurements.size());
    if (!checkpoints.path.empty() && (i + 1) % checkpoints.every == 0) {
      const auto c0 = Clock::now();
      at.next_measurement = i + 1;
      out.total_seconds = seconds_before + since(start) - recording;
      // The records first: a checkpoint never points past what is durable.
      sendRecords();
      const std::string mark = recorder.mark();
      saveCheckpoint(*est, checkpoints.path, encodeRun(out, at, mark));
      recording += since(c0);
    }
  }
  feedInputsBefore(std::numeric_limits<double>::infinity());  // inputs after the last measurement
  if (at_inputs && at.row_due) addRow(est->current());
  out.total_seconds = seconds_before + since(start) - recording;
  sendRecords();
  out.summary = est->report().detail;
  return out;
}

OfflineRun runBatch(const Model& model, const EstimatorOptions& options,
                    const std::vector<Measurement>& measurements,
                    const std::vector<Input>& inputs, RowTimes rows) {
  OfflineRun out;
  out.method = Method::Batch;
  const auto start = Clock::now();
  Problem p = buildProblem(model, measurements, inputs, options.t0);
  Values x = ekfInitialGuess(model, ExtendedKalmanFilterOptions{}, measurements, inputs, options.t0);
  BatchSolver solver(options.batch);
  const BatchSolverSummary sum = solver.solve(p.graph, x);
  out.iterations = sum.iterations;
  out.summary = sum.toString();
  out.update_seconds.push_back(sum.seconds);
  const int nc = model.dims().nc, nb = model.dims().nb;
  for (const auto& f : p.graph)
    if (f->loss().robust() && f->weight(x) < 1.0) ++out.downweighted;
  // One row per measurement time (states between measurements, made by
  // inputs, have no row), as the streaming runs report; or one per input time.
  std::size_t mi = 0, ii = 0;
  for (std::size_t k = 1; k < p.times.size(); ++k) {
    if (rows == RowTimes::Inputs) {
      while (ii < inputs.size() && inputs[ii].t < p.times[k]) ++ii;
      if (ii >= inputs.size() || inputs[ii].t != p.times[k]) continue;
    } else {
      if (mi >= measurements.size() || measurements[mi].t != p.times[k]) continue;
      while (mi < measurements.size() && measurements[mi].t == p.times[k]) ++mi;
    }
    const Key key = Key::state(static_cast<std::int64_t>(k));
    EstimateRow row;
    row.t = p.times[k];
    row.mean.resize(nc + nb);
    row.mean.head(nc) = x.at(key);
    if (nb) row.mean.tail(nb) = x.at(Key::constants());
    row.mean = model.wrapStacked(std::move(row.mean));
    row.covariance = solver.jointMarginalCovariance(stackedKeys(model, key.step));
    out.rows.push_back(std::move(row));
  }
  out.total_seconds = since(start);
  return out;
}

OfflineRun runOffline(const Model& model, const EstimatorOptions& options,
                      const std::vector<Measurement>& measurements, const std::vector<Input>& inputs,
                      const std::function<void(std::size_t, std::size_t)>& progress,
                      const StreamingCheckpoints& checkpoints, RowTimes rows) {
  if (methodInfo(options.method).streaming)
    return runStreaming(model, options, measurements, inputs, progress, checkpoints, rows);
  if (!checkpoints.path.empty() || !checkpoints.resume_from.empty())
    throw InvalidArgument(std::string("runOffline: checkpoints apply to streaming methods, not '") +
                          methodName(options.method) + "'");
  return runBatch(model, options, measurements, inputs, rows);
}

}  // namespace gssm
