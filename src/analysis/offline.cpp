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

// A batch start must hold the problem's variables with their sizes.
void requireSameVariables(const Values& start, const Values& problem) {
  bool same = start.size() == problem.size();
  for (auto a = start.begin(), b = problem.begin(); same && a != start.end(); ++a, ++b)
    same = a->first == b->first && a->second.size() == b->second.size() && a->second.allFinite();
  if (!same)
    throw InvalidArgument("runBatch: the start (" + std::to_string(start.size()) + " variables) is not of this run (" +
                          std::to_string(problem.size()) + "): it needs the same variables, sizes and finite values");
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

namespace {
// One streaming run over a dataset: the estimator, where the run is (what a
// checkpoint stores) and the records it has made.
class StreamingRun {
 public:
  StreamingRun(const Model& model, const EstimatorOptions& options, const std::vector<Measurement>& measurements,
               const std::vector<Input>& inputs, const StreamingCheckpoints& checkpoints, RowTimes rows)
      : model_(model), options_(options), measurements_(measurements), inputs_(inputs), checkpoints_(checkpoints),
        inline_recorder_(out_), recorder_(checkpoints.recorder ? *checkpoints.recorder : inline_recorder_),
        at_inputs_(rows == RowTimes::Inputs || rows == RowTimes::States),
        at_epochs_(rows == RowTimes::Epochs || rows == RowTimes::States),
        group_epochs_(at_epochs_ && !options.compute_nis) {
    out_.method = options.method;
    at_.data_fingerprint = internal::kFnv1a64Basis;
    if (!checkpoints.resume_from.empty()) resume();
    else est_ = makeEstimator(model, options);
    out_.rows.reserve(measurements.size());
    out_.update_seconds.reserve(measurements.size());
    rows_sent_ = out_.rows.size(), updates_sent_ = out_.update_seconds.size();  // resumed: already there
  }

  OfflineRun run(const std::function<void(std::size_t, std::size_t)>& progress) {
    const std::size_t n = measurements_.size(), every = std::max<std::size_t>(1, n / 100);
    for (std::size_t i = at_.next_measurement; i < n;) {
      // With rows per epoch, the measurements of one instant are one update.
      std::size_t j = i + 1;
      if (group_epochs_)
        while (j < n && measurements_[j].t == measurements_[i].t) ++j;
      update(i, j);
      if (progress && (j / every > i / every || j == n)) progress(j, n);
      if (!checkpoints_.path.empty() && j / checkpoints_.every > i / checkpoints_.every) checkpoint(j);
      i = j;
    }
    feedInputsBefore(std::numeric_limits<double>::infinity());  // inputs after the last measurement
    if ((at_inputs_ || at_epochs_) && at_.row_due) addRow(est_->current());
    out_.total_seconds = seconds_before_ + since(start_) - recording_;
    sendRecords();
    out_.summary = est_->report().detail;
    return std::move(out_);
  }

 private:
  void resume();
  void update(std::size_t first, std::size_t end);
  void checkpoint(std::size_t next_measurement);
  void addRow(const StateEstimate& e) { out_.rows.push_back({e.t, e.mean, e.covariance}); }
  // Events in time order: an input at t makes the state at t (when after
  // the newest), a measurement at t attaches to it or makes it. With rows at
  // inputs, the row of a state an input made is taken just before the first
  // later event, so it holds every measurement at its time (at_.row_due: the
  // newest state, made by an input, has no row yet).
  void feedInputsBefore(double t) {
    for (; at_.next_input < inputs_.size() && inputs_[at_.next_input].t < t; ++at_.next_input) {
      const double ti = std::max(inputs_[at_.next_input].t, est_->time());
      if ((at_inputs_ || at_epochs_) && at_.row_due && ti > est_->time()) addRow(est_->current()), at_.row_due = false;
      const bool advances = ti > est_->time();
      est_->addInput(ti, inputs_[at_.next_input].u);
      if (at_inputs_ && advances) at_.row_due = true;
    }
  }
  // The recorder gets the records at each checkpoint and at the end, not
  // inside the loop: writing output files is not the estimator's time (left
  // out of total_seconds) and costs the loop nothing.
  void sendRecords() {
    for (; rows_sent_ < out_.rows.size(); ++rows_sent_) recorder_.row(out_.rows[rows_sent_]);
    for (; updates_sent_ < out_.update_seconds.size(); ++updates_sent_)
      recorder_.update(out_.update_seconds[updates_sent_],
                       options_.compute_nis ? std::optional<double>(out_.nis[updates_sent_]) : std::nullopt);
  }

  const Model& model_;
  const EstimatorOptions& options_;
  const std::vector<Measurement>& measurements_;
  const std::vector<Input>& inputs_;
  const StreamingCheckpoints& checkpoints_;
  OfflineRun out_;
  InlineRecorder inline_recorder_;
  RunRecorder& recorder_;
  const bool at_inputs_, at_epochs_, group_epochs_;
  const Clock::time_point start_ = Clock::now();
  std::unique_ptr<Estimator> est_;
  RunProgress at_;  // where the run is (what a checkpoint stores)
  double seconds_before_ = 0, recording_ = 0;
  std::size_t rows_sent_ = 0, updates_sent_ = 0;
};

// Continues from checkpoints_.resume_from, after checking it was written by
// this method and window on this dataset's first measurements.
void StreamingRun::resume() {
  const std::string& from = checkpoints_.resume_from;
  CheckpointInfo info;
  est_ = restoreCheckpoint(model_, from, &info);
  RunProgress saved;
  std::string mark;
  out_ = decodeRun(info.user_data, from, saved, mark);
  const auto fail = [&](const std::string& why) { throw CheckpointError(from + ": cannot resume this run: " + why); };
  if (info.method != options_.method || out_.method != options_.method)
    fail(std::string("it was written by method '") + methodName(info.method) + "', this run is '" +
         methodName(options_.method) + "'");
  if (est_->report().window != options_.window())
    fail("it was written with window " + std::to_string(est_->report().window) + ", this run asks for " +
         std::to_string(options_.window()));
  if (saved.next_measurement <= measurements_.size())
    for (std::size_t i = 0; i < saved.next_measurement; ++i)
      at_.data_fingerprint = foldMeasurement(at_.data_fingerprint, measurements_[i]);
  if (saved.next_measurement > measurements_.size() || saved.next_input > inputs_.size() ||
      at_.data_fingerprint != saved.data_fingerprint)
    fail("its first " + std::to_string(saved.next_measurement) +
         " measurements differ from this dataset's (another dataset?)");
  recorder_.resume(mark, out_);
  if (out_.update_seconds.size() != saved.next_measurement)
    fail("its records hold " + std::to_string(out_.update_seconds.size()) + " updates, its progress says " +
         std::to_string(saved.next_measurement));
  at_ = saved;
  seconds_before_ = out_.total_seconds;
}

// Measurements [first, end) of one instant (one unless grouped by epoch):
// one update; each gets an equal share of its time.
void StreamingRun::update(std::size_t first, std::size_t end) {
  const Measurement& m = measurements_[first];
  feedInputsBefore(m.t);
  if ((at_inputs_ || at_epochs_) && at_.row_due && m.t > est_->time()) {
    addRow(est_->current());
    at_.row_due = false;
  }
  const auto t0 = Clock::now();
  if (end == first + 1) est_->addMeasurement(m);
  else est_->addMeasurements(&measurements_[first], end - first);
  const double seconds = since(t0) / static_cast<double>(end - first);
  for (std::size_t i = first; i < end; ++i) {
    out_.update_seconds.push_back(seconds);
    at_.data_fingerprint = foldMeasurement(at_.data_fingerprint, measurements_[i]);
  }
  if (options_.compute_nis) out_.nis.push_back(est_->reportNumbers().nis);
  if (at_epochs_) at_.row_due = true;  // the epoch's row: before the first later measurement
  // The EKF gates instead of weighting; the others' weight is the
  // measurement factor's own, at the estimate after its update.
  bool weigh = false;
  for (std::size_t i = first; i < end; ++i)
    weigh = weigh || (model_.channel(measurements_[i].channel).loss.robust() && options_.method != Method::Ekf);
  const bool row_now = !at_inputs_ && !at_epochs_;
  if (row_now || weigh) {
    const StateEstimate e = est_->current();
    if (row_now) addRow(e);
    for (std::size_t i = first; weigh && i < end; ++i) {
      const Measurement& mi = measurements_[i];
      if (model_.channel(mi.channel).loss.robust() &&
          MeasurementFactor(model_, e.step, mi).weight(stateValues(model_, e)) < 1.0)
        ++out_.downweighted;
    }
  }
  out_.rejected = est_->reportNumbers().rejected;  // not report(): formatting its line costs ~15% of an EKF update
  out_.iterations = std::max(out_.iterations, est_->reportNumbers().iterations);
}

void StreamingRun::checkpoint(std::size_t next_measurement) {
  const auto c0 = Clock::now();
  at_.next_measurement = next_measurement;
  out_.total_seconds = seconds_before_ + since(start_) - recording_;
  // The records first: a checkpoint never points past what is durable.
  sendRecords();
  const std::string mark = recorder_.mark();
  saveCheckpoint(*est_, checkpoints_.path, encodeRun(out_, at_, mark));
  recording_ += since(c0);
}
}  // namespace

OfflineRun runStreaming(const Model& model, const EstimatorOptions& options,
                        const std::vector<Measurement>& measurements,
                        const std::vector<Input>& inputs,
                        const std::function<void(std::size_t, std::size_t)>& progress,
                        const StreamingCheckpoints& checkpoints, RowTimes rows) {
  if (!checkpoints.path.empty() && checkpoints.every == 0)
    throw InvalidArgument("runStreaming: a checkpoint path needs checkpoints.every >= 1");
  return StreamingRun(model, options, measurements, inputs, checkpoints, rows).run(progress);
}

std::optional<RowTimes> rowTimesNamed(const std::string& name) {
  if (name == "measurements") return RowTimes::Measurements;
  if (name == "inputs") return RowTimes::Inputs;
  if (name == "epochs") return RowTimes::Epochs;
  if (name == "states") return RowTimes::States;
  return std::nullopt;
}

OfflineRun runBatch(const Model& model, const EstimatorOptions& options,
                    const std::vector<Measurement>& measurements,
                    const std::vector<Input>& inputs, RowTimes rows, const Values* from) {
  OfflineRun out;
  out.method = Method::Batch;
  const auto start = Clock::now();
  Problem p = buildProblem(model, measurements, inputs, options.t0);
  if (from) requireSameVariables(*from, p.initial);
  Values x = from ? *from : ekfInitialGuess(model, ExtendedKalmanFilterOptions{}, measurements, inputs, options.t0);
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
    if (rows == RowTimes::States) {
      // every state
    } else if (rows == RowTimes::Inputs) {
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
                      const StreamingCheckpoints& checkpoints, RowTimes rows, const Values* batch_start) {
  if (methodInfo(options.method).streaming)
    return runStreaming(model, options, measurements, inputs, progress, checkpoints, rows);
  if (!checkpoints.path.empty() || !checkpoints.resume_from.empty())
    throw InvalidArgument(std::string("runOffline: checkpoints apply to streaming methods, not '") +
                          methodName(options.method) + "'");
  return runBatch(model, options, measurements, inputs, rows, batch_start);
}

}  // namespace gssm
