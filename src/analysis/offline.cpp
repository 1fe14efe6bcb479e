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

// The run so far, stored as a checkpoint's user data.
// v2 adds whether a row is due, the down-weighted and gated counts.
constexpr const char* kRunTag = "gssm offline run v2";

// Fingerprint of the measurements a checkpoint has consumed (folded in one
// at a time), so a run is not resumed on another dataset.
std::uint64_t foldMeasurement(std::uint64_t h, const Measurement& m) {
  h = internal::fnv1a64(reinterpret_cast<const char*>(&m.t), sizeof m.t, h);
  if (m.channel != 0) h = internal::fnv1a64(reinterpret_cast<const char*>(&m.channel), sizeof m.channel, h);
  return internal::fnv1a64(reinterpret_cast<const char*>(m.y.data()),
                           static_cast<std::size_t>(m.y.size()) * sizeof(double), h);
}

std::string encodeRun(const OfflineRun& run, std::size_t next_measurement, std::size_t next_input,
                      std::uint64_t data_fingerprint, bool row_due) {
  internal::ByteWriter w;
  w.str(kRunTag);
  w.boolean(row_due);
  w.u64(run.downweighted);
  w.i64(run.rejected);
  w.u64(data_fingerprint);
  w.str(methodName(run.method));
  w.u64(next_measurement);
  w.u64(next_input);
  w.i32(run.iterations);
  w.f64(run.total_seconds);
  w.u64(run.rows.size());
  for (const auto& r : run.rows) {
    w.f64(r.t);
    w.vec(r.mean);
    w.mat(r.covariance);
  }
  w.u64(run.update_seconds.size());
  for (double s : run.update_seconds) w.f64(s);
  w.u64(run.nis.size());
  for (double v : run.nis) w.f64(v);
  return w.bytes();
}

OfflineRun decodeRun(const std::string& bytes, const std::string& source, std::size_t& next_measurement,
                     std::size_t& next_input, std::uint64_t& data_fingerprint, bool& row_due) {
  internal::ByteReader r(bytes, source + " (run progress)");
  const std::string tag = r.str("run tag");
  if (tag != kRunTag && tag != "gssm offline run v1") r.fail("not the checkpoint of an offline run (gssm-process)");
  OfflineRun run;
  row_due = false;
  if (tag == kRunTag) {
    row_due = r.boolean("row due");
    run.downweighted = r.u64("down-weighted count");
    run.rejected = r.i64("gated count");
  }
  data_fingerprint = r.u64("data fingerprint");
  const std::string method = r.str("method");
  if (!methodNamed(method)) r.fail("unknown method '" + method + "'");
  run.method = *methodNamed(method);
  next_measurement = r.u64("measurements consumed");
  next_input = r.u64("inputs consumed");
  run.iterations = r.i32("iterations");
  run.total_seconds = r.f64("seconds");
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
  if (!r.atEnd()) r.fail("unexpected bytes after the run progress");
  if (run.update_seconds.size() != next_measurement) r.fail("latency count does not match the measurements consumed");
  return run;
}
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
  std::unique_ptr<Estimator> est;
  std::size_t first = 0, next_input = 0;
  bool row_due = false;  // rows at inputs: the newest state, made by an input, has no row yet
  std::uint64_t data_hash = internal::kFnv1a64Basis;
  double seconds_before = 0;
  if (!checkpoints.resume_from.empty()) {
    CheckpointInfo info;
    est = restoreCheckpoint(model, checkpoints.resume_from, &info);
    std::uint64_t fingerprint = 0;
    out = decodeRun(info.user_data, checkpoints.resume_from, first, next_input, fingerprint, row_due);
    const auto fail = [&](const std::string& why) {
      throw CheckpointError(checkpoints.resume_from + ": cannot resume this run: " + why);
    };
    if (info.method != options.method || out.method != options.method)
      fail(std::string("it was written by method '") + methodName(info.method) + "', this run is '" +
           methodName(options.method) + "'");
    if (est->report().window != options.window())
      fail("it was written with window " + std::to_string(est->report().window) + ", this run asks for " +
           std::to_string(options.window()));
    if (first <= measurements.size())
      for (std::size_t i = 0; i < first; ++i) data_hash = foldMeasurement(data_hash, measurements[i]);
    if (first > measurements.size() || next_input > inputs.size() || data_hash != fingerprint)
      fail("its first " + std::to_string(first) + " measurements differ from this dataset's (another dataset?)");
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
  const auto record = [&] {
    const StateEstimate e = est->current();
    out.rows.push_back({e.t, e.mean, e.covariance});
  };
  auto feedInputsBefore = [&](double t) {
    for (; next_input < inputs.size() && inputs[next_input].t < t; ++next_input) {
      const double ti = std::max(inputs[next_input].t, est->time());
      if (at_inputs && row_due && ti > est->time()) record();
      const bool advances = ti > est->time();
      est->addInput(ti, inputs[next_input].u);
      if (at_inputs && advances) row_due = true;
    }
  };
  for (std::size_t i = first; i < measurements.size(); ++i) {
    const Measurement& m = measurements[i];
    feedInputsBefore(m.t);
    if (at_inputs && row_due && m.t > est->time()) {
      record();
      row_due = false;
    }
    const auto t0 = Clock::now();
    est->addMeasurement(m);
    out.update_seconds.push_back(since(t0));
    data_hash = foldMeasurement(data_hash, m);
    if (options.compute_nis) out.nis.push_back(est->reportNumbers().nis);
    // The EKF gates instead of weighting; the others' weight is the
    // measurement factor's own, at the estimate after its update.
    const bool weigh = model.channel(m.channel).loss.robust() && options.method != Method::Ekf;
    if (!at_inputs || weigh) {
      const StateEstimate e = est->current();
      if (!at_inputs) out.rows.push_back({e.t, e.mean, e.covariance});
      if (weigh && MeasurementFactor(model, e.step, m).weight(stateValues(model, e)) < 1.0) ++out.downweighted;
    }
    out.rejected = est->reportNumbers().rejected;  // not report(): formatting its line costs ~15% of an EKF update
    out.iterations = std::max(out.iterations, est->reportNumbers().iterations);
    if (progress && ((i + 1) % every == 0 || i + 1 == measurements.size())) progress(i + 1, measurements.size());
    if (!checkpoints.path.empty() && (i + 1) % checkpoints.every == 0) {
      out.total_seconds = seconds_before + since(start);
      saveCheckpoint(*est, checkpoints.path, encodeRun(out, i + 1, next_input, data_hash, row_due));
    }
  }
  feedInputsBefore(std::numeric_limits<double>::infinity());  // inputs after the last measurement
  if (at_inputs && row_due) record();
  out.total_seconds = seconds_before + since(start);
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
