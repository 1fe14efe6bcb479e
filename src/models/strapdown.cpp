#include "gssm/models/strapdown.h"

#include <Eigen/Geometry>
#include <cmath>

namespace gssm::strapdown {

NavFrame::NavFrame(const geodesy::Geodetic& anchor)
    : local_(anchor), ecef_to_frame_(geodesy::nedToEcef(anchor).transpose()) {
  earth_rate_ = geodesy::earthRateNed(anchor.lat);
}

so3::Vector3 NavFrame::gravity(const so3::Vector3& p, so3::Matrix3* J_g_p) const {
  const geodesy::Geodetic g = local_.toGeodetic(p);
  const double gamma = geodesy::normalGravity(g.lat, g.height);
  if (J_g_p) *J_g_p = gamma / (geodesy::transverseRadius(g.lat) + g.height) * so3::Vector3(-1, -1, 2).asDiagonal();
  return gamma * (ecef_to_frame_ * geodesy::nedToEcef(g).col(2));
}

NavState step(const NavState& x, const so3::Vector3& gyro, const so3::Vector3& accel, const so3::Vector3& bg,
              const so3::Vector3& ba, double dt, const NavFrame& frame, StepJacobians* J) {
  return step(x, gyro, accel, bg, ba, dt, frame, LocalGravity(frame, x.p), J);
}

NavState step(const NavState& x, const so3::Vector3& gyro, const so3::Vector3& accel, const so3::Vector3& bg,
              const so3::Vector3& ba, double dt, const NavFrame& frame, const LocalGravity& gravity,
              StepJacobians* J) {
  using so3::Matrix3;
  const so3::Vector3& w_ie = frame.earthRate();
  const so3::Vector3 a_body = accel - ba;
  Matrix3 Jr_w;
  const Matrix3 dR = so3::Exp((gyro - bg) * dt, J ? &Jr_w : nullptr);
  const Matrix3& a_p = gravity.J_g_p;  // ∂g/∂p
  const so3::Vector3 a = x.R * a_body + gravity.at(x.p) - 2 * w_ie.cross(x.v);
  NavState n;
  n.R = so3::Exp(-w_ie * dt) * x.R * dR;
  n.v = x.v + a * dt;
  n.p = x.p + x.v * dt + 0.5 * a * dt * dt;
  if (J) {
    // ∂a/∂θ = −R·hat(a_body), ∂a/∂v = −2·hat(ω_ie), ∂a/∂p = ∂g/∂p, ∂a/∂b_a = −R.
    const Matrix3 a_theta = -x.R * so3::hat(a_body), a_v = -2 * so3::hat(w_ie);
    const Matrix3 I = Matrix3::Identity();
    J->dt = dt;
    J->J_next_x.setZero();
    J->J_next_x.block<3, 3>(0, 0) = dR.transpose();
    J->J_next_x.block<3, 3>(3, 0) = a_theta * dt;
    J->J_next_x.block<3, 3>(3, 3) = I + a_v * dt;
    J->J_next_x.block<3, 3>(3, 6) = a_p * dt;
    J->J_next_x.block<3, 3>(6, 0) = 0.5 * a_theta * dt * dt;
    J->J_next_x.block<3, 3>(6, 3) = I * dt + 0.5 * a_v * dt * dt;
    J->J_next_x.block<3, 3>(6, 6) = I + 0.5 * a_p * dt * dt;
    J->J_next_bg.setZero();
    J->J_next_bg.block<3, 3>(0, 0) = -Jr_w * dt;
    J->J_next_ba.setZero();
    J->J_next_ba.block<3, 3>(3, 0) = -x.R * dt;
    J->J_next_ba.block<3, 3>(6, 0) = -0.5 * x.R * dt * dt;
  }
  return n;
}

Eigen::Vector2d rollPitchFromSpecificForce(const so3::Vector3& f) {
  // f = −Rᵀ(0, 0, g) = g·(sin p, −cos p sin r, −cos p cos r).
  return {std::atan2(-f.y(), -f.z()), std::atan2(f.x(), std::hypot(f.y(), f.z()))};
}

}  // namespace gssm::strapdown
