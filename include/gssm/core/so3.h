#pragma once
// Rotations as a manifold (SO(3)): the exponential and logarithm maps, the
// right Jacobians, ⊕/⊖ and the group operations, each with its optional
// Jacobians J_out_in in the right (body-frame) tangent convention of manif
// (J. Solà, D. Atchuthan, J. Deray, "A micro Lie theory for state estimation
// in robotics", 2018, App. B):
//   R ⊕ θ = R·Exp(θ),   R₁ ⊖ R₂ = Log(R₂ᵀ·R₁),
//   J_f_R = ∂(f(R ⊕ θ) ⊖ f(R))/∂θ at θ = 0.
// The strapdown navigation model keeps attitude this way: a rotation in the
// state, a 3-vector tangent in every Jacobian and update.
#include <Eigen/Core>

namespace gssm::so3 {

using Matrix3 = Eigen::Matrix3d;
using Vector3 = Eigen::Vector3d;

/// The skew-symmetric matrix of w: hat(w)·v = w × v.
Matrix3 hat(const Vector3& w);
/// w from a skew-symmetric matrix (its antisymmetric part, for any 3×3).
Vector3 vee(const Matrix3& W);

/// Exp(φ) by Rodrigues' formula, series below 1e-4 rad;
/// J_R_phi = Jr(φ).
Matrix3 Exp(const Vector3& phi, Matrix3* J_R_phi = nullptr);
/// Log(R) ∈ {|φ| ≤ π}, accurate near 0 and near π (the axis from
/// R + Rᵀ there); J_phi_R = Jr⁻¹(φ).
Vector3 Log(const Matrix3& R, Matrix3* J_phi_R = nullptr);

/// Right Jacobian Jr(φ) and its inverse; the left ones are
/// Jl(φ) = Jr(−φ).
Matrix3 rightJacobian(const Vector3& phi);
Matrix3 rightJacobianInverse(const Vector3& phi);

/// R ⊕ θ = R·Exp(θ): J_out_R = Exp(θ)ᵀ, J_out_theta = Jr(θ).
Matrix3 plus(const Matrix3& R, const Vector3& theta, Matrix3* J_out_R = nullptr, Matrix3* J_out_theta = nullptr);
/// R₁ ⊖ R₂ = Log(R₂ᵀR₁) = τ: J_tau_R1 = Jr⁻¹(τ), J_tau_R2 = −Jr⁻¹(−τ).
Vector3 minus(const Matrix3& R1, const Matrix3& R2, Matrix3* J_tau_R1 = nullptr, Matrix3* J_tau_R2 = nullptr);
/// R₁R₂: J_out_R1 = R₂ᵀ, J_out_R2 = I.
Matrix3 compose(const Matrix3& R1, const Matrix3& R2, Matrix3* J_out_R1 = nullptr, Matrix3* J_out_R2 = nullptr);
/// Rᵀ: J_out_R = −R.
Matrix3 inverse(const Matrix3& R, Matrix3* J_out_R = nullptr);
/// R·v: J_out_R = −R·hat(v), J_out_v = R.
Vector3 act(const Matrix3& R, const Vector3& v, Matrix3* J_out_R = nullptr, Matrix3* J_out_v = nullptr);

/// The rotation body → navigation frame of roll, pitch and yaw (rad; ZYX:
/// R = Rz(yaw)·Ry(pitch)·Rx(roll), the aerospace convention in NED).
/// J_out_rpy: R(rpy + d) = R·Exp(J·d) to first order, the Euler rates → body
/// rates matrix [[1, 0, −sin p], [0, cos r, sin r cos p], [0, −sin r, cos r cos p]].
Matrix3 fromRollPitchYaw(const Vector3& rpy, Matrix3* J_out_rpy = nullptr);
/// Roll, pitch, yaw of R, pitch in [−π/2, π/2], roll and yaw in (−π, π].
/// At pitch ±π/2 (gimbal lock) only yaw ∓ roll is defined: roll is 0
/// there. J_rpy_R (the body rates → Euler rates matrix) is singular at
/// gimbal lock and only filled away from it (|cos pitch| > 1e-9).
Vector3 rollPitchYaw(const Matrix3& R, Matrix3* J_rpy_R = nullptr);

/// The nearest rotation to a matrix that drifted from one (after many
/// compositions in floating point), by its polar decomposition.
Matrix3 orthonormalized(const Matrix3& R);

}  // namespace gssm::so3
