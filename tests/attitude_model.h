#pragma once
// A model with a rotation state for the manifold tests (docs/DESIGN.md §12):
// attitude R = Exp(φ) (body → world) driven by a gyro ω̃ with a constant
// bias b, R' = R·Exp((ω̃ − b)·dt), seen through two known world directions
// measured in the body frame, y = Rᵀv (gravity on channel 0, north on 1).
#include <Eigen/Core>

#include "gssm/core/so3.h"
#include "gssm/model/model.h"

namespace gssm::testing {

class AttitudeModel final : public Model {
 public:
  /// gyro_sd: white rate noise (rad/s/√Hz); vector_sd: σ of each measured component.
  AttitudeModel(double T, double gyro_sd, double vector_sd, double bias_sd, double attitude_sd)
      : Model({3, 3, 3, 3}, {{"phi_x", "phi_y", "phi_z"}, {"bg_x", "bg_y", "bg_z"}, {"wx", "wy", "wz"},
                             {"g_x", "g_y", "g_z"}},
              noise(T, gyro_sd, vector_sd, bias_sd, attitude_sd)),
        gyro_var_(gyro_sd * gyro_sd) {
    MeasurementChannel g, n;
    g.name = "gravity", g.components = {"g_x", "g_y", "g_z"};
    n.name = "north", n.components = {"n_x", "n_y", "n_z"};
    g.R = n.R = Eigen::Matrix3d::Identity() * vector_sd * vector_sd;
    setChannels({g, n});
    setRotationBlocks({0});
  }
  std::string name() const override { return "attitude_test"; }

  // f(R ⊕ δ) ⊖ f(R) = Exp(wdt)ᵀδ; b + ε turns the step by −Jr(wdt)·ε·dt.
  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                    Eigen::MatrixXd* J_f_xc = nullptr, Eigen::MatrixXd* J_f_xb = nullptr) const override {
    const Eigen::Vector3d w = (u - xb) * dt;
    const Eigen::Matrix3d step = so3::Exp(w);
    if (J_f_xc) *J_f_xc = step.transpose();
    if (J_f_xb) *J_f_xb = -so3::rightJacobian(w) * dt;
    return so3::Log(so3::Exp(xc) * step);
  }
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc = nullptr,
                    Eigen::MatrixXd* J_h_xb = nullptr) const override {
    return h(0, xc, xb, J_h_xc, J_h_xb);
  }
  // (R·Exp(δ))ᵀv = Exp(−δ)·Rᵀv ≈ Rᵀv + [Rᵀv]×·δ.
  Eigen::VectorXd h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& /*xb*/, Eigen::MatrixXd* J_h_xc = nullptr,
                    Eigen::MatrixXd* J_h_xb = nullptr) const override {
    const Eigen::Vector3d v = this->channel(channel).name == "gravity" ? Eigen::Vector3d(0, 0, 9.8)
                                                                        : Eigen::Vector3d(1, 0, 0);
    const Eigen::Vector3d y = so3::Exp(xc).transpose() * v;
    if (J_h_xc) *J_h_xc = so3::hat(y);
    if (J_h_xb) *J_h_xb = Eigen::Matrix3d::Zero();
    return y;
  }
  Eigen::MatrixXd processNoise(double dt) const override { return Eigen::Matrix3d::Identity() * gyro_var_ * dt; }

 private:
  static ModelNoise noise(double T, double gyro_sd, double vector_sd, double bias_sd, double attitude_sd) {
    ModelNoise n;
    n.T = T;
    n.Q = Eigen::Matrix3d::Identity() * gyro_sd * gyro_sd * T;
    n.R = Eigen::Matrix3d::Identity() * vector_sd * vector_sd;
    n.prior_state = {Eigen::Vector3d(0.1, -0.2, 3.0), Eigen::Matrix3d::Identity() * attitude_sd * attitude_sd};
    n.prior_constants = {Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity() * bias_sd * bias_sd};
    return n;
  }
  double gyro_var_;
};

}  // namespace gssm::testing
