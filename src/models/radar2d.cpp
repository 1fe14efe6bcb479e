#include "gssm/models/radar2d.h"

#include <cmath>

#include "gssm/model/noise_params.h"
#include "gssm/model/registry.h"

namespace gssm::models {

namespace {
ModelNoise radarNoise(const Radar2D::Params& p) {
  ModelNoise n;
  n.T = p.T;
  n.Q = Eigen::MatrixXd::Constant(1, 1, p.q);
  n.R = Eigen::MatrixXd::Constant(1, 1, p.r);
  n.prior_state.mean = Eigen::VectorXd::Constant(1, p.prior_x);
  n.prior_state.covariance = Eigen::MatrixXd::Constant(1, 1, p.prior_var_x);
  n.prior_constants.mean = Eigen::Vector2d(p.prior_xdot, p.prior_h);
  n.prior_constants.covariance = Eigen::Vector2d(p.prior_var_xdot, p.prior_var_h).asDiagonal();
  return n;
}
}  // namespace

Radar2D::Radar2D(const Params& p) : Radar2D(radarNoise(p)) {}

Radar2D::Radar2D(const ModelNoise& noise)
    : Model({1, 2, 0, 1}, {{"x"}, {"xdot", "h"}, {}, {"range"}}, noise) {}

Eigen::VectorXd Radar2D::f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                           const Eigen::VectorXd& /*u*/, double dt, Eigen::MatrixXd* J_f_xc,
                           Eigen::MatrixXd* J_f_xb) const {
  if (J_f_xc) *J_f_xc = Eigen::MatrixXd::Ones(1, 1);
  if (J_f_xb) {
    J_f_xb->resize(1, 2);
    *J_f_xb << dt, 0.0;
  }
  return Eigen::VectorXd::Constant(1, xc[0] + xb[0] * dt);
}

// Linearized measurement row [α] on x and [0, β] on [xdot, h], with
// α = x/ρ and β = h/ρ (the paper's H row [β, α] on [h, x_k]).
Eigen::VectorXd Radar2D::h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                           Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  Eigen::VectorXd out;
  hInto(0, xc, xb, out, J_h_xc, J_h_xb);
  return out;
}

void Radar2D::hInto(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::VectorXd& out,
                    Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  this->channel(channel);  // range check: throws, naming the channels
  const double x = xc[0], alt = xb[1];
  const double rho = std::hypot(x, alt);
  if (J_h_xc || J_h_xb) {
    // At x = h = 0 the range is not differentiable; the zero row it gives
    // makes the information matrix singular, which the solvers report.
    const double inv = rho > 0 ? 1.0 / rho : 0.0;
    if (J_h_xc) *J_h_xc = Eigen::MatrixXd::Constant(1, 1, x * inv);
    if (J_h_xb) {
      J_h_xb->resize(1, 2);
      *J_h_xb << 0.0, alt * inv;
    }
  }
  out.resize(1);
  out[0] = rho;
}

namespace {
// [model] type = radar_2d: T, Q, R and the priors; absent keys keep the
// paper's settings.
const ModelRegistration radar2d_registration{{
    "radar_2d", {"radar2d"}, "Radar2D",
    "The paper's radar example: x_c = x, x_b = [xdot, h], y = range (docs/DESIGN.md §2).",
    noiseParams(),
    [](const ParamSource& in) -> std::unique_ptr<Model> {
      const Radar2D paper;
      return std::make_unique<Radar2D>(readNoise(in, paper.dims(), paper.noise()));
    },
    [](const Model& m, ParamSink& out) { writeNoise(m, out); },
    [](const Model& m) { return dynamic_cast<const Radar2D*>(&m) != nullptr; },
    [](ParamSink& out) { writeNoise(Radar2D(), out); }}};
}  // namespace

}  // namespace gssm::models
