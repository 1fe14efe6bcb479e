// Rotations on the manifold (include/gssm/core/so3.h): every analytic
// Jacobian against central differences on ⊕/⊖ at attitudes that break
// naive formulas — identity, tiny and series-boundary angles, angles near π,
// gimbal-lock pitch, yaw near ±π — and the maps' round trips.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/LU>

#include "gssm/core/so3.h"
#include "manifold_check.h"

using namespace gssm;
using gssm::testing::expectJacobian;
using gssm::testing::rotations;
using gssm::testing::vectors3;
using so3::Matrix3;
using so3::Vector3;

namespace {
const double kPi = M_PI;

// Rotation vectors at every regime of the closed forms and series.
std::vector<Vector3> tangents() {
  const Vector3 a = Vector3(0.3, -0.5, 0.8).normalized();
  std::vector<Vector3> v{Vector3::Zero(), 1e-9 * a, 3e-5 * a, 2e-4 * a, 0.7 * a, 2.0 * a, (kPi - 1e-3) * a,
                         (kPi - 1e-6) * a, -(kPi - 1e-6) * a, (kPi - 1e-10) * Vector3(0.6, 0, -0.8),
                         Vector3(kPi - 1e-7, 0, 0)};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.8, 1.8);
  for (int i = 0; i < 6; ++i) v.emplace_back(u(rng), u(rng), u(rng));
  return v;
}

// Attitudes: the above as rotations, gimbal lock both ways, yaw near ±π.
std::vector<Matrix3> attitudeMatrices() {
  std::vector<Matrix3> R;
  for (const auto& phi : tangents()) R.push_back(so3::Exp(phi));
  for (const Vector3& rpy : {Vector3(0.3, kPi / 2, 1.0), Vector3(-0.2, -kPi / 2, -2.5), Vector3(0.1, 0.2, kPi - 1e-9),
                             Vector3(-0.1, 0.3, -kPi + 1e-9), Vector3(0.05, kPi / 2 - 1e-7, 0.4)})
    R.push_back(so3::fromRollPitchYaw(rpy));
  return R;
}

std::string at(int i) { return " at point " + std::to_string(i); }
}  // namespace

TEST(So3, ExpAndLogJacobiansMatchDifferences) {
  int i = 0;
  for (const Vector3& phi : tangents()) {
    Matrix3 J;
    so3::Exp(phi, &J);
    expectJacobian<Vector3, Matrix3>("J_Exp_phi" + at(i), [](const Vector3& p) { return so3::Exp(p); }, phi, J,
                                     vectors3(), rotations());
    const Matrix3 R = so3::Exp(phi);
    so3::Log(R, &J);
    if (phi.norm() < kPi - 1e-5)  // Log jumps at π (φ and −φ are the same rotation)
      expectJacobian<Matrix3, Vector3>("J_Log_R" + at(i), [](const Matrix3& r) { return so3::Log(r); }, R, J,
                                       rotations(), vectors3());
    ++i;
  }
}

TEST(So3, GroupOperationJacobiansMatchDifferences) {
  const std::vector<Matrix3> Rs = attitudeMatrices();
  const Vector3 v(1.5, -0.4, 2.0), theta(0.2, -0.1, 0.3);
  for (std::size_t i = 0; i + 1 < Rs.size(); ++i) {
    const Matrix3 &R = Rs[i], &S = Rs[i + 1];
    Matrix3 J1, J2;
    so3::plus(R, theta, &J1, &J2);
    expectJacobian<Matrix3, Matrix3>("J_plus_R" + at(i), [&](const Matrix3& r) { return so3::plus(r, theta); }, R, J1,
                                     rotations(), rotations());
    expectJacobian<Vector3, Matrix3>("J_plus_theta" + at(i), [&](const Vector3& t) { return so3::plus(R, t); }, theta,
                                     J2, vectors3(), rotations());
    so3::compose(R, S, &J1, &J2);
    expectJacobian<Matrix3, Matrix3>("J_compose_R1" + at(i), [&](const Matrix3& r) { return so3::compose(r, S); }, R,
                                     J1, rotations(), rotations());
    expectJacobian<Matrix3, Matrix3>("J_compose_R2" + at(i), [&](const Matrix3& s) { return so3::compose(R, s); }, S,
                                     J2, rotations(), rotations());
    so3::inverse(R, &J1);
    expectJacobian<Matrix3, Matrix3>("J_inverse_R" + at(i), [](const Matrix3& r) { return so3::inverse(r); }, R, J1,
                                     rotations(), rotations());
    so3::act(R, v, &J1, &J2);
    expectJacobian<Matrix3, Vector3>("J_act_R" + at(i), [&](const Matrix3& r) { return so3::act(r, v); }, R, J1,
                                     rotations(), vectors3());
    expectJacobian<Vector3, Vector3>("J_act_v" + at(i), [&](const Vector3& w) { return so3::act(R, w); }, v, J2,
                                     vectors3(), vectors3());
    if (so3::minus(R, S).norm() < kPi - 1e-5) {  // ⊖ jumps where R and S are π apart
      so3::minus(R, S, &J1, &J2);
      expectJacobian<Matrix3, Vector3>("J_minus_R1" + at(i), [&](const Matrix3& r) { return so3::minus(r, S); }, R,
                                       J1, rotations(), vectors3());
      expectJacobian<Matrix3, Vector3>("J_minus_R2" + at(i), [&](const Matrix3& s) { return so3::minus(R, s); }, S,
                                       J2, rotations(), vectors3());
    }
  }
}

TEST(So3, EulerAnglesJacobianMatchesDifferencesAwayFromGimbalLock) {
  // Euler angles differ as angles: yaw near ±π wraps.
  gssm::testing::Space<Vector3> euler = vectors3();
  euler.minus = [](const Vector3& a, const Vector3& b) {
    Eigen::VectorXd d = a - b;
    for (int k = 0; k < 3; ++k) d[k] = std::remainder(d[k], 2 * kPi);
    return d;
  };
  int i = 0, checked = 0;
  for (const Matrix3& R : attitudeMatrices()) {
    Matrix3 J;
    const Vector3 rpy = so3::rollPitchYaw(R, &J);
    if (std::abs(std::cos(rpy.y())) > 1e-3) {
      expectJacobian<Matrix3, Vector3>("J_rpy_R" + at(i), [](const Matrix3& r) { return so3::rollPitchYaw(r); }, R, J,
                                       rotations(), euler, 1e-5);
      ++checked;
    }
    ++i;
  }
  EXPECT_GE(checked, 15);
}

TEST(So3, RotationOfEulerAnglesJacobianMatchesDifferences) {
  // J_out_rpy everywhere, gimbal lock included (the map itself is smooth).
  int i = 0;
  for (const Matrix3& R : attitudeMatrices()) {
    const Vector3 rpy = so3::rollPitchYaw(R) + Vector3(0.1, 0.0, -0.2);
    Matrix3 J;
    so3::fromRollPitchYaw(rpy, &J);
    expectJacobian<Vector3, Matrix3>("J_R_rpy" + at(i++), [](const Vector3& a) { return so3::fromRollPitchYaw(a); },
                                     rpy, J, vectors3(), rotations(), 1e-7);
  }
  // and its inverse is rollPitchYaw's (Euler rates ↔ body rates)
  Matrix3 J_rpy_R, J_R_rpy;
  so3::fromRollPitchYaw(so3::rollPitchYaw(so3::Exp(Vector3(0.3, -0.4, 2.0)), &J_rpy_R), &J_R_rpy);
  EXPECT_LT((J_rpy_R * J_R_rpy - Matrix3::Identity()).norm(), 1e-12);
}

TEST(So3, MapsRoundTrip) {
  for (const Vector3& phi : tangents()) {
    const Vector3 back = so3::Log(so3::Exp(phi));
    EXPECT_LT((back - phi).norm(), 1e-12 * (1 + phi.norm()) + (phi.norm() > kPi - 1e-5 ? 1e-8 : 0)) << phi.transpose();
    EXPECT_LT((so3::rightJacobian(phi) * so3::rightJacobianInverse(phi) - Matrix3::Identity()).norm(), 1e-9)
        << phi.transpose();
  }
  const std::vector<Matrix3> Rs = attitudeMatrices();
  for (std::size_t i = 0; i < Rs.size(); ++i) {
    const Matrix3& R = Rs[i];
    EXPECT_LT((so3::Exp(so3::Log(R)) - R).norm(), 1e-9) << "point " << i;
    EXPECT_LT((R.transpose() * R - Matrix3::Identity()).norm(), 1e-12) << "point " << i;
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12) << "point " << i;
    // Euler angles give the rotation back, at gimbal lock too (roll 0 there).
    EXPECT_LT((so3::fromRollPitchYaw(so3::rollPitchYaw(R)) - R).norm(), 1e-9) << "point " << i;
    const Matrix3& S = Rs[(i + 1) % Rs.size()];
    EXPECT_LT((so3::plus(R, so3::minus(S, R)) - S).norm(), 1e-9) << "point " << i;
  }
  // Near π from a product, whose rounding is not antisymmetric like Exp's:
  // the axis must come from R + Rᵀ, not from R − Rᵀ (~1e-10 there).
  const Vector3 axis = Vector3(-0.2, 0.9, 0.4).normalized();
  const Matrix3 near_pi = so3::Exp(axis * 1.3) * so3::Exp(axis * (kPi - 1.3 - 1e-10));
  EXPECT_LT((so3::Log(near_pi) - axis * (kPi - 1e-10)).norm(), 1e-12);
  const Vector3 rpy(0.3, -0.4, kPi - 1e-9);
  EXPECT_LT((so3::rollPitchYaw(so3::fromRollPitchYaw(rpy)) - rpy).norm(), 1e-12);
}

TEST(So3, EulerAnglesFollowTheAerospaceConvention) {
  // Yaw 90° turns the body's x axis (forward) to the navigation y axis (east);
  // pitch up 30° lifts it: NED z is down, so its z becomes −sin 30°.
  const Matrix3 R = so3::fromRollPitchYaw(Vector3(0, kPi / 6, kPi / 2));
  EXPECT_LT((R * Vector3::UnitX() - Vector3(0, std::cos(kPi / 6), -0.5)).norm(), 1e-15);
  EXPECT_LT((so3::fromRollPitchYaw(Vector3(0.4, 0, 0)) - so3::Exp(Vector3(0.4, 0, 0))).norm(), 1e-15);
}

TEST(So3, OrthonormalizedIsTheNearestRotation) {
  Matrix3 R = so3::Exp(Vector3(0.4, -1.1, 2.2));
  Matrix3 drifted = R;
  drifted(0, 1) += 1e-6;
  drifted(2, 0) -= 2e-6;
  const Matrix3 Q = so3::orthonormalized(drifted);
  EXPECT_LT((Q.transpose() * Q - Matrix3::Identity()).norm(), 1e-14);
  EXPECT_NEAR(Q.determinant(), 1.0, 1e-14);
  EXPECT_LT((Q - R).norm(), 3e-6);
  EXPECT_LT((so3::orthonormalized(R) - R).norm(), 1e-14);
}
