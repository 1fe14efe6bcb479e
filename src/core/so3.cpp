#include "gssm/core/so3.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace gssm::so3 {

namespace {
// Below this angle the closed forms lose digits to cancellation: their
// Taylor series to θ⁴ are exact to rounding there (the next term ~1e-16·θ⁶).
constexpr double kSmallAngle = 1e-4;

// Coefficients of Rodrigues' formula and of the Jacobians at angle θ:
// a = sin θ/θ, b = (1 − cos θ)/θ², c = (θ − sin θ)/θ³.
struct Coefficients {
  double a, b, c;
};
Coefficients coefficients(double theta) {
  const double t2 = theta * theta;
  if (theta < kSmallAngle)
    return {1 - t2 / 6 + t2 * t2 / 120, 0.5 - t2 / 24 + t2 * t2 / 720, 1.0 / 6 - t2 / 120 + t2 * t2 / 5040};
  const double s = std::sin(theta), co = std::cos(theta);
  return {s / theta, (1 - co) / t2, (theta - s) / (t2 * theta)};
}
}  // namespace

Matrix3 hat(const Vector3& w) {
  Matrix3 W;
  W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return W;
}

Vector3 vee(const Matrix3& W) { return 0.5 * Vector3(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1)); }

Matrix3 Exp(const Vector3& phi, Matrix3* J_R_phi) {
  const Coefficients k = coefficients(phi.norm());
  const Matrix3 W = hat(phi), W2 = W * W;
  if (J_R_phi) *J_R_phi = Matrix3::Identity() - k.b * W + k.c * W2;
  return Matrix3::Identity() + k.a * W + k.b * W2;
}

Matrix3 rightJacobian(const Vector3& phi) {
  const Coefficients k = coefficients(phi.norm());
  const Matrix3 W = hat(phi);
  return Matrix3::Identity() - k.b * W + k.c * W * W;
}

Matrix3 rightJacobianInverse(const Vector3& phi) {
  // Jr⁻¹(φ) = I + ½ hat(φ) + d·hat(φ)², d = 1/θ² − cot(θ/2)/(2θ): cot(θ/2)
  // rather than (1 + cos θ)/sin θ, which is 0/0 at θ = π.
  const double theta = phi.norm(), t2 = theta * theta;
  const double d = theta < kSmallAngle ? 1.0 / 12 + t2 / 720 + t2 * t2 / 30240
                                       : 1 / t2 - std::cos(theta / 2) / (2 * theta * std::sin(theta / 2));
  const Matrix3 W = hat(phi);
  return Matrix3::Identity() + 0.5 * W + d * W * W;
}

Vector3 Log(const Matrix3& R, Matrix3* J_phi_R) {
  // θ from both its cosine and its sine: acos alone loses half the digits
  // near 0 and near π.
  const Vector3 s2 = 2 * vee(R);  // 2 sin θ · axis
  const double cos_theta = std::clamp((R.trace() - 1) / 2, -1.0, 1.0);
  const double theta = std::atan2(0.5 * s2.norm(), cos_theta);
  Vector3 phi;
  if (theta < kSmallAngle) {
    phi = 0.5 * s2 * (1 + theta * theta / 6 + 7 * theta * theta * theta * theta / 360);  // θ/(2 sin θ)·s2
  } else if (theta < M_PI - 1e-3) {
    phi = theta / (2 * std::sin(theta)) * s2;
  } else {
    // Near π the axis comes from the symmetric part: (R + Rᵀ)/2 − cos θ·I =
    // (1 − cos θ)·a aᵀ; its largest column, its sign from sin θ·a.
    const Matrix3 B = 0.5 * (R + R.transpose()) - cos_theta * Matrix3::Identity();
    Eigen::Index i = 0;
    B.diagonal().maxCoeff(&i);
    Vector3 axis = B.col(i) / std::sqrt(std::max(B(i, i), 1e-300) * (1 - cos_theta));
    axis.normalize();
    if (axis.dot(s2) < 0) axis = -axis;
    phi = theta * axis;
  }
  if (J_phi_R) *J_phi_R = rightJacobianInverse(phi);
  return phi;
}

Matrix3 plus(const Matrix3& R, const Vector3& theta, Matrix3* J_out_R, Matrix3* J_out_theta) {
  const Matrix3 E = Exp(theta, J_out_theta);
  if (J_out_R) *J_out_R = E.transpose();
  return R * E;
}

Vector3 minus(const Matrix3& R1, const Matrix3& R2, Matrix3* J_tau_R1, Matrix3* J_tau_R2) {
  const Vector3 tau = Log(R2.transpose() * R1);
  if (J_tau_R1) *J_tau_R1 = rightJacobianInverse(tau);
  if (J_tau_R2) *J_tau_R2 = -rightJacobianInverse(-tau);
  return tau;
}

Matrix3 compose(const Matrix3& R1, const Matrix3& R2, Matrix3* J_out_R1, Matrix3* J_out_R2) {
  if (J_out_R1) *J_out_R1 = R2.transpose();
  if (J_out_R2) J_out_R2->setIdentity();
  return R1 * R2;
}

Matrix3 inverse(const Matrix3& R, Matrix3* J_out_R) {
  if (J_out_R) *J_out_R = -R;
  return R.transpose();
}

Vector3 act(const Matrix3& R, const Vector3& v, Matrix3* J_out_R, Matrix3* J_out_v) {
  if (J_out_R) *J_out_R = -R * hat(v);
  if (J_out_v) *J_out_v = R;
  return R * v;
}

Matrix3 fromRollPitchYaw(const Vector3& rpy, Matrix3* J_out_rpy) {
  const double cr = std::cos(rpy.x()), sr = std::sin(rpy.x()), cp = std::cos(rpy.y()), sp = std::sin(rpy.y());
  const double cy = std::cos(rpy.z()), sy = std::sin(rpy.z());
  if (J_out_rpy) *J_out_rpy << 1, 0, -sp, 0, cr, sr * cp, 0, -sr, cr * cp;
  Matrix3 R;
  R << cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,  //
      sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,   //
      -sp, cp * sr, cp * cr;
  return R;
}

Vector3 rollPitchYaw(const Matrix3& R, Matrix3* J_rpy_R) {
  const double cp = std::hypot(R(2, 1), R(2, 2));
  const double pitch = std::atan2(-R(2, 0), cp);
  double roll, yaw;
  if (cp > 1e-12) {
    roll = std::atan2(R(2, 1), R(2, 2));
    yaw = std::atan2(R(1, 0), R(0, 0));
  } else {  // gimbal lock: R's first two rows depend on yaw ∓ roll only
    roll = 0;
    yaw = std::atan2(-R(0, 1), R(1, 1));
  }
  if (J_rpy_R && std::abs(std::cos(pitch)) > 1e-9) {
    // A body-frame rotation θ moves the Euler angles by W·θ (the body rates
    // → Euler rates matrix).
    const double sr = std::sin(roll), cr = std::cos(roll), tp = std::tan(pitch), c = std::cos(pitch);
    *J_rpy_R << 1, sr * tp, cr * tp, 0, cr, -sr, 0, sr / c, cr / c;
  }
  return {roll, pitch, yaw};
}

Matrix3 orthonormalized(const Matrix3& R) {
  const Eigen::JacobiSVD<Matrix3> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3 Q = svd.matrixU() * svd.matrixV().transpose();
  if (Q.determinant() < 0) {  // a reflection: flip the weakest direction
    Matrix3 U = svd.matrixU();
    U.col(2) = -U.col(2);
    Q = U * svd.matrixV().transpose();
  }
  return Q;
}

}  // namespace gssm::so3
