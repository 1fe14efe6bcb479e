#include "drift_1d.h"

#include "gssm/model/registry.h"

namespace gssm::testing {

namespace {
ModelNoise driftNoise(const Drift1D::Params& p) {
  ModelNoise n;
  n.T = p.T;
  n.Q = Eigen::MatrixXd::Constant(1, 1, p.q * p.T);
  n.R = Eigen::MatrixXd::Constant(1, 1, p.r);
  n.prior_state = {Eigen::VectorXd::Constant(1, p.start), Eigen::MatrixXd::Constant(1, 1, p.start_sd * p.start_sd)};
  n.prior_constants = {Eigen::VectorXd::Zero(2),
                       Eigen::MatrixXd(Eigen::Vector2d(p.drift_sd * p.drift_sd, p.offset_sd * p.offset_sd).asDiagonal())};
  return n;
}
}  // namespace

Drift1D::Drift1D(const Params& p) : Model({1, 2, 0, 1}, {{"x"}, {"drift", "offset"}, {}, {"y"}}, driftNoise(p)), p_(p) {}

Eigen::VectorXd Drift1D::f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd&, double dt,
                           Eigen::MatrixXd* J_f_xc, Eigen::MatrixXd* J_f_xb) const {
  if (J_f_xc) *J_f_xc = Eigen::MatrixXd::Ones(1, 1);
  if (J_f_xb) *J_f_xb = (Eigen::MatrixXd(1, 2) << dt, 0.0).finished();
  return Eigen::VectorXd::Constant(1, xc[0] + xb[0] * dt);
}

Eigen::VectorXd Drift1D::h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                           Eigen::MatrixXd* J_h_xb) const {
  if (J_h_xc) *J_h_xc = Eigen::MatrixXd::Ones(1, 1);
  if (J_h_xb) *J_h_xb = (Eigen::MatrixXd(1, 2) << 0.0, 1.0).finished();
  return Eigen::VectorXd::Constant(1, xc[0] + xb[1]);
}

namespace {
// Its one registration: INI [model] type = drift_1d, Python gssm.models.Drift1D.
const ModelRegistration registration{{
    "drift_1d", {"drift"}, "Drift1D", "A position drifting at a constant rate, measured with an offset (a test model).",
    {param::real("model", "T", "nominal step (s)"), param::real("model", "q", "process noise variance per second"),
     param::real("model", "r", "measurement noise variance"), param::real("prior", "start", "prior mean of x(0)"),
     param::real("prior", "start_sd", "prior σ of x(0)"), param::real("prior", "drift_sd", "prior σ of the drift"),
     param::real("prior", "offset_sd", "prior σ of the offset")},
    [](const ParamSource& in) -> std::unique_ptr<Model> {
      Drift1D::Params p;
      for (auto [section, key, value] :
           {std::tuple{"model", "T", &p.T}, {"model", "q", &p.q}, {"model", "r", &p.r}, {"prior", "start", &p.start},
            {"prior", "start_sd", &p.start_sd}, {"prior", "drift_sd", &p.drift_sd}, {"prior", "offset_sd", &p.offset_sd}})
        *value = in.real(section, key, *value);
      return std::make_unique<Drift1D>(p);
    },
    [](const Model& m, ParamSink& out) {
      const Drift1D::Params& p = dynamic_cast<const Drift1D&>(m).params();
      for (auto [section, key, value] :
           {std::tuple{"model", "T", p.T}, {"model", "q", p.q}, {"model", "r", p.r}, {"prior", "start", p.start},
            {"prior", "start_sd", p.start_sd}, {"prior", "drift_sd", p.drift_sd}, {"prior", "offset_sd", p.offset_sd}})
        out.real(section, key, value);
    },
    [](const Model& m) { return dynamic_cast<const Drift1D*>(&m) != nullptr; },
    {}}};
}  // namespace

}  // namespace gssm::testing
