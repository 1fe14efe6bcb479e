#include "gssm/factors/factors.h"

#include <sstream>

#include "gssm/core/error.h"

namespace gssm {

namespace {
std::vector<Key> withConstants(const Model& m, std::vector<Key> keys) {
  if (m.dims().nb > 0) keys.push_back(Key::constants());
  return keys;
}
const Eigen::VectorXd& constantsOrEmpty(const Model& m, const Values& x) {
  static const Eigen::VectorXd kEmpty;
  return m.dims().nb > 0 ? x.at(Key::constants()) : kEmpty;
}
}  // namespace

double Factor::cost(const Values& x) const {
  Eigen::VectorXd r;
  linearize(x, r, nullptr);
  return 0.5 * r.squaredNorm();
}

double FactorGraph::cost(const Values& x) const {
  double c = 0;
  Eigen::VectorXd r;  // one buffer for all factors
  for (const auto& f : factors_) {
    f->linearize(x, r, nullptr);
    c += 0.5 * r.squaredNorm();
  }
  return c;
}

// ---- PriorFactor -------------------------------------------------------------
PriorFactor::PriorFactor(Key key, const Gaussian& prior)
    : Factor({key}, static_cast<int>(prior.mean.size())),
      mean_(prior.mean),
      noise_(prior.covariance, "prior on " + key.toString()) {
  requireVector(prior.mean, noise_.dim(), "prior mean of " + key.toString());
}

void PriorFactor::linearize(const Values& x, Eigen::VectorXd& r,
                            std::vector<Eigen::MatrixXd>* J) const {
  r = x.at(keys()[0]) - mean_;
  noise_.whitenInPlace(r);
  if (J) {
    J->resize(1);
    (*J)[0] = noise_.sqrtCovariance().triangularView<Eigen::Lower>().solve(
        Eigen::MatrixXd::Identity(dim(), dim()));
  }
}

std::string PriorFactor::describe() const { return "prior on " + keys()[0].toString(); }

// ---- ProcessFactor -----------------------------------------------------------
ProcessFactor::ProcessFactor(const Model& model, std::int64_t k, const Eigen::VectorXd& u,
                             double dt)
    : Factor(withConstants(model, {Key::state(k), Key::state(k + 1)}), model.dims().nc),
      model_(&model),
      u_(u),
      dt_(dt),
      noise_(model.processNoiseModel(dt, "process noise of step " + std::to_string(k))) {
  if (!(dt > 0) || !std::isfinite(dt))
    throw InvalidArgument("process factor x_c(" + std::to_string(k) + ") -> x_c(" +
                          std::to_string(k + 1) + "): time step must be > 0, got " +
                          std::to_string(dt));
  requireVector(u, model.dims().nu, "input u at step " + std::to_string(k));
}

void ProcessFactor::linearize(const Values& x, Eigen::VectorXd& r,
                              std::vector<Eigen::MatrixXd>* J) const {
  const Eigen::VectorXd& xk = x.at(keys()[0]);
  const Eigen::VectorXd& xk1 = x.at(keys()[1]);
  const Eigen::VectorXd& xb = constantsOrEmpty(*model_, x);
  Eigen::MatrixXd J_f_xc, J_f_xb;
  r = xk1 - model_->f(xk, xb, u_, dt_, J ? &J_f_xc : nullptr, J ? &J_f_xb : nullptr);
  noise_.whitenInPlace(r);
  if (J) {
    const int nc = model_->dims().nc;
    J->resize(keys().size());
    (*J)[0] = -J_f_xc;
    (*J)[1] = Eigen::MatrixXd::Identity(nc, nc);
    if (keys().size() == 3) (*J)[2] = -J_f_xb;
    for (auto& block : *J) noise_.whitenInPlace(block);
  }
}

std::string ProcessFactor::describe() const {
  return "process model " + keys()[0].toString() + " -> " + keys()[1].toString();
}

// ---- MeasurementFactor -------------------------------------------------------
MeasurementFactor::MeasurementFactor(const Model& model, std::int64_t k, const Eigen::VectorXd& y)
    : MeasurementFactor(model, k, y, model.measurementNoiseModel()) {}

MeasurementFactor::MeasurementFactor(const Model& model, std::int64_t k, const Eigen::VectorXd& y,
                                     const GaussianNoise& noise)
    : Factor(withConstants(model, {Key::state(k)}), model.dims().ny),
      model_(&model),
      y_(y),
      noise_(noise) {
  requireVector(y, model.dims().ny, "measurement y at step " + std::to_string(k));
}

void MeasurementFactor::linearize(const Values& x, Eigen::VectorXd& r,
                                  std::vector<Eigen::MatrixXd>* J) const {
  const Eigen::VectorXd& xc = x.at(keys()[0]);
  const Eigen::VectorXd& xb = constantsOrEmpty(*model_, x);
  Eigen::MatrixXd J_h_xc, J_h_xb;
  r = model_->h(xc, xb, J ? &J_h_xc : nullptr, J ? &J_h_xb : nullptr) - y_;
  noise_.whitenInPlace(r);
  if (J) {
    J->resize(keys().size());
    (*J)[0] = J_h_xc;
    if (keys().size() == 2) (*J)[1] = J_h_xb;
    for (auto& block : *J) noise_.whitenInPlace(block);
  }
}

std::string MeasurementFactor::describe() const {
  return "measurement at " + keys()[0].toString();
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

void LinearGaussianFactor::linearize(const Values& x, Eigen::VectorXd& r,
                                     std::vector<Eigen::MatrixXd>* J) const {
  r = -b_;
  for (std::size_t i = 0; i < keys().size(); ++i)
    r += A_[i] * (x.at(keys()[i]) - x0_.at(keys()[i]));
  if (J) *J = A_;
}

std::string LinearGaussianFactor::describe() const {
  std::string s = "marginal prior on";
  for (const auto& k : keys()) s += " " + k.toString();
  return s;
}

}  // namespace gssm
