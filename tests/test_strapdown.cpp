// The strapdown step (include/gssm/models/strapdown.h): its Jacobians in the
// tangent space (δθ, δv, δp) and on the biases against central differences
// on ⊕/⊖ at attitudes from level to gimbal lock; an IMU at rest that senses
// only gravity and the Earth's rotation stays where it is; roll and pitch of
// a body at rest come back from its specific force.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "gssm/models/strapdown.h"
#include "manifold_check.h"

using namespace gssm;
using gssm::testing::expectJacobian;
using gssm::testing::Space;
using gssm::testing::vectors3;
using so3::Matrix3;
using so3::Vector3;
using strapdown::NavState;

namespace {
constexpr double kRadPerDeg = M_PI / 180;
const geodesy::Geodetic kAnchor{40.0966268 * kRadPerDeg, -105.1474483 * kRadPerDeg, 1601.474};

Space<NavState> navStates() {
  return {[](const NavState& x, const Eigen::VectorXd& d) {
            NavState y = x;
            y.R = so3::plus(x.R, Vector3(d.segment<3>(0)));
            y.v += d.segment<3>(3);
            y.p += d.segment<3>(6);
            return y;
          },
          [](const NavState& a, const NavState& b) {
            Eigen::VectorXd d(9);
            d << so3::minus(a.R, b.R), a.v - b.v, a.p - b.p;
            return d;
          },
          9};
}

// A car-like state at attitude rpy: 8.7 m/s, 1.3 km from the anchor.
NavState movingAt(const Vector3& rpy) {
  NavState x;
  x.R = so3::fromRollPitchYaw(rpy);
  x.v = Vector3(8.7, -3.0, 0.4);
  x.p = Vector3(350, -1200, 24);
  return x;
}
}  // namespace

TEST(Strapdown, StepJacobiansMatchDifferences) {
  const strapdown::NavFrame frame(kAnchor);
  const Vector3 gyro(0.02, -0.15, 0.3), accel(1.2, -0.4, -9.6), bg(0.001, -0.002, 0.0005), ba(0.05, -0.03, 0.1);
  int i = 0;
  for (const Vector3& rpy : {Vector3(0, 0, 0), Vector3(0.1, -0.12, 2.0), Vector3(3.0, -0.12, 3.1415),
                             Vector3(0.2, M_PI / 2, 1.0), Vector3(-0.3, 0.4, -M_PI + 1e-9)})
    for (double dt : {0.01, 0.25}) {
      const NavState x = movingAt(rpy);
      strapdown::StepJacobians J;
      strapdown::step(x, gyro, accel, bg, ba, dt, frame, &J);
      const std::string at = " at point " + std::to_string(i++);
      expectJacobian<NavState, NavState>("J_next_x" + at,
                                         [&](const NavState& y) { return strapdown::step(y, gyro, accel, bg, ba, dt, frame); },
                                         x, J.J_next_x, navStates(), navStates());
      expectJacobian<Vector3, NavState>("J_next_bg" + at,
                                        [&](const Vector3& b) { return strapdown::step(x, gyro, accel, b, ba, dt, frame); },
                                        bg, J.J_next_bg, vectors3(), navStates());
      expectJacobian<Vector3, NavState>("J_next_ba" + at,
                                        [&](const Vector3& b) { return strapdown::step(x, gyro, accel, bg, b, dt, frame); },
                                        ba, J.J_next_ba, vectors3(), navStates());
    }
}

// Chaining a pack of readings multiplies by each step's J_next_x through its
// block structure (StepJacobians::leftMultiply): the dense product's result,
// at attitudes from level to gimbal lock, short and long steps.
TEST(Strapdown, StructuredLeftMultiplyIsTheDenseProduct) {
  const strapdown::NavFrame frame(kAnchor);
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  for (const Vector3& rpy : {Vector3(0, 0, 0), Vector3(0.2, M_PI / 2, 1.0), Vector3(-0.3, 0.4, -M_PI + 1e-9)})
    for (double dt : {0.01, 0.25}) {
      const NavState x = movingAt(rpy);
      strapdown::StepJacobians J;
      strapdown::step(x, Vector3(0.02, -0.15, 0.3), Vector3(1.2, -0.4, -9.6), Vector3::Zero(), Vector3::Zero(), dt,
                      frame, &J);
      Eigen::Matrix<double, 9, 12> M;
      for (Eigen::Index i = 0; i < M.size(); ++i) M(i) = n01(rng);
      const Eigen::Matrix<double, 9, 12> dense = J.J_next_x * M, structured = J.leftMultiply(M);
      EXPECT_LT((structured - dense).cwiseAbs().maxCoeff(), 1e-12 * (1 + dense.cwiseAbs().maxCoeff()))
          << "rpy " << rpy.transpose() << " dt " << dt;
      const Eigen::Matrix<double, 9, 9> I = Eigen::Matrix<double, 9, 9>::Identity();
      EXPECT_LT((J.leftMultiply(I) - J.J_next_x).cwiseAbs().maxCoeff(), 1e-14) << "rpy " << rpy.transpose();
    }
}

TEST(Strapdown, AnImuAtRestStaysWhereItIs) {
  // At rest the gyros sense the Earth's rotation and the accelerometers the
  // reaction to gravity, in body axes; 100 s at 100 Hz must not move it.
  const strapdown::NavFrame frame(kAnchor);
  for (const Vector3& rpy : {Vector3(0, 0, 0.3), Vector3(M_PI, -6.79 * kRadPerDeg, 185.35 * kRadPerDeg)}) {
    NavState x;
    x.R = so3::fromRollPitchYaw(rpy);
    const Vector3 gyro = x.R.transpose() * frame.earthRate(), accel = -x.R.transpose() * frame.gravity(x.p);
    NavState y = x;
    for (int k = 0; k < 10000; ++k) y = strapdown::step(y, gyro, accel, Vector3::Zero(), Vector3::Zero(), 0.01, frame);
    EXPECT_LT(y.v.norm(), 1e-9) << rpy.transpose();
    EXPECT_LT(y.p.norm(), 1e-7) << rpy.transpose();
    EXPECT_LT(so3::minus(y.R, x.R).norm(), 1e-12) << rpy.transpose();
  }
  // Gravity at the anchor is the site's normal gravity, straight down.
  EXPECT_LT((frame.gravity(Vector3::Zero()) - Vector3(0, 0, geodesy::normalGravity(kAnchor.lat, kAnchor.height))).norm(),
            1e-12);
}

TEST(Strapdown, RollAndPitchFromTheSpecificForceAtRest) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> roll(-M_PI, M_PI), pitch(-1.4, 1.4), yaw(-M_PI, M_PI);
  for (int i = 0; i < 50; ++i) {
    const Vector3 rpy(roll(rng), pitch(rng), yaw(rng));
    const Vector3 f = -so3::fromRollPitchYaw(rpy).transpose() * Vector3(0, 0, 9.797);
    const Eigen::Vector2d rp = strapdown::rollPitchFromSpecificForce(f);
    EXPECT_NEAR(std::remainder(rp.x() - rpy.x(), 2 * M_PI), 0, 1e-12) << rpy.transpose();
    EXPECT_NEAR(rp.y(), rpy.y(), 1e-12) << rpy.transpose();
  }
}

// A pack's readings take gravity from one evaluation at the pack's start
// and its slope: within 1e-7 m/s² of the field over 3 m (the slope is the
// spherical Earth's, 1 % off: ~2e-8 m/s² a metre), where the field itself
// changes by ~5e-6 m/s²; the same as the field at the start point itself.
TEST(Strapdown, LocalGravityFollowsTheFieldOverAPack) {
  const strapdown::NavFrame frame(kAnchor);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const Vector3& p0 : {Vector3(0, 0, 0), Vector3(1000, -700, -100)}) {
    const strapdown::LocalGravity local(frame, p0);
    EXPECT_EQ(local.at(p0), frame.gravity(p0));
    double changed = 0;
    for (int i = 0; i < 50; ++i) {
      const Vector3 p = p0 + 3.0 * Vector3(u(rng), u(rng), u(rng)).normalized();
      EXPECT_LT((local.at(p) - frame.gravity(p)).norm(), 1e-7) << p.transpose();
      changed = std::max(changed, (frame.gravity(p) - frame.gravity(p0)).norm());
    }
    EXPECT_GT(changed, 3e-6);
  }
}

TEST(Strapdown, GravityGradientIsTheGravityFieldsSlope) {
  // Tiny next to the step's other entries (1.5e-6 s⁻²), so checked on its own,
  // relative to its size: the spherical Earth's slope within 1 % of the
  // ellipsoid's normal gravity, 1 km out and 100 m up.
  const strapdown::NavFrame frame(kAnchor);
  for (const Vector3& p : {Vector3(0, 0, 0), Vector3(1000, -700, -100)}) {
    Matrix3 numeric;
    for (int j = 0; j < 3; ++j) {
      const Vector3 d = Vector3::Unit(j) * 1.0;
      numeric.col(j) = (frame.gravity(p + d) - frame.gravity(p - d)) / 2.0;
    }
    Matrix3 analytic;
    frame.gravity(p, &analytic);
    EXPECT_LT((analytic - numeric).norm(), 0.01 * numeric.norm()) << "at " << p.transpose() << "\nanalytic\n"
                                                                  << analytic << "\nnumeric\n" << numeric;
  }
}
