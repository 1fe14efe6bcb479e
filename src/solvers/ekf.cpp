#include "gssm/solvers/ekf.h"

#include <Eigen/Cholesky>
#include <optional>
#include <sstream>

#include "core/byte_stream.h"
#include "gssm/core/angles.h"
#include "gssm/core/rotation_blocks.h"
#include "gssm/core/error.h"
#include "gssm/core/gaussian.h"
#include "gssm/core/key.h"
#include "gssm/factors/problem.h"

namespace gssm {

namespace {
// Every entry finite: a NaN or an infinity anywhere makes the sum
// non-finite (one vectorized pass; Eigen's allFinite() compares entry by
// entry, a quarter of a 31-state filter's update). Only a sum of finite
// entries beyond 1e308 reads as non-finite too: no covariance is that.
bool allFinite(const Eigen::MatrixXd& m) { return std::isfinite(m.sum()); }

// The leading k × k block of m made exactly symmetric, ½(M + Mᵀ) in place.
void symmetrizeLeading(Eigen::MatrixXd& m, Eigen::Index k) {
  for (Eigen::Index j = 1; j < k; ++j)
    for (Eigen::Index i = 0; i < j; ++i) m(i, j) = m(j, i) = 0.5 * (m(i, j) + m(j, i));
}
}  // namespace

bool ExtendedKalmanFilterOptions::validate(int nb, std::string* why) const {
  auto fail = [&](const std::string& msg) {
    if (why) *why = "ExtendedKalmanFilterOptions: " + msg;
    return false;
  };
  if (constant_process_noise.size() != 0 && constant_process_noise.size() != nb)
    return fail("constant_process_noise needs " + std::to_string(nb) + " entries (one per constant), got " +
                std::to_string(constant_process_noise.size()));
  if (!(outlier_probability >= 0 && outlier_probability < 1)) return fail("outlier_probability must be in [0, 1)");
  for (Eigen::Index i = 0; i < constant_process_noise.size(); ++i)
    if (!(constant_process_noise[i] >= 0) || !std::isfinite(constant_process_noise[i]))
      return fail("constant_process_noise entry " + std::to_string(i) + " must be a finite variance >= 0");
  return true;
}

ExtendedKalmanFilter::ExtendedKalmanFilter(const Model& model, ExtendedKalmanFilterOptions options,
                                           double t0)
    : model_(&model), options_(std::move(options)), t_(t0) {
  const ModelDims& d = model.dims();
  std::string why;
  if (!options_.validate(d.nb, &why)) throw InvalidArgument(why);
  if (options_.constant_process_noise.size() == 0)
    options_.constant_process_noise = Eigen::VectorXd::Zero(d.nb);
  if (!options_.likelihood_channels.empty()) counted_.assign(static_cast<std::size_t>(model.numChannels()), 0);
  for (int c : options_.likelihood_channels) {
    if (c < 0 || c >= model.numChannels())
      throw InvalidArgument("ExtendedKalmanFilter: likelihood channel " + std::to_string(c) + " is not one of the " +
                            std::to_string(model.numChannels()) + " channels of " + model.name());
    counted_[static_cast<std::size_t>(c)] = 1;
  }
  z_.resize(d.nc + d.nb);
  z_ << model.priorState().mean, model.priorConstants().mean;
  P_ = Eigen::MatrixXd::Zero(d.nc + d.nb, d.nc + d.nb);
  P_.topLeftCorner(d.nc, d.nc) = model.priorState().covariance;
  if (d.nb > 0) P_.bottomRightCorner(d.nb, d.nb) = model.priorConstants().covariance;
}

void ExtendedKalmanFilter::predict(double t, const Eigen::VectorXd& u) {
  const ModelDims& d = model_->dims();
  if (!std::isfinite(t) || !(t > t_)) {
    std::ostringstream os;
    os << "ExtendedKalmanFilter::predict: time " << t << " must be after the filter time " << t_;
    throw InvalidArgument(os.str());
  }
  requireVector(u, d.nu, "ExtendedKalmanFilter::predict: input u");
  const double dt = t - t_;
  PredictBuffers& b = p_;  // kept from one prediction to the next: none allocates
  const Eigen::VectorXd xc = model_->f(z_.head(d.nc), z_.tail(d.nb), u, dt, &b.J_f_xc, &b.J_f_xb);
  // F = [F_c F_cb; 0 I]: only x_c's rows move, so F P Fᵀ is formed from
  // A = [F_c F_cb] (n_c × n): T = A P, then P_cc = T Aᵀ, P_cb = T's x_b
  // columns, P_bb unchanged — n_c·n² multiplies instead of 2n³ (a 31-state
  // filter with n_c = 6: 10× fewer).
  const int n = d.nc + d.nb;
  b.A.resize(d.nc, n);
  b.A << b.J_f_xc, b.J_f_xb;
  b.T.noalias() = b.A * P_;
  b.Pcc.noalias() = b.T * b.A.transpose();
  b.Pcc += model_->processNoiseOf(dt, u);
  b.constants_var = P_.diagonal().tail(d.nb) + options_.constant_process_noise * (dt / model_->nominalStep());
  if (!xc.allFinite() || !allFinite(b.Pcc) || !allFinite(b.T) || !b.constants_var.allFinite())
    throw NumericalError("ExtendedKalmanFilter::predict: the prediction to t = " +
                         std::to_string(t) + " is not finite; filter left at t = " +
                         std::to_string(t_));
  z_.head(d.nc) = xc;
  wrapAngles(z_, model_->angleStates());
  P_.topLeftCorner(d.nc, d.nc) = b.Pcc;
  P_.topRightCorner(d.nc, d.nb) = b.T.rightCols(d.nb);
  P_.bottomLeftCorner(d.nb, d.nc) = b.T.rightCols(d.nb).transpose();
  P_.diagonal().tail(d.nb) = b.constants_var;
  // P_ = ½(P_ + P_ᵀ). Once P_ is exactly symmetric (every update leaves it
  // so), its x_b rows are x_c's columns transposed and only P_cc can differ
  // from its transpose: the loop over the whole of P was 3 % of a filter
  // pass on the GNSS/INS drive.
  symmetrizeLeading(P_, symmetric_ ? d.nc : P_.cols());
  symmetric_ = true;
  t_ = t;
}

void ExtendedKalmanFilter::update(const Eigen::VectorXd& y) { update(Measurement{t_, y}); }

namespace {
// log((1 − ε)·N + ε·u) from log N and log u without underflow, and the
// inlier responsibility w = (1 − ε)·N / that.
std::pair<double, double> mixture(double log_normal, double epsilon, double log_uniform) {
  if (!(epsilon > 0)) return {log_normal, 1.0};
  const double a = std::log1p(-epsilon) + log_normal, b = std::log(epsilon) + log_uniform;
  const double hi = std::max(a, b), lp = hi + std::log(std::exp(a - hi) + std::exp(b - hi));
  return {lp, std::exp(a - lp)};
}
}  // namespace

bool ExtendedKalmanFilter::update(const Measurement& m) {
  const ModelDims& d = model_->dims();
  const MeasurementChannel& ch = model_->channel(m.channel);
  const Eigen::VectorXd& y = m.y;
  if (!validVector(y, ch.dim()))
    requireVector(y, ch.dim(), "ExtendedKalmanFilter::update: measurement on channel '" + ch.name + "'");
  if (m.R.size()) requireCovariance(m.R, ch.dim(), "ExtendedKalmanFilter::update: the measurement's own R");
  UpdateBuffers& b = u_;
  b.xc = z_.head(d.nc);
  b.xb = z_.tail(d.nb);
  model_->hWith(m.channel, m.regressors, b.xc, b.xb, b.yhat, &b.J_h_xc, &b.J_h_xb);
  b.H.resize(ch.dim(), d.nc + d.nb);
  b.H << b.J_h_xc, b.J_h_xb;
  if (m.R.size()) innovationCovariance(m.R, ch.own_R_scale);  // ch.covarianceOf(m.R), without a fresh matrix
  else innovationCovariance(ch.R, 1.0);
  b.llt.compute(b.S);
  if (b.llt.info() != Eigen::Success || !b.S.allFinite())
    throw NumericalError("ExtendedKalmanFilter::update at t = " + std::to_string(t_) +
                         ": innovation covariance S = HPHᵀ + R is not positive definite; "
                         "check R and the covariance P (filter unchanged)");
  b.innov = y - b.yhat;
  wrapAngles(b.innov, ch.angles);
  // A scalar's S⁻¹ is a division (the gain and the NIS take it: no
  // triangular solves of 31 columns); several rows solve with S's factor.
  if (b.S.size() == 1) b.whitened = b.innov * (1.0 / b.S(0, 0));
  else b.whitened = b.llt.solve(b.innov);
  const double nis = b.innov.dot(b.whitened);
  if (options_.use_gates && ch.ekf_gate > 0 && nis > ch.ekf_gate) {  // an outlier: leave the estimate as it is
    nis_ = nis;
    ++rejected_;
    return false;
  }
  // log N(e; 0, S) = −½ (eᵀS⁻¹e + log det S + m log 2π), log det S from S's Cholesky factor.
  const double log_det_S = 2.0 * b.llt.matrixLLT().diagonal().array().log().sum();
  const double log_normal = -0.5 * (nis + log_det_S + static_cast<double>(ch.dim()) * std::log(2.0 * M_PI));
  const auto [log_p, w] = mixture(log_normal, options_.outlier_probability, outlierLogDensity(m.channel));
  commitUpdate(w);
  nis_ = nis;
  if (counted_.empty() || counted_[static_cast<std::size_t>(m.channel)]) {
    log_likelihood_ += log_p;
    if (options_.keep_log_likelihood_terms) log_likelihood_terms_.push_back(log_p);
  }
  return true;
}

double ExtendedKalmanFilter::outlierLogDensity(int channel) const {
  if (!(options_.outlier_probability > 0)) return 0;
  if (static_cast<std::size_t>(channel) >= options_.outlier_log_density.size())
    throw InvalidArgument("ExtendedKalmanFilter: outlier_probability > 0 needs outlier_log_density for channel " +
                          std::to_string(channel));
  return options_.outlier_log_density[static_cast<std::size_t>(channel)];
}

// P Hᵀ and S = H P Hᵀ + R. A scalar measurement sums P's columns at H's
// nonzero columns (P is symmetric): a range reaches 5 of a 31-state
// filter's columns, so P Hᵀ reads 5 columns of P, not 31. Several rows take
// the blocked products (row by row, a 64-state filter's update was 1.5×
// slower).
void ExtendedKalmanFilter::innovationCovariance(const Eigen::MatrixXd& R, double scale) {
  UpdateBuffers& b = u_;
  b.S = scale * R;
  if (b.H.rows() > 1) {
    b.PHt.noalias() = P_ * b.H.transpose();
    b.S.noalias() += b.H * b.PHt;
    return;
  }
  b.nonzero.clear();
  for (Eigen::Index c = 0; c < b.H.cols(); ++c)
    if (b.H(0, c) != 0.0) b.nonzero.push_back(c);
  b.PHt.setZero(P_.rows(), 1);
  for (const Eigen::Index c : b.nonzero) b.PHt.col(0) += b.H(0, c) * P_.col(c);
  for (const Eigen::Index c : b.nonzero) b.S(0, 0) += b.H(0, c) * b.PHt(c, 0);
}

// The update with inlier weight w (1: the Kalman update): the moments of the
// mixture w·N(inlier update) + (1 − w)·N(no update).
void ExtendedKalmanFilter::commitUpdate(double w) {
  UpdateBuffers& b = u_;
  if (b.S.size() == 1) {  // K = P Hᵀ S⁻¹
    b.K.noalias() = b.PHt * (1.0 / b.S(0, 0));
  } else {
    b.KT = b.llt.solve(b.PHt.transpose());
    b.K = b.KT.transpose();
  }
  Eigen::MatrixXd& P = b.P;
  bool finite = true;
  if (options_.joseph_form) finite = josephUpdate();
  else P = P_ - b.K * b.PHt.transpose();
  b.dz.noalias() = b.K * b.innov;
  const Eigen::VectorXd& dz = b.dz;
  if (w < 1.0) P = w * P + (1.0 - w) * P_ + (w * (1.0 - w)) * dz * dz.transpose();
  // ½(P + Pᵀ) in place (P = 0.5 * (P + P.transpose()) reads entries it has
  // already written: not exactly symmetric)
  if (!options_.joseph_form || w < 1.0) symmetrizeLeading(P, P.cols());
  // With R > 0 the update keeps P positive definite in exact arithmetic
  // (the mixture too: a convex combination plus a rank-one term); what
  // rounding breaks first is a variance, so every update checks the
  // diagonal and only the non-Joseph form, which can lose definiteness to
  // cancellation, pays a Cholesky of P (it was 40% of a 31-state filter's
  // time).
  if (!options_.joseph_form || w < 1.0) finite = allFinite(P);
  if (!finite || !(P.diagonal().array() > 0).all() ||
      (!options_.joseph_form && Eigen::LLT<Eigen::MatrixXd>(P).info() != Eigen::Success))
    throw NumericalError("ExtendedKalmanFilter::update at t = " + std::to_string(t_) +
                         ": the updated covariance is not positive definite (filter unchanged)");
  // z ⊕ w·dz: an error-state update on the rotation blocks (docs/DESIGN.md
  // §12), P kept as the covariance of the tangent at the new estimate (the
  // reset Jacobian I − ½[w·dz]× of an error-state filter is dropped, as is usual).
  if (model_->rotationBlocks().empty()) z_ += w * dz;
  else retractBlocks(z_, w * dz, model_->rotationBlocks());
  wrapAngles(z_, model_->angleStates());
  P_.swap(P);  // the old covariance's storage is the next candidate's
}

// Joseph form (I − KH) P (I − KH)ᵀ + K R Kᵀ into b.P, expanded as
// P − K(HP) − (K(HP))ᵀ + K S Kᵀ = P + K Atᵀ + At Kᵀ with At = ½ K S − P Hᵀ:
// one n × m × n product for an m-row update (a scalar range: one rank-2
// update) instead of two n×n×n products. The upper triangle by columns, read
// from P_ as it is written, then mirrored: exactly symmetric. Returns whether
// every entry is finite (summed as written: a NaN or an infinity makes the
// sum non-finite).
bool ExtendedKalmanFilter::josephUpdate() {
  UpdateBuffers& b = u_;
  b.At.noalias() = b.K * (0.5 * b.S);
  b.At -= b.PHt;
  Eigen::MatrixXd& P = b.P;
  P.resize(P_.rows(), P_.cols());
  double sum = 0;
  for (Eigen::Index j = 0; j < P.cols(); ++j) {
    auto upper = P.col(j).head(j + 1);
    upper = P_.col(j).head(j + 1) + (b.K.col(0).head(j + 1) * b.At(j, 0) + b.At.col(0).head(j + 1) * b.K(j, 0));
    for (Eigen::Index c = 1; c < b.K.cols(); ++c)
      upper += b.K.col(c).head(j + 1) * b.At(j, c) + b.At.col(c).head(j + 1) * b.K(j, c);
    sum += upper.sum();
  }
  for (Eigen::Index j = 0; j < P.cols(); ++j)
    for (Eigen::Index i = j + 1; i < P.rows(); ++i) P(i, j) = P(j, i);
  return std::isfinite(sum);
}

void filterAlong(ExtendedKalmanFilter& filter, const std::vector<ScheduledStep>& schedule,
                 const std::vector<Measurement>& measurements, const std::vector<Input>& inputs,
                 const std::function<void()>& after, const std::function<void()>& predicted) {
  for (const ScheduledStep& step : schedule) {
    filter.predict(step.t, inputAt(filter.model(), inputs, filter.time()));
    if (predicted) predicted();
    for (std::size_t i : step.measurements) filter.update(measurements[i]);
    if (after) after();
  }
}

namespace {
// The RTS smoother's record of an EKF pass, in flat arrays (one heap block
// each, not three a step: on 200,000 radar steps the smoother then adds
// 50 % to the filter's pass instead of 76 %): z(k+1|k) and x_c's rows of the gain
// G_k = P(k|k) Fᵀ P(k+1|k)⁻¹, F = [A; 0 I], whose transpose solves
// P(k+1|k) G_kᵀ = F P(k|k)'s x_c columns. A gain is zero (the filtered
// state kept) where P(k+1|k) is not positive definite in rounding.
class SmootherRecord {
 public:
  SmootherRecord(Eigen::Index nc, Eigen::Index n) : nc_(nc), n_(n), M_(n, nc) {}
  void add(const Eigen::MatrixXd& P_filtered, const ExtendedKalmanFilter& ekf) {
    predicted_.insert(predicted_.end(), ekf.mean().data(), ekf.mean().data() + n_);
    const Eigen::MatrixXd& A = ekf.lastTransition();
    M_.topRows(nc_).noalias() = A * P_filtered.leftCols(nc_);
    M_.bottomRows(n_ - nc_) = P_filtered.bottomLeftCorner(n_ - nc_, nc_);
    llt_.compute(ekf.covariance());
    if (llt_.info() == Eigen::Success) Gt_ = llt_.solve(M_);
    if (llt_.info() != Eigen::Success || !Gt_.allFinite()) Gt_.setZero(n_, nc_);
    gains_.insert(gains_.end(), Gt_.data(), Gt_.data() + n_ * nc_);
  }
  Eigen::Map<const Eigen::VectorXd> predicted(std::size_t k) const { return {predicted_.data() + k * n_, n_}; }
  // G_kᵀ (n × n_c).
  Eigen::Map<const Eigen::MatrixXd> gainTransposed(std::size_t k) const {
    return {gains_.data() + k * n_ * nc_, n_, nc_};
  }
  std::size_t size() const { return predicted_.size() / static_cast<std::size_t>(n_); }

 private:
  Eigen::Index nc_, n_;
  Eigen::MatrixXd M_, Gt_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  std::vector<double> predicted_, gains_;
};

// The RTS smoother backwards over the filtered x_c(k|k) in `states`:
// x_c(k|N) = x_c(k|k) ⊕ G_k (z(k+1|N) ⊖ z(k+1|k)), in place, from the
// filter's final estimate `last`; the constants stay at it throughout (they
// have no process noise: their smoothed value is the final one at every k).
void smoothBackwards(const Model& model, const SmootherRecord& record, const Eigen::VectorXd& last,
                     std::vector<Eigen::VectorXd>& states) {
  const Eigen::Index nc = model.dims().nc;
  Eigen::VectorXd next = last, d, step(nc);
  for (std::size_t k = record.size(); k-- > 0;) {
    localBlocks(next, record.predicted(k), d, model.rotationBlocks());
    wrapAngles(d, model.angleStates());
    step.noalias() = record.gainTransposed(k).transpose() * d;
    retractBlocks(states[k], step, model.rotationBlocks());
    wrapAngles(states[k], model.angleStates());
    next.head(nc) = states[k];
  }
}
}  // namespace

Values ekfInitialGuess(const Model& model, const ExtendedKalmanFilterOptions& options,
                       const std::vector<Measurement>& measurements,
                       const std::vector<Input>& inputs, double t0, bool smoothed) {
  // The same steps as buildProblem: x_c(k|k) after each, and with
  // `smoothed` the record of each prediction for the smoother.
  const ModelDims& d = model.dims();
  ExtendedKalmanFilter ekf(model, options, t0);
  std::vector<Eigen::VectorXd> states{model.priorState().mean};
  std::optional<SmootherRecord> record;
  Eigen::MatrixXd P_filtered;  // P(k|k) of the step before the prediction
  if (smoothed) {
    record.emplace(d.nc, d.nc + d.nb);
    P_filtered = ekf.covariance();
  }
  const auto filtered = [&] {
    states.push_back(ekf.mean().head(d.nc));
    if (record) P_filtered = ekf.covariance();
  };
  const auto predicted = [&] { record->add(P_filtered, ekf); };
  filterAlong(ekf, stepSchedule(measurements, inputs, t0), measurements, inputs, filtered,
              record ? std::function<void()>(predicted) : std::function<void()>{});
  if (record) smoothBackwards(model, *record, ekf.mean(), states);
  Values x;
  for (std::size_t k = 0; k < states.size(); ++k) x.insert(Key::state(static_cast<std::int64_t>(k)), states[k]);
  if (d.nb > 0) x.insert(Key::constants(), ekf.mean().tail(d.nb));
  return x;
}

void ExtendedKalmanFilter::save(internal::ByteWriter& out) const {
  out.f64(t_);
  out.vec(z_);
  out.mat(P_);
  out.f64(nis_);
  out.i64(rejected_);  // since format version 2
}

void ExtendedKalmanFilter::load(internal::ByteReader& in) {
  const double t = in.f64("EKF time");
  Eigen::VectorXd z = in.vec("EKF mean");
  Eigen::MatrixXd P = in.mat("EKF covariance");
  const double nis = in.f64("EKF NIS", true);
  const std::int64_t rejected = in.version() >= 2 ? in.i64("EKF gated measurements") : 0;
  if (rejected < 0) in.fail("EKF gated measurements: negative count");
  const Eigen::Index n = model_->dims().nc + model_->dims().nb;
  if (z.size() != n || P.rows() != n || P.cols() != n)
    in.fail("EKF state has size " + std::to_string(z.size()) + " (covariance " + std::to_string(P.rows()) +
            " x " + std::to_string(P.cols()) + "), the model's stacked state " + std::to_string(n));
  symmetric_ = false;  // as saved, symmetrized by the next prediction
  t_ = t;
  z_ = std::move(z);
  P_ = std::move(P);
  nis_ = nis;
  rejected_ = rejected;
}

}  // namespace gssm
