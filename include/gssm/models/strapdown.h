#pragma once
// Strapdown inertial navigation in a local-level north-east-down frame fixed
// to the Earth at an anchor point (the first GNSS fix): attitude on SO(3),
// velocity and position in that frame, the IMU's rates and specific forces
// held over each sample interval; Earth rotation and normal gravity included
// (Groves, "Principles of GNSS, Inertial, and Multisensor Integrated
// Navigation Systems", 2nd ed., §5.2: the Earth-frame mechanization, with
// the frame's axes those of NED at the anchor). The navigation model of issue
// #37 propagates its states with strapdownStep.
#include <Eigen/Core>

#include "gssm/core/so3.h"
#include "gssm/models/geodesy.h"

namespace gssm::strapdown {

/// Attitude (body → frame), velocity over the Earth and position, in the anchored NED frame.
struct NavState {
  so3::Matrix3 R = so3::Matrix3::Identity();
  so3::Vector3 v = so3::Vector3::Zero();
  so3::Vector3 p = so3::Vector3::Zero();
};

/// Jacobians of one step in the tangent order (δθ, δv, δp): δθ the
/// body-frame rotation of R ⊕ δθ = R·Exp(δθ). J_next_x has the step's
/// block structure, with A_θ = ∂a/∂θ·dt, A_v = ∂a/∂v·dt, A_p = ∂a/∂p·dt:
///   [ dRᵀ      0              0           ]
///   [ A_θ      I + A_v        A_p         ]
///   [ ½dt·A_θ  dt·I + ½dt·A_v I + ½dt·A_p ]
struct StepJacobians {
  Eigen::Matrix<double, 9, 9> J_next_x;
  Eigen::Matrix<double, 9, 3> J_next_bg;  ///< gyro bias
  Eigen::Matrix<double, 9, 3> J_next_ba;  ///< accelerometer bias
  double dt = 0;                          ///< the step's interval

  /// J_next_x·M from its blocks: ~half the multiplications of the dense
  /// product, which chaining a pack of readings pays at every reading
  /// (docs/DESIGN.md §12). N_v = M_v + T and N_p = M_p + dt·M_v + ½dt·T
  /// with T = A_θ·M_θ + A_v·M_v + A_p·M_p.
  template <int K>
  Eigen::Matrix<double, 9, K> leftMultiply(const Eigen::Matrix<double, 9, K>& M) const {
    const auto Mt = M.template topRows<3>(), Mv = M.template middleRows<3>(3), Mp = M.template bottomRows<3>();
    const so3::Matrix3 Av = J_next_x.block<3, 3>(3, 3) - so3::Matrix3::Identity();
    const Eigen::Matrix<double, 3, K> T = J_next_x.block<3, 3>(3, 0).lazyProduct(Mt) + Av.lazyProduct(Mv) +
                                          J_next_x.block<3, 3>(3, 6).lazyProduct(Mp);
    Eigen::Matrix<double, 9, K> N;
    N.template topRows<3>() = J_next_x.block<3, 3>(0, 0).lazyProduct(Mt);
    N.template middleRows<3>(3) = Mv + T;
    N.template bottomRows<3>() = Mp + dt * Mv + (0.5 * dt) * T;
    return N;
  }
};

/// The anchored frame: the Earth's rotation in it (constant: the frame turns
/// with the Earth) and normal gravity at any point of it.
class NavFrame {
 public:
  explicit NavFrame(const geodesy::Geodetic& anchor);
  const geodesy::LocalFrame& local() const { return local_; }
  /// ω_ie in the frame's axes.
  const so3::Vector3& earthRate() const { return earth_rate_; }
  /// Normal gravity at position p of the frame, along that point's own
  /// down (which tilts by the distance over the Earth's radius); J_g_p the
  /// tilt of the down direction and the height gradient (γ/R_E·diag(−1, −1,
  /// 2), a spherical Earth's; ellipsoidal terms 0.3 % of it), from the same
  /// geodetic point (one iteration of the coordinates per IMU sample).
  so3::Vector3 gravity(const so3::Vector3& p, so3::Matrix3* J_g_p = nullptr) const;

 private:
  geodesy::LocalFrame local_;
  so3::Vector3 earth_rate_;
  so3::Matrix3 ecef_to_frame_;
};

/// Normal gravity about a point p0 of the frame, to first order: g(p) =
/// g(p0) + J_g_p·(p − p0), J_g_p the spherical Earth's slope (1 % off the
/// ellipsoid's). Over a pack of readings (a few metres) that is ~2e-8
/// m/s² a metre off the field, five decades under any accelerometer's
/// noise: a pack's readings share one evaluation of the geodetic
/// coordinates (a tenth of a filter pass's work).
struct LocalGravity {
  LocalGravity(const NavFrame& frame, const so3::Vector3& p0) : p0(p0), g0(frame.gravity(p0, &J_g_p)) {}
  so3::Vector3 at(const so3::Vector3& p) const { return g0 + J_g_p * (p - p0); }
  so3::Vector3 p0, g0;
  so3::Matrix3 J_g_p;
};

/// One IMU interval of dt seconds with the measured rate `gyro` (rad/s) and
/// specific force `accel` (m/s²), both in body axes, less the biases bg, ba:
///   R' = Exp(−ω_ie·dt)·R·Exp((ω̃ − b_g)·dt)
///   v' = v + a·dt,  p' = p + v·dt + ½·a·dt²,  a = R(f̃ − b_a) + g(p) − 2 ω_ie × v.
NavState step(const NavState& x, const so3::Vector3& gyro, const so3::Vector3& accel, const so3::Vector3& bg,
              const so3::Vector3& ba, double dt, const NavFrame& frame, StepJacobians* J = nullptr);
/// The same with gravity from `gravity` (one of a pack's readings); with
/// p0 = x.p it is the step above.
NavState step(const NavState& x, const so3::Vector3& gyro, const so3::Vector3& accel, const so3::Vector3& bg,
              const so3::Vector3& ba, double dt, const NavFrame& frame, const LocalGravity& gravity,
              StepJacobians* J = nullptr);

/// Roll and pitch (rad) of a body at rest from its specific force, which is
/// then the reaction to gravity: f = −Rᵀ·(0, 0, g).
Eigen::Vector2d rollPitchFromSpecificForce(const so3::Vector3& f);

}  // namespace gssm::strapdown
