#include "gssm/estimator/estimator.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <deque>
#include <map>
#include <type_traits>
#include <sstream>
#include <utility>

#include "core/byte_stream.h"
#include "factors/factor_io.h"
#include "gssm/core/angles.h"
#include "gssm/core/error.h"
#include "gssm/core/time.h"
#include "gssm/factors/problem.h"
#include "gssm/solvers/batch_solver.h"
#include "solvers/option_fields.h"

namespace gssm {

bool EstimatorOptions::validate(const Model& model, std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = "EstimatorOptions: " + m;
    return false;
  };
  const unsigned reads = methodInfo(method).reads;  // throws for a value outside the enum
  if (!std::isfinite(t0)) return fail("t0 must be finite");
  if ((reads & kFixedLagOptions) && fixed_lag.window < 1)
    return fail("fixed_lag.window must be >= 1, got " + std::to_string(fixed_lag.window));
  if ((reads & kFixedLagOptions) && !std::isnan(fixed_lag.constants_check_sigmas) && !(fixed_lag.constants_check_sigmas > 0))
    return fail("fixed_lag.constants_check_sigmas must be > 0 (or NaN: [smoother]'s)");
  if ((reads & kPaperWindowOptions) && paper_window.window < 1)
    return fail("paper_window.window must be >= 1, got " + std::to_string(paper_window.window));
  if ((reads & kEkfOptions) && !ekf.validate(model.dims().nb, why)) return false;
  if ((reads & kBatchOptions) && !batch.validate(why)) return false;
  return !(reads & kSmootherOptions) || smoother.validate(why);
}

Estimator::Estimator(const Model& model, const EstimatorOptions& options)
    : model_(model), t_(options.t0), options_(options) {
  report_.method = options.method;
  report_.window = options.window();
  if (options.method == Method::Incremental) report_.ordering = options.incremental.ordering;
  if (options.method == Method::FixedLag) report_.ordering = EliminationOrdering::TimeOrdered;
}

// ---- checkpoints ------------------------------------------------------------------
namespace internal {
template <class Io>
void fields(Io& io, EstimatorOptions& o) {  // after the method, which goes by name
  // Format v1 holds one window: the method's.
  io(o.method == Method::PaperWindow ? o.paper_window.window : o.fixed_lag.window, "window");
  fields(io, o.ekf);
  io.enumeration(o.incremental.ordering, 1, "smoother ordering");
  fields(io, o.smoother);
  io(o.t0, "t0");
  io(o.compute_nis, "compute_nis");
  if (io.version() >= 3) io(o.drop_late, "drop_late");
}

template <class Io>
void fields(Io& io, EstimatorReport& r) {  // all but what the options determine
  io(r.measurements, "report measurements");
  io(r.seconds, "report seconds");
  io(r.iterations, "report iterations");
  fields(io, r.smoother);
  io(r.detail, "report detail");
  io(r.nis, "report nis", true);  // NaN without compute_nis
}

void writeOptions(ByteWriter& out, const EstimatorOptions& options) {
  out.str(methodName(options.method));  // by name: stable across enum changes
  FieldWriter w{out};
  EstimatorOptions copy = options;
  fields(w, copy);
}

EstimatorOptions readOptions(ByteReader& in) {
  const std::string name = in.str("estimator method");
  const auto method = methodNamed(name);
  if (!method || !methodInfo(*method).streaming) in.fail("estimator method: no streaming method '" + name + "'");
  EstimatorOptions o(*method);
  FieldReader r{in};
  fields(r, o);
  return o;
}
}  // namespace internal

void Estimator::save(internal::ByteWriter& out) const {
  out.f64(t_);
  out.i64(k_);
  out.vec(input_);
  EstimatorReport r = report();  // formats a pending detail line
  internal::FieldWriter w{out};
  internal::fields(w, r);
  out.i64(r.late);  // since format version 3
  out.i64(r.late_dropped);
  saveState(out);
}

void Estimator::load(internal::ByteReader& in) {
  const double t = in.f64("estimator time");
  const std::int64_t k = in.i64("estimator step");
  if (k < 0 || k > (std::int64_t(1) << 53)) in.fail("step counter " + std::to_string(k) + " out of range");
  Eigen::VectorXd input = in.vec("input in force");
  if (input.size() != 0 && input.size() != model_.dims().nu)
    in.fail("input in force has size " + std::to_string(input.size()) + ", the model's inputs " +
            std::to_string(model_.dims().nu));
  EstimatorReport r = report_;  // method, window, ordering: from the options
  internal::FieldReader reader{in};
  internal::fields(reader, r);
  if (in.version() >= 3) {
    r.late = in.i64("report late measurements");
    r.late_dropped = in.i64("report late measurements dropped");
    if (r.late < 0 || r.late_dropped < 0) in.fail("late measurement counts: negative");
  }
  // The base state first: the method's loadState checks itself against it.
  t_ = t;
  k_ = k;
  input_ = std::move(input);
  report_ = std::move(r);
  detail_stale_ = false;
  loadState(in);
}

void Estimator::saveState(internal::ByteWriter&) const {
  throw CheckpointError(std::string(methodName()) + ": this estimator does not support checkpoints");
}
void Estimator::loadState(internal::ByteReader&) {
  throw CheckpointError(std::string(methodName()) + ": this estimator does not support checkpoints");
}

const EstimatorReport& Estimator::report() const {
  if (detail_stale_) {
    report_.detail = formatDetail();
    detail_stale_ = false;
  }
  return report_;
}

void Estimator::addInput(double t, const Eigen::VectorXd& u) {
  if (!validVector(u, model_.dims().nu))  // the message only when it is needed: 27k inputs a drive
    requireVector(u, model_.dims().nu, std::string(methodName()) + ": input u at t = " + std::to_string(t));
  // A time stamp within rounding of the newest state's (k·T computed two
  // ways) means "now".
  if (std::isfinite(t) && sameTime(t, t_)) t = t_;
  if (!std::isfinite(t) || t < t_) {
    std::ostringstream os;
    os << methodName() << ": input at t = " << t << " must be at or after the newest state (t = " << t_ << ")";
    throw InvalidArgument(os.str());
  }
  if (t > t_) advance(t);  // strong guarantee: throws before changing anything
  input_ = u;
}

Eigen::VectorXd Estimator::inputInForce() const {
  return input_.size() ? input_ : Eigen::VectorXd(Eigen::VectorXd::Zero(model_.dims().nu));
}

void Estimator::advance(double t) {
  const auto start = std::chrono::steady_clock::now();
  doStep(k_ + 1, t - t_, inputInForce(), nullptr, 0);
  t_ = t;
  ++k_;
  report_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double Estimator::innovationNis(double dt, const Eigen::VectorXd& u, const Measurement& m) {
  const ModelDims& d = model_.dims();
  const MeasurementChannel& ch = model_.channel(m.channel);
  const StateEstimate e = current();
  const Eigen::VectorXd xc = e.mean.head(d.nc), xb = e.mean.tail(d.nb);
  Eigen::VectorXd x = xc;
  Eigen::MatrixXd P = e.covariance;
  if (dt > 0) {  // predict [x_c; x_b] through the model, as an EKF would
    Eigen::MatrixXd J_f_xc, J_f_xb;
    x = model_.f(xc, xb, u, dt, &J_f_xc, &J_f_xb);
    Eigen::MatrixXd F = Eigen::MatrixXd::Identity(d.nc + d.nb, d.nc + d.nb);
    F.topLeftCorner(d.nc, d.nc) = J_f_xc;
    F.topRightCorner(d.nc, d.nb) = J_f_xb;
    P = F * P * F.transpose();
    P.topLeftCorner(d.nc, d.nc) += model_.processNoiseOf(dt, u);
  }
  Eigen::MatrixXd J_h_xc, J_h_xb;
  Eigen::VectorXd innovation = m.y - model_.hWith(m.channel, m.regressors, x, xb, &J_h_xc, &J_h_xb);
  wrapAngles(innovation, ch.angles);
  Eigen::MatrixXd H(ch.dim(), d.nc + d.nb);
  H << J_h_xc, J_h_xb;
  const Eigen::MatrixXd S = H * P * H.transpose() + ch.covarianceOf(m.R);
  return innovation.dot(S.ldlt().solve(innovation));
}

void Estimator::addMeasurement(double t, const Eigen::VectorXd& y) { addMeasurement(Measurement{t, y}); }

void Estimator::addMeasurement(double t, const std::string& channel, const Eigen::VectorXd& y) {
  addMeasurement(Measurement{t, y, model_.channelIndex(channel), {}});
}

void Estimator::requireUsable(const Measurement& m) const {
  const double t = m.t;
  if (!std::isfinite(t) || t < t_ || (t == t_ && k_ == 0)) {
    std::ostringstream os;
    os << methodName() << ": measurement time " << t << " must be after the previous state (" << t_ << ")"
       << (k_ == 0 ? ", the start t0" : "");
    throw InvalidArgument(os.str());
  }
  requireValues(m);
}

void Estimator::requireValues(const Measurement& m) const {
  const double t = m.t;
  if (m.channel < 0 || m.channel >= model_.numChannels())
    throw InvalidArgument(std::string(methodName()) + ": measurement at t = " + std::to_string(t) + " names channel " +
                          std::to_string(m.channel) + "; model '" + model_.name() + "' has " +
                          std::to_string(model_.numChannels()));
  const MeasurementChannel& ch = model_.channel(m.channel);
  if (!validVector(m.y, ch.dim())) {
    const std::string what = model_.numChannels() == 1 ? "measurement y" : "measurement on channel '" + ch.name + "'";
    requireVector(m.y, ch.dim(), std::string(methodName()) + ": " + what + " at t = " + std::to_string(t));
  }
  if (m.R.size())
    requireCovariance(m.R, ch.dim(), std::string(methodName()) + ": own noise covariance of the measurement at t = " +
                                         std::to_string(t));
  if (!validVector(m.regressors, ch.regressors))
    requireVector(m.regressors, ch.regressors,
                  std::string(methodName()) + ": known values (regressors) of the measurement on channel '" + ch.name +
                      "' at t = " + std::to_string(t));
}

void Estimator::addLate(const Measurement& m) {
  const std::optional<std::int64_t> k = stateAt(m.t);
  if (!k && m.t > options_.t0 && insertLate(m)) {
    ++report_.late;
    ++report_.measurements;
    return;
  }
  if (!k && options_.drop_late) {
    ++report_.late_dropped;
    return;
  }
  if (!k) {
    std::ostringstream os;
    os << methodName() << ": measurement at t = " << m.t << " is before the newest state (t = " << t_ << ") and "
       << (method() == Method::Incremental || method() == Method::FixedLag
               ? std::string(method() == Method::FixedLag
                                 ? "it is older than the window (the fixed lag takes a late measurement at or "
                                   "between the states it still holds)"
                                 : "it is not after the start")
               : "this method takes measurements in time order only")
       << "; EstimatorOptions::drop_late drops and counts it instead";
    throw InvalidArgument(os.str());
  }
  requireValues(m);  // its time is a held state's
  doMeasurements(*k, &m, 1);
  ++report_.late;
  ++report_.measurements;
}

void Estimator::addMeasurement(const Measurement& m) {
  const auto start = std::chrono::steady_clock::now();
  if (std::isfinite(m.t) && m.t < t_) {
    addLate(m);
    report_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return;
  }
  requireUsable(m);
  const double nis = options_.compute_nis ? innovationNis(m.t - t_, inputInForce(), m) : report_.nis;
  addAt(m.t, &m, 1);
  report_.nis = nis;
  report_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void Estimator::addMeasurements(const std::vector<Measurement>& ms) { addMeasurements(ms.data(), ms.size()); }

void Estimator::addMeasurements(const Measurement* ms, std::size_t count) {
  if (count == 0) return;
  if (options_.compute_nis || (std::isfinite(ms[0].t) && ms[0].t < t_)) {  // late: each joins its state
    for (std::size_t i = 0; i < count; ++i) addMeasurement(ms[i]);
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < count; ++i) {
    requireUsable(ms[i]);
    if (ms[i].t != ms[0].t)
      throw InvalidArgument(std::string(methodName()) + ": addMeasurements takes one instant; t = " +
                            std::to_string(ms[i].t) + " differs from " + std::to_string(ms[0].t));
  }
  addAt(ms[0].t, ms, count);
  report_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Validated measurements at time t: at the newest state, or a new one.
void Estimator::addAt(double t, const Measurement* ms, std::size_t count) {
  if (t == t_ || (k_ > 0 && sameTime(t, t_))) {  // the newest state's instant (core/time.h)
    doMeasurements(k_, ms, count);
  } else {
    doStep(k_ + 1, t - t_, inputInForce(), ms, count);  // strong guarantee: throws before changing anything
    t_ = t;
    ++k_;
  }
  report_.measurements += static_cast<std::int64_t>(count);
}

namespace {

Eigen::VectorXd stack(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb) {
  Eigen::VectorXd z(xc.size() + xb.size());
  z << xc, xb;
  return z;
}

// ---- EKF ----------------------------------------------------------------------
class EkfEstimator final : public Estimator {
 public:
  EkfEstimator(const Model& m, const EstimatorOptions& o)
      : Estimator(m, o), ekf_(m, o.ekf, o.t0) {}

  StateEstimate current() override { return {time(), step(), ekf_.mean(), ekf_.covariance()}; }
  std::optional<StateEstimate> smoothed(std::int64_t k) override {
    if (k == step()) return current();
    return std::nullopt;
  }
  std::optional<Eigen::MatrixXd> marginalCovariance(const std::vector<Key>& keys) override {
    // Rows of the stacked state [x_c; x_b] that each key occupies.
    const int nc = model_.dims().nc, nb = model_.dims().nb;
    std::vector<Eigen::Index> idx;
    for (const auto& k : keys) {
      if (k.isConstants()) {
        for (int i = 0; i < nb; ++i) idx.push_back(nc + i);
      } else if (k.step == step()) {
        for (int i = 0; i < nc; ++i) idx.push_back(i);
      } else {
        return std::nullopt;
      }
    }
    Eigen::MatrixXd out(idx.size(), idx.size());
    for (std::size_t a = 0; a < idx.size(); ++a)
      for (std::size_t b = 0; b < idx.size(); ++b) out(a, b) = ekf_.covariance()(idx[a], idx[b]);
    return out;
  }

 protected:
  void doStep(std::int64_t, double dt, const Eigen::VectorXd& u, const Measurement* ms, std::size_t count) override {
    ExtendedKalmanFilter next = ekf_;  // commit only if both halves succeed
    next.predict(ekf_.time() + dt, u);
    for (std::size_t i = 0; i < count; ++i) next.update(ms[i]);
    ekf_ = std::move(next);
    report_.iterations = 1;
    report_.rejected = ekf_.rejected();
    updated_ = count > 0;
    markDetail();
  }
  void doMeasurements(std::int64_t, const Measurement* ms, std::size_t count) override {
    ExtendedKalmanFilter next = ekf_;
    for (std::size_t i = 0; i < count; ++i) next.update(ms[i]);
    ekf_ = std::move(next);
    report_.rejected = ekf_.rejected();
    updated_ = true;
    markDetail();
  }

 private:
  std::string formatDetail() const override {
    return updated_ ? "EKF update, NIS " + std::to_string(ekf_.lastNis()) : "EKF prediction";
  }
  bool updated_ = false;  // the last step had a measurement
  void saveState(internal::ByteWriter& out) const override { ekf_.save(out); }
  void loadState(internal::ByteReader& in) override {
    ekf_.load(in);
    report_.rejected = ekf_.rejected();
  }
  ExtendedKalmanFilter ekf_;
};

// ---- IncrementalSmoother / FixedLagSmoother --------------------------------------
// x_c(k) starts at the model's prediction; a non-finite one is a numerical
// failure of the model, reported before anything changes.
Eigen::VectorXd predictState(const Model& m, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                             const Eigen::VectorXd& u, double dt, std::int64_t k) {
  Eigen::VectorXd x = m.f(xc, xb, u, dt);
  if (!x.allFinite()) {
    std::ostringstream os;
    os << m.name() << ": the prediction f(x_c(" << k - 1 << "), x_b, u, dt = " << dt << ") of x_c(" << k
       << ") is not finite; estimator unchanged";
    throw NumericalError(os.str());
  }
  return x;
}

// The model's priors with their means as initial values.
std::vector<FactorPtr> modelPriors(const Model& m, Values& initial) {
  initial.insert(Key::state(0), m.priorState().mean);
  if (m.dims().nb > 0) initial.insert(Key::constants(), m.priorConstants().mean);
  return priorFactors(m, m.priorState(), m.priorConstants());
}

template <class Smoother>
class SmootherEstimator final : public Estimator {
 public:
  /// `args` construct the smoother; keep_times = 0 keeps every state's time.
  template <class... Args>
  SmootherEstimator(const Model& m, const EstimatorOptions& o, std::size_t keep_times, Args&&... args)
      : Estimator(m, o), smoother_(std::forward<Args>(args)...), keep_times_(keep_times) {
    Values initial;
    const auto priors = modelPriors(m, initial);
    report_.smoother = smoother_.update(priors, initial);
    times_.push_back(o.t0);
  }

  StateEstimate current() override { return *smoothed(step()); }

  std::optional<std::int64_t> stateAt(double t) const override {
    for (const auto& [step, ins] : inserted_)
      if (sameTime(ins.t, t)) return step;
    const auto it = std::lower_bound(times_.begin(), times_.end(), t,
                                     [](double a, double b) { return a < b && !sameTime(a, b); });
    if (it == times_.end() || !sameTime(*it, t)) return std::nullopt;
    const std::int64_t k = step() - static_cast<std::int64_t>(times_.end() - 1 - it);
    if (k < 1 || !smoother_.contains(Key::state(k))) return std::nullopt;  // x_c(0) is the prior's
    return k;
  }

  std::optional<StateEstimate> smoothed(std::int64_t k) override {
    if (k < 0 || k > step() || step() - k >= static_cast<std::int64_t>(times_.size()) ||
        !smoother_.contains(Key::state(k)))
      return std::nullopt;
    const bool nb = model_.dims().nb > 0;
    StateEstimate e;
    e.step = k;
    e.t = times_[times_.size() - 1 - static_cast<std::size_t>(step() - k)];
    const Eigen::VectorXd xb = nb ? smoother_.estimate(Key::constants()) : Eigen::VectorXd();
    e.mean = model_.wrapStacked(stack(smoother_.estimate(Key::state(k)), xb));
    e.covariance = smoother_.jointMarginalCovariance(stackedKeys(model_, k));
    return e;
  }

  std::optional<Eigen::MatrixXd> marginalCovariance(const std::vector<Key>& keys) override {
    for (const auto& k : keys)
      if (!smoother_.contains(k)) return std::nullopt;
    return smoother_.jointMarginalCovariance(keys);
  }

 protected:
  void doStep(std::int64_t k, double dt, const Eigen::VectorXd& u, const Measurement* ms, std::size_t count) override {
    const auto factors = stepFactors(model_, k, dt, u, ms, count);
    const Eigen::VectorXd xb = model_.dims().nb ? smoother_.estimate(Key::constants())
                                                : Eigen::VectorXd(Eigen::VectorXd::Zero(0));
    Values initial;
    initial.insert(Key::state(k), predictState(model_, smoother_.estimate(Key::state(k - 1)), xb, u, dt, k));
    report_.smoother = smoother_.update(factors, initial);  // transactional
    report_.iterations = report_.smoother.iterations;
    markDetail();
    forgetMarginalized();
    times_.push_back(times_.back() + dt);
    if (model_.dims().nu > 0) inputs_.push_back(u);
    while (keep_times_ > 0 && times_.size() > keep_times_) times_.pop_front();
    while (keep_times_ > 0 && inputs_.size() > keep_times_) inputs_.pop_front();
  }
  void doMeasurements(std::int64_t k, const Measurement* ms, std::size_t count) override {
    std::vector<FactorPtr> factors;
    for (std::size_t i = 0; i < count; ++i) factors.push_back(std::make_shared<MeasurementFactor>(model_, k, ms[i]));
    report_.smoother = smoother_.update(factors, Values{});
    report_.iterations = report_.smoother.iterations;
    markDetail();
  }

  // Between two held states: x(t) inserted, the process factor between them
  // replaced by two through it, the measurement on it (incremental only).
  bool insertLate(const Measurement& m) override {
    {
      const auto around = neighbours(m.t);
      if (!around || !smoother_.contains(around->first.key) || !smoother_.contains(around->second.key)) return false;
      const auto& [prev, next] = *around;
      if (model_.dims().nu > 0 && next.u.size() == 0) return false;  // its input is unknown (an old checkpoint)
      requireValues(m);
      const Key x = Key::state(inserted_.empty() ? -1 : inserted_.begin()->first - 1);  // a key no state holds
      const Eigen::VectorXd u = model_.dims().nu > 0 ? next.u : Eigen::VectorXd(Eigen::VectorXd::Zero(0));
      std::vector<FactorPtr> factors{std::make_shared<ProcessFactor>(model_, prev.key, x, u, m.t - prev.t),
                                     std::make_shared<ProcessFactor>(model_, x, next.key, u, next.t - m.t),
                                     std::make_shared<MeasurementFactor>(model_, x.step, m)};
      const Eigen::VectorXd xb = model_.dims().nb ? smoother_.estimate(Key::constants())
                                                  : Eigen::VectorXd(Eigen::VectorXd::Zero(0));
      Values initial;
      initial.insert(x, predictState(model_, smoother_.estimate(prev.key), xb, u, m.t - prev.t, x.step));
      report_.smoother = smoother_.replace({{prev.key, next.key}}, factors, initial);  // transactional
      report_.iterations = report_.smoother.iterations;
      markDetail();
      inserted_[x.step] = {m.t, u};
      return true;
    }
  }
  // Inserted states a fixed lag has marginalized are forgotten.
  void forgetMarginalized() {
    for (auto it = inserted_.begin(); it != inserted_.end();)
      it = smoother_.contains(Key::state(it->first)) ? std::next(it) : inserted_.erase(it);
  }

 private:
  struct HeldState {
    Key key;
    double t;
    Eigen::VectorXd u;  // the input over the interval ending at it (empty without inputs)
  };
  // The held states just before and after t (regular or inserted), when t lies strictly between two.
  std::optional<std::pair<HeldState, HeldState>> neighbours(double t) const {
    const auto it = std::upper_bound(times_.begin(), times_.end(), t);
    if (it == times_.begin() || it == times_.end()) return std::nullopt;
    const auto i = static_cast<std::size_t>(it - times_.begin());
    auto regular = [&](std::size_t idx) {
      const std::int64_t k = step() - static_cast<std::int64_t>(times_.size() - 1 - idx);
      const std::size_t ui = inputs_.size() - (times_.size() - idx);  // inputs_ has one per state after the first
      return HeldState{Key::state(k), times_[idx],
                       model_.dims().nu > 0 && idx > 0 && ui < inputs_.size() ? inputs_[ui] : Eigen::VectorXd()};
    };
    HeldState prev = regular(i - 1), next = regular(i);
    for (const auto& [step, ins] : inserted_) {  // a nearer inserted state
      if (ins.t < t && ins.t > prev.t) prev = {Key::state(step), ins.t, ins.u};
      if (ins.t > t && ins.t < next.t) next = {Key::state(step), ins.t, ins.u};
    }
    if (sameTime(prev.t, t) || sameTime(next.t, t)) return std::nullopt;
    return std::make_pair(prev, next);
  }
  void saveState(internal::ByteWriter& out) const override {
    smoother_.save(out);
    out.times(times_);
    out.u64(inputs_.size());  // since format version 3
    for (const auto& u : inputs_) out.vec(u);
    out.u64(inserted_.size());
    for (const auto& [step, ins] : inserted_) out.i64(step), out.f64(ins.t), out.vec(ins.u);
  }
  void loadState(internal::ByteReader& in) override {
    smoother_.load(in, model_);
    std::deque<double> times = in.times("state times");
    std::deque<Eigen::VectorXd> inputs;
    std::map<std::int64_t, Inserted> inserted;
    if (in.version() >= 3) readInsertions(in, inputs, inserted);
    const auto held = static_cast<std::size_t>(step()) + 1;
    const std::size_t expect = keep_times_ ? std::min(held, keep_times_) : held;
    const bool nb = model_.dims().nb > 0;
    if (times.size() != expect || !sameTime(times.back(), time()) ||
        smoother_.numVariables() != times.size() + inserted.size() + (nb ? 1 : 0) ||
        !smoother_.contains(Key::state(step())) ||
        !smoother_.contains(Key::state(step() - static_cast<std::int64_t>(times.size()) + 1)) ||
        (nb && !smoother_.contains(Key::constants())))
      in.fail("the smoother's variables do not match step " + std::to_string(step()) + " and " +
              std::to_string(times.size()) + " state times");
    times_ = std::move(times);
    inputs_ = std::move(inputs);
    inserted_ = std::move(inserted);
  }
  struct Inserted {
    double t;
    Eigen::VectorXd u;
  };
  void readInsertions(internal::ByteReader& in, std::deque<Eigen::VectorXd>& inputs,
                      std::map<std::int64_t, Inserted>& inserted) const {
    const std::uint64_t n = in.u64("state inputs (count)");
    if (n > static_cast<std::uint64_t>(step()) + 1) in.fail("state inputs: more than the states");
    for (std::uint64_t i = 0; i < n; ++i) inputs.push_back(in.vec("state input"));
    const std::uint64_t m = in.u64("inserted states (count)");
    if (m > (std::uint64_t(1) << 40)) in.fail("inserted states: count out of range");
    for (std::uint64_t i = 0; i < m; ++i) {
      const std::int64_t key = in.i64("inserted state key");
      const double t = in.f64("inserted state time");
      if (key >= 0 || !smoother_.contains(Key::state(key)))
        in.fail("inserted state " + std::to_string(key) + ": not an inserted state the smoother holds");
      inserted[key] = {t, in.vec("inserted state input")};
    }
  }
  Smoother smoother_;
  std::size_t keep_times_;   // 0: keep all
  std::deque<double> times_; // times of the states still held
  std::deque<Eigen::VectorXd> inputs_;  // the input into each held state after the first (models with inputs)
  std::map<std::int64_t, Inserted> inserted_;  // states inserted for late measurements, by (negative) key step
};

// ---- The paper's window re-solve (reproduction mode) -----------------------------
// The author's scheme (docs/DESIGN.md §4): the window holds the newest w
// states; a new state joins and the w + 1 states are solved by Gauss–Newton;
// once that is more than w, the oldest state leaves with its process factor
// and the measurements of the state after it, all priors are replaced by
// independent 1-D priors (mean = estimate, variance = marginal variance of
// the w + 1 window just solved) on the oldest remaining x_c and on each
// constant, and the w states left are solved again: the reported estimate
// and covariances are the second solve's. This counts the window's
// measurements again at every step, so it is over-confident; it exists to
// reproduce the paper's figures, not as an estimator to deploy.
class PaperWindowEstimator final : public Estimator {
 public:
  PaperWindowEstimator(const Model& m, const EstimatorOptions& o)
      : Estimator(m, o), window_(o.paper_window.window) {
    values_.insert(Key::state(0), m.priorState().mean);
    prior_state_ = m.priorState();
    if (m.dims().nb > 0) {
      values_.insert(Key::constants(), m.priorConstants().mean);
      prior_constants_ = m.priorConstants();
    }
    times_.push_back(o.t0);
    solver_.solve(graph(), values_);
  }

  StateEstimate current() override { return *smoothed(step()); }
  std::optional<StateEstimate> smoothed(std::int64_t k) override {
    if (k < oldest_ || k > step()) return std::nullopt;
    const bool nb = model_.dims().nb > 0;
    StateEstimate e;
    e.step = k;
    e.t = times_[static_cast<std::size_t>(k - oldest_)];
    e.mean = model_.wrapStacked(stack(values_.at(Key::state(k)), nb ? values_.at(Key::constants()) : Eigen::VectorXd()));
    e.covariance = solver_.jointMarginalCovariance(stackedKeys(model_, k));
    return e;
  }
  std::optional<Eigen::MatrixXd> marginalCovariance(const std::vector<Key>& keys) override {
    for (const auto& k : keys)
      if (!values_.contains(k)) return std::nullopt;
    return solver_.jointMarginalCovariance(keys);
  }

 protected:
  void doStep(std::int64_t k, double dt, const Eigen::VectorXd& u, const Measurement* ms, std::size_t count) override {
    // Work on copies; commit at the end.
    auto steps = steps_;
    auto times = times_;
    Values values = values_;
    Gaussian prior_state = prior_state_, prior_constants = prior_constants_;
    std::int64_t oldest = oldest_;
    steps.push_back(stepFactors(model_, k, dt, u, ms, count));
    const Eigen::VectorXd xb = model_.dims().nb ? values.at(Key::constants()) : Eigen::VectorXd();
    values.insert(Key::state(k), predictState(model_, values.at(Key::state(k - 1)), xb, u, dt, k));
    times.push_back(times.back() + dt);
    BatchSolver& solver = spare_;  // the committed solver_ stays as it is until the step succeeds
    std::vector<FactorPtr> priors = priorFactors(model_, prior_state, prior_constants, oldest);
    BatchSolverSummary sum = solver.solve(windowGraph(steps, priors), values);
    if (static_cast<int>(times.size()) > window_) {
      // w + 1 states: the oldest leaves, new 1-D priors from this solve.
      const Key next = Key::state(oldest + 1);
      prior_state = diagonalPrior(values.at(next), solver.marginalCovariance(next));
      if (model_.dims().nb > 0)
        prior_constants = diagonalPrior(values.at(Key::constants()), solver.marginalCovariance(Key::constants()));
      // The re-solve's first Gauss–Newton step from the first solve's
      // factorization: only the priors and the oldest step's factors change.
      GraphChange change;
      for (const auto& f : priors) change.removed.add(f);
      for (const auto& f : steps.front()) change.removed.add(f);
      priors = priorFactors(model_, prior_state, prior_constants, oldest + 1);
      for (const auto& f : priors) change.added.add(f);
      change.dropped = {Key::state(oldest)};
      solver.stepAfterChange(change, values);
      steps.pop_front();
      times.pop_front();
      ++oldest;
      const BatchSolverSummary first = sum;
      sum = solver.solve(windowGraph(steps, priors), values);
      sum.iterations += first.iterations + 1;
      sum.factorizations += first.factorizations;
    }
    steps_ = std::move(steps);
    times_ = std::move(times);
    values_ = std::move(values);
    prior_state_ = std::move(prior_state);
    prior_constants_ = std::move(prior_constants);
    oldest_ = oldest;
    commitSolve(sum);
  }

 private:
  void doMeasurements(std::int64_t k, const Measurement* ms, std::size_t count) override {
    auto steps = steps_;
    Values values = values_;
    for (std::size_t i = 0; i < count; ++i) steps.back().push_back(std::make_shared<MeasurementFactor>(model_, k, ms[i]));
    BatchSolver& solver = spare_;
    const BatchSolverSummary sum = solver.solve(graph(steps), values);
    steps_ = std::move(steps);
    values_ = std::move(values);
    commitSolve(sum);
  }
  // The spare solver, which solved the step, becomes the window's; the old
  // one is the next step's spare (its buffers are reused, not reallocated).
  void commitSolve(const BatchSolverSummary& sum) {
    std::swap(solver_, spare_);
    report_.iterations = sum.iterations;
    last_summary_ = sum;
    markDetail();
  }
  // Gauss–Newton to a cost change below 1e-9 of the cost: the window is
  // solved twice a step, and on a log with robust ranges its iterations
  // converge linearly (a step ~1/30 of the one before); the batch default
  // (1e-12) spent a fourth iteration moving the estimate by < 1e-6 m (UWB:
  // 20% of the method's time; estimates within 2·10⁻⁵ of it). The last,
  // negligible step is taken without relinearizing after it: the window's
  // covariances come from the factorization that computed it. Up to 1000
  // iterations: from the paper's prior (143σ off) Gauss–Newton converges at
  // a rate near 1 and takes hundreds over the first windows; stopped at 20,
  // the windows were 0.6σ from their minimum and the priors carried that on.
  static BatchSolverOptions gaussNewton() {
    BatchSolverOptions o;
    o.method = BatchSolverOptions::Method::GaussNewton;
    o.max_iterations = 1000;
    o.relative_cost_tolerance = 1e-9;
    o.relinearize_at_solution = false;
    return o;
  }
  static Gaussian diagonalPrior(const Eigen::VectorXd& mean, const Eigen::MatrixXd& cov) {
    return {mean, Eigen::MatrixXd(cov.diagonal().asDiagonal())};
  }
  // The window's graph: the priors on its oldest state and the constants,
  // then every step's factors.
  static FactorGraph windowGraph(const std::deque<std::vector<FactorPtr>>& steps, const std::vector<FactorPtr>& priors) {
    FactorGraph g;
    for (const auto& f : priors) g.add(f);
    for (const auto& s : steps)
      for (const auto& f : s) g.add(f);
    return g;
  }
  // The committed window's graph, with `steps` for its steps.
  FactorGraph graph(const std::deque<std::vector<FactorPtr>>& steps) const {
    return windowGraph(steps, priorFactors(model_, prior_state_, prior_constants_, oldest_));
  }
  FactorGraph graph() const { return graph(steps_); }

  void saveState(internal::ByteWriter& out) const override {
    out.u64(steps_.size());
    for (const auto& s : steps_) {
      out.u64(s.size());
      for (const auto& f : s) internal::writeFactor(out, *f);
    }
    out.times(times_);
    out.values(values_);
    out.gaussian(prior_state_);
    out.gaussian(prior_constants_);
    out.i64(oldest_);
    out.values(solver_.factoredAt(values_));  // since version 5
  }
  void loadState(internal::ByteReader& in) override {
    std::deque<std::vector<FactorPtr>> steps(in.count("window steps", 8));
    for (std::size_t i = 0; i < steps.size(); ++i) {
      steps[i].resize(in.count("factors of window step", 1));
      for (auto& f : steps[i]) f = internal::readFactor(in, model_, "window factor");
    }
    std::deque<double> times = in.times("state times");
    Values values = in.values("window values");
    Gaussian ps = in.gaussian("prior on the oldest state"), pb = in.gaussian("prior on the constants");
    const std::int64_t oldest = in.i64("oldest step");
    Values factored = in.version() >= 5 ? in.values("window factorization point") : values;
    const bool nb = model_.dims().nb > 0;
    if (oldest < 0 || oldest > step()) in.fail("oldest window step " + std::to_string(oldest) + " out of range");
    const std::int64_t held = step() - oldest + 1;
    bool ok = oldest >= 0 && held >= 1 && held <= window_ && static_cast<std::int64_t>(times.size()) == held &&
              static_cast<std::int64_t>(steps.size()) == held - 1 && sameTime(times.back(), time()) &&
              values.size() == static_cast<std::size_t>(held) + (nb ? 1 : 0) &&
              ps.mean.size() == model_.dims().nc && pb.mean.size() == model_.dims().nb;
    for (std::int64_t k = oldest; ok && k <= step(); ++k)
      ok = values.contains(Key::state(k)) && values.at(Key::state(k)).size() == model_.dims().nc;
    if (ok && nb) ok = values.contains(Key::constants()) && values.at(Key::constants()).size() == model_.dims().nb;
    ok = ok && sameLayout(factored, values);
    if (!ok) in.fail("the paper window's states, times and priors do not match step " + std::to_string(step()));
    // The covariances come from the factorization the uninterrupted run
    // kept: at the point before its last step (version 4 and older: at the
    // window's values).
    steps_ = std::move(steps);
    times_ = std::move(times);
    values_ = std::move(values);
    prior_state_ = std::move(ps);
    prior_constants_ = std::move(pb);
    oldest_ = oldest;
    solver_.evaluateAt(graph(), factored);
  }
  static bool sameLayout(const Values& a, const Values& b) {
    if (a.size() != b.size()) return false;
    for (auto i = a.begin(), j = b.begin(); i != a.end(); ++i, ++j)
      if (!(i->first == j->first) || i->second.size() != j->second.size()) return false;
    return true;
  }
  std::string formatDetail() const override { return last_summary_.toString(); }
  BatchSolverSummary last_summary_;
  int window_;
  std::deque<std::vector<FactorPtr>> steps_;  // factors of each step in the window
  std::deque<double> times_;
  Values values_;
  Gaussian prior_state_, prior_constants_;
  std::int64_t oldest_ = 0;
  BatchSolver solver_{gaussNewton()};
  BatchSolver spare_{gaussNewton()};  // what a step solves in
};

}  // namespace

std::unique_ptr<Estimator> makeEstimator(const Model& model, const EstimatorOptions& options) {
  std::string why;
  if (!options.validate(model, &why)) throw InvalidArgument(why);
  std::unique_ptr<Estimator> e;
  switch (options.method) {
    case Method::Ekf:
      e = std::make_unique<EkfEstimator>(model, options);
      break;
    case Method::Incremental:
      e = std::make_unique<SmootherEstimator<IncrementalSmoother>>(model, options, 0, options.smoother,
                                                                   options.incremental.ordering);
      break;
    case Method::FixedLag: {
      EstimatorOptions own = options;  // the fixed lag's relinearization (saved so in a checkpoint)
      if (!std::isnan(own.fixed_lag.constants_check_sigmas))
        own.smoother.constants_check_sigmas = own.fixed_lag.constants_check_sigmas;
      e = std::make_unique<SmootherEstimator<FixedLagSmoother>>(
          model, own, static_cast<std::size_t>(own.fixed_lag.window),
          FixedLagSmootherOptions{own.fixed_lag.window, own.smoother});
      break;
    }
    case Method::PaperWindow:
      e = std::make_unique<PaperWindowEstimator>(model, options);
      break;
    case Method::Batch:
      throw InvalidArgument("makeEstimator: method 'batch' needs the whole run (runOffline, BatchSolver); "
                            "streaming methods: " + methodNameList(true));
  }
  return e;
}

}  // namespace gssm
