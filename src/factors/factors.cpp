#include "gssm/factors/factors.h"

#include <sstream>

#include "gssm/core/angles.h"
#include "gssm/core/error.h"
#include "gssm/core/rotation_blocks.h"
#include "factors/model_factors.h"

namespace gssm {

namespace {
// The keys, then the constants' if the model has any; allocated at their
// exact size (a full-history run keeps every factor's keys).
std::vector<Key> withConstants(const Model& m, std::initializer_list<Key> states) {
  std::vector<Key> keys;
  keys.reserve(states.size() + (m.dims().nb > 0 ? 1 : 0));
  keys.insert(keys.end(), states);
  if (m.dims().nb > 0) keys.push_back(Key::constants());
  return keys;
}
}  // namespace

void Factor::linearize(const Values& x, Eigen::VectorXd& r, std::vector<Eigen::MatrixXd>* J) const {
  // The variables' addresses in key order: on the stack for the few keys of
  // a model factor, on the heap for a wide marginal prior.
  constexpr std::size_t kInline = 8;
  const Eigen::VectorXd* on_stack[kInline];
  std::vector<const Eigen::VectorXd*> on_heap;
  const Eigen::VectorXd** vars = on_stack;
  if (keys_.size() > kInline) {
    on_heap.resize(keys_.size());
    vars = on_heap.data();
  }
  for (std::size_t i = 0; i < keys_.size(); ++i) vars[i] = &x.at(keys_[i]);
  linearizeAt(vars, r, J);
}

double Factor::linearizeRobust(const Values& x, Eigen::VectorXd& r, std::vector<Eigen::MatrixXd>* J) const {
  linearize(x, r, J);
  return robustify(r, J);
}

double Factor::linearizeRobustAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                                 std::vector<Eigen::MatrixXd>* J) const {
  linearizeAt(x, r, J);
  return robustify(r, J);
}

double internal::robustify(const RobustLoss& loss, Eigen::VectorXd& r, std::vector<Eigen::MatrixXd>* J) {
  const double s = r.squaredNorm();
  if (!loss.robust()) return 0.5 * s;
  const double w = std::sqrt(loss.weight(s));
  if (w != 1.0) {  // an inlier of a Huber loss keeps its weight 1: nothing to scale
    r *= w;
    if (J)
      for (auto& block : *J) block *= w;
  }
  return 0.5 * loss.rho(s);
}

double Factor::robustify(Eigen::VectorXd& r, std::vector<Eigen::MatrixXd>* J) const {
  return internal::robustify(loss_, r, J);
}

double Factor::cost(const Values& x) const {
  Eigen::VectorXd r;
  linearize(x, r, nullptr);
  return 0.5 * loss_.rho(r.squaredNorm());
}

double Factor::weight(const Values& x) const {
  if (!loss_.robust()) return 1.0;
  Eigen::VectorXd r;
  linearize(x, r, nullptr);
  return loss_.weight(r.squaredNorm());
}

double FactorGraph::cost(const Values& x) const {
  double c = 0;
  Eigen::VectorXd r;  // one buffer for all factors
  for (const auto& f : factors_) {
    f->linearize(x, r, nullptr);
    c += 0.5 * f->loss().rho(r.squaredNorm());
  }
  return c;
}

// ---- PriorFactor -------------------------------------------------------------
PriorFactor::PriorFactor(Key key, const Gaussian& prior, std::vector<int> angles, std::vector<int> rotations)
    : Factor({key}, static_cast<int>(prior.mean.size())),
      mean_(prior.mean),
      noise_(prior.covariance, "prior on " + key.toString()),
      angles_(std::move(angles)),
      rotations_(std::move(rotations)) {
  requireVector(prior.mean, noise_.dim(), "prior mean of " + key.toString());
}

void PriorFactor::linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                              std::vector<Eigen::MatrixXd>* J) const {
  std::vector<Eigen::Matrix3d> J_r_x;  // per rotation block: r = x ⊖ mean there
  if (rotations_.empty()) r = *x[0] - mean_;
  else localBlocks(*x[0], mean_, r, rotations_, 0, J ? &J_r_x : nullptr);
  wrapAngles(r, angles_);
  noise_.whitenInPlace(r);
  if (J) {
    J->resize(1);
    (*J)[0].setIdentity(dim(), dim());  // whitened in place: L⁻¹ (1/σ for independent components), no temporaries
    if (!J_r_x.empty()) premultiplyBlocks((*J)[0], J_r_x, rotations_);
    noise_.whitenInPlace((*J)[0]);
  }
}

std::string PriorFactor::describe() const { return "prior on " + keys()[0].toString(); }

// ---- ProcessFactor -----------------------------------------------------------
ProcessFactor::ProcessFactor(const Model& model, std::int64_t k, const Eigen::VectorXd& u,
                             double dt)
    : ProcessFactor(model, k, u, dt,
                    model.processNoiseDependsOnInput()
                        ? GaussianNoise(model.processNoiseOf(dt, u), "process noise of step " + std::to_string(k))
                        : model.processNoiseModel(dt, k)) {}

namespace {
// What every process factor checks: a positive step, the input's and the
// noise's sizes. One is made per step: the message is built only on failure.
void checkProcess(const Model& model, const Key& from, const Key& to, const Eigen::VectorXd& u, double dt,
                  const GaussianNoise& noise) {
  auto what = [&] { return "process factor " + from.toString() + " -> " + to.toString(); };
  if (!(dt > 0) || !std::isfinite(dt))
    throw InvalidArgument(what() + ": time step must be > 0, got " + std::to_string(dt));
  if (!validVector(u, model.dims().nu)) requireVector(u, model.dims().nu, "input u of the " + what());
  if (noise.dim() != model.dims().nc)
    throw InvalidArgument(what() + ": its noise covariance is " + std::to_string(noise.dim()) + " x " +
                          std::to_string(noise.dim()) + ", the state has " + std::to_string(model.dims().nc) +
                          " components");
}
}  // namespace

ProcessFactor::ProcessFactor(const Model& model, std::int64_t k, const Eigen::VectorXd& u, double dt,
                             const GaussianNoise& noise)
    : Factor(withConstants(model, {Key::state(k), Key::state(k + 1)}), model.dims().nc),
      model_(&model),
      u_(u),
      dt_(dt),
      noise_(noise) {
  checkProcess(model, Key::state(k), Key::state(k + 1), u, dt, noise);
}

ProcessFactor::ProcessFactor(const Model& model, Key from, Key to, const Eigen::VectorXd& u, double dt)
    : ProcessFactor(model, from, to, u, dt,
                    GaussianNoise(model.processNoiseOf(dt, u), "process noise " + from.toString() + " -> " + to.toString())) {}

ProcessFactor::ProcessFactor(const Model& model, Key from, Key to, const Eigen::VectorXd& u, double dt,
                             const GaussianNoise& noise)
    : Factor(withConstants(model, {from, to}), model.dims().nc), model_(&model), u_(u), dt_(dt), noise_(noise) {
  checkProcess(model, from, to, u, dt, noise_);
}

void internal::processResidual(const Model& model, const Eigen::VectorXd& u, double dt, const GaussianNoise& noise,
                               const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                               std::vector<Eigen::MatrixXd>* J) {
  static const Eigen::VectorXd kNoConstants;
  const bool has_constants = model.dims().nb > 0;
  const Eigen::VectorXd& xk = *x[0];
  const Eigen::VectorXd& xk1 = *x[1];
  const Eigen::VectorXd& xb = has_constants ? *x[2] : kNoConstants;
  // The model writes its Jacobians straight into the caller's blocks (which a
  // solver reuses from factor to factor): no allocation per linearization.
  Eigen::MatrixXd no_constants;  // J_f_xb of a model without constants (n_b = 0: empty)
  if (J) J->resize(has_constants ? 3 : 2);
  Eigen::MatrixXd* J_f_xc = J ? &(*J)[0] : nullptr;
  Eigen::MatrixXd* J_f_xb = J ? (has_constants ? &(*J)[2] : &no_constants) : nullptr;
  const std::vector<int>& rot = model.rotationBlocks();
  std::vector<Eigen::Matrix3d> J_r_next, J_r_f;  // per rotation block (none: nothing allocated)
  if (!hasRotationIn(rot, model.dims().nc)) {
    r = xk1 - model.f(xk, xb, u, dt, J_f_xc, J_f_xb);
  } else {  // r = x_c(k+1) ⊖ f on the rotation blocks (docs/DESIGN.md §12)
    localBlocks(xk1, model.f(xk, xb, u, dt, J_f_xc, J_f_xb), r, rot, 0, J ? &J_r_next : nullptr,
                J ? &J_r_f : nullptr);
    // J_r_f = −Jr⁻¹(−r) on a block: its rows of J_f become Jr⁻¹(−r)·J_f, negated below with the rest.
    for (auto& M : J_r_f) M = -M;
    if (J) premultiplyBlocks(*J_f_xc, J_r_f, rot);
    if (J && has_constants) premultiplyBlocks(*J_f_xb, J_r_f, rot);
  }
  wrapAngles(r, model.angleStates());  // stacked indices below n_c are x_c's
  noise.whitenInPlace(r);
  if (J) {
    const int nc = model.dims().nc;
    (*J)[0] *= -1.0;
    (*J)[1].setIdentity(nc, nc);
    if (!J_r_next.empty()) premultiplyBlocks((*J)[1], J_r_next, rot);
    if (has_constants) (*J)[2] *= -1.0;
    for (auto& block : *J) noise.whitenInPlace(block);
  }
}

Factor::Rotations internal::rotationsOfVariable(const Model& model, bool constants) {
  if (model.rotationBlocks().empty()) return {};
  return {&model.rotationBlocks(), constants ? model.dims().nc : 0};
}

Factor::Rotations ProcessFactor::rotationsOf(std::size_t a) const {
  return internal::rotationsOfVariable(*model_, a == 2);
}
Factor::Rotations MeasurementFactor::rotationsOf(std::size_t a) const {
  return internal::rotationsOfVariable(*model_, a == 1);
}

void ProcessFactor::linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                                std::vector<Eigen::MatrixXd>* J) const {
  internal::processResidual(*model_, u_, dt_, noise_, x, r, J);
}

std::string ProcessFactor::describe() const {
  return "process model " + keys()[0].toString() + " -> " + keys()[1].toString();
}

// ---- MeasurementFactor -------------------------------------------------------
MeasurementFactor::MeasurementFactor(const Model& model, std::int64_t k, const Eigen::VectorXd& y)
    : MeasurementFactor(model, k, y, 0, model.channelNoiseModel(0)) {}

namespace {
GaussianNoise measurementNoise(const Model& model, std::int64_t k, const Measurement& m) {
  if (m.R.size() == 0) return model.channelNoiseModel(m.channel);
  const MeasurementChannel& ch = model.channel(m.channel);
  return GaussianNoise(ch.covarianceOf(m.R), "noise of the measurement on channel '" + ch.name +
                                "' at step " + std::to_string(k));
}
}  // namespace

MeasurementFactor::MeasurementFactor(const Model& model, std::int64_t k, const Measurement& m)
    : MeasurementFactor(model, k, m.y, m.channel, measurementNoise(model, k, m), m.regressors) {}

MeasurementFactor::MeasurementFactor(const Model& model, std::int64_t k, const Eigen::VectorXd& y, int channel,
                                     const GaussianNoise& noise, const Eigen::VectorXd& regressors)
    : Factor(withConstants(model, {Key::state(k)}), model.channel(channel).dim(), model.channel(channel).loss),
      model_(&model),
      y_(y),
      regressors_(regressors),
      channel_(channel),
      noise_(noise) {
  const MeasurementChannel& ch = model.channel(channel);
  if (!validVector(y, ch.dim()))
    requireVector(y, ch.dim(), "measurement on channel '" + ch.name + "' at step " + std::to_string(k));
  if (!validVector(regressors, ch.regressors))
    requireVector(regressors, ch.regressors,
                  "known values (regressors) of the measurement on channel '" + ch.name + "' at step " + std::to_string(k));
  if (noise.dim() != ch.dim())
    throw InvalidArgument("measurement on channel '" + ch.name + "' at step " + std::to_string(k) +
                          ": its noise covariance is " + std::to_string(noise.dim()) + " x " +
                          std::to_string(noise.dim()) + ", the channel has " + std::to_string(ch.dim()) + " components");
}

void internal::measurementResidual(const Model& model, int channel, const Eigen::Ref<const Eigen::VectorXd>& y,
                                   const GaussianNoise& noise, const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                                   std::vector<Eigen::MatrixXd>* J, const Eigen::VectorXd& regressors) {
  static const Eigen::VectorXd kNoConstants;
  const bool has_constants = model.dims().nb > 0;
  const Eigen::VectorXd& xc = *x[0];
  const Eigen::VectorXd& xb = has_constants ? *x[1] : kNoConstants;
  Eigen::MatrixXd no_constants;  // as in processResidual
  if (J) J->resize(has_constants ? 2 : 1);
  Eigen::MatrixXd* J_h_xc = J ? &(*J)[0] : nullptr;
  Eigen::MatrixXd* J_h_xb = J ? (has_constants ? &(*J)[1] : &no_constants) : nullptr;
  model.hWith(channel, regressors, xc, xb, r, J_h_xc, J_h_xb);
  r -= y;
  wrapAngles(r, model.channel(channel).angles);
  noise.whitenInPlace(r);
  if (J)
    for (auto& block : *J) noise.whitenInPlace(block);
}

void MeasurementFactor::linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                                    std::vector<Eigen::MatrixXd>* J) const {
  internal::measurementResidual(*model_, channel_, y_, noise_, x, r, J, regressors_);
}

const std::vector<int>* MeasurementFactor::columnsOf(std::size_t a) const {
  if (a != 1) return nullptr;  // keys: x_c(k), then x_b
  const std::vector<int>& used = model_->channel(channel_).constants;
  return used.empty() ? nullptr : &used;
}

std::string MeasurementFactor::describe() const {
  if (channel_ == 0 && model_->numChannels() == 1) return "measurement at " + keys()[0].toString();
  return "measurement on channel '" + model_->channel(channel_).name + "' at " + keys()[0].toString();
}

// ---- LinearGaussianFactor ----------------------------------------------------
LinearGaussianFactor::LinearGaussianFactor(std::vector<Key> keys, std::vector<Eigen::MatrixXd> A,
                                           Eigen::VectorXd b, Values linearization_point)
    : Factor(keys, static_cast<int>(b.size())),
      A_(std::move(A)),
      b_(std::move(b)),
      x0_(std::move(linearization_point)) {
  if (A_.size() != keys.size())
    throw InvalidArgument("LinearGaussianFactor: one Jacobian block per key is required");
  for (std::size_t i = 0; i < keys.size(); ++i)
    if (A_[i].rows() != b_.size() || A_[i].cols() != x0_.at(keys[i]).size())
      throw InvalidArgument("LinearGaussianFactor: block for " + keys[i].toString() +
                            " has the wrong size");
}

void LinearGaussianFactor::linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                                       std::vector<Eigen::MatrixXd>* J) const {
  r = -b_;
  for (std::size_t i = 0; i < keys().size(); ++i)
    r += A_[i] * (*x[i] - x0_.at(keys()[i]));
  if (J) *J = A_;
}

std::string LinearGaussianFactor::describe() const {
  std::string s = "marginal prior on";
  for (const auto& k : keys()) s += " " + k.toString();
  return s;
}

}  // namespace gssm
