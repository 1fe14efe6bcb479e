#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "gssm/core/error.h"
#include "gssm/models/linear.h"
#include "gssm/models/radar2d.h"
#include "jacobian_check.h"
#include "reference_kalman.h"

using namespace gssm;
using gssm::testing::JacobianPoint;
using gssm::testing::uniformVector;

TEST(Radar2D, AnalyticJacobiansMatchCentralDifferences) {
  models::Radar2D radar;
  gssm::testing::expectJacobiansMatchDifferences(radar, [](std::mt19937& rng) {
    JacobianPoint p;
    p.xc = uniformVector(rng, 1, -500, 500);
    p.xb = uniformVector(rng, 2, -300, 3000);
    p.xb[1] = std::abs(p.xb[1]) + 10;  // keep away from rho = 0
    p.u = Eigen::VectorXd(0);
    p.dt = 0.05;
    return p;
  });
}

TEST(Radar2D, PaperDefaults) {
  models::Radar2D radar;
  EXPECT_EQ(radar.dims().nc, 1);
  EXPECT_EQ(radar.dims().nb, 2);
  EXPECT_DOUBLE_EQ(radar.nominalStep(), 0.05);
  EXPECT_DOUBLE_EQ(radar.noise().Q(0, 0), 0.005 * 0.005);
  EXPECT_DOUBLE_EQ(radar.measurementNoise()(0, 0), 9.0);
  EXPECT_EQ(radar.stackedStateNames(), (std::vector<std::string>{"x", "xdot", "h"}));
  // range of (x, h) = (300, 400) is 500
  EXPECT_DOUBLE_EQ(radar.h(Eigen::VectorXd::Constant(1, 300), Eigen::Vector2d(0, 400))[0], 500);
}

TEST(LinearModel, EulerAndExactJacobiansMatchCentralDifferences) {
  std::mt19937 rng(7);
  models::LinearSystem sys = gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1);
  sys.B = Eigen::MatrixXd::Random(3, 1);
  for (auto disc : {models::Discretization::Euler, models::Discretization::Exact}) {
    models::LinearModel m(sys, disc);
    gssm::testing::expectJacobiansMatchDifferences(m, [](std::mt19937& r) {
      return JacobianPoint{uniformVector(r, 3, -2, 2), uniformVector(r, 2, -2, 2),
                           uniformVector(r, 1, -1, 1), 0.07};
    });
  }
}

TEST(LinearModel, ExactDiscretizationMatchesEulerForSmallSteps) {
  std::mt19937 rng(8);
  models::LinearSystem sys = gssm::testing::randomLinearSystem(rng, 3, 2, 2, 1e-5);
  models::LinearModel euler(sys), exact(sys, models::Discretization::Exact);
  Eigen::MatrixXd Fe, Fbe, Be, Fx, Fbx, Bx;
  euler.discreteMatrices(1e-5, Fe, Fbe, Be);
  exact.discreteMatrices(1e-5, Fx, Fbx, Bx);
  EXPECT_LT((Fe - Fx).norm(), 1e-8);
  EXPECT_LT((Fbe - Fbx).norm(), 1e-8);
  // and differs at a large step, as it should (second-order term A_c A_b T²/2)
  euler.discreteMatrices(0.5, Fe, Fbe, Be);
  exact.discreteMatrices(0.5, Fx, Fbx, Bx);
  EXPECT_NEAR((Fbx - Fbe).norm(), (0.5 * sys.A_c * sys.A_b * 0.25).norm(),
              0.5 * (0.5 * sys.A_c * sys.A_b * 0.25).norm());
}

TEST(Model, RejectsBadDimensionsAndCovariances) {
  models::Radar2D::Params p;
  p.r = 0.0;
  try {
    models::Radar2D bad(p);
    FAIL() << "zero measurement variance accepted";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("measurement noise R"), std::string::npos) << e.what();
  }
  p = {};
  p.T = -1;
  EXPECT_THROW(models::Radar2D{p}, InvalidArgument);
  std::mt19937 rng(1);
  models::LinearSystem sys = gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1);
  sys.C_b = Eigen::MatrixXd::Zero(2, 3);
  EXPECT_THROW(models::LinearModel{sys}, InvalidArgument);
}

#include "gssm/models/nav2d.h"

TEST(Nav2D, AnalyticJacobiansMatchCentralDifferences) {
  models::Nav2D nav;
  gssm::testing::expectJacobiansMatchDifferences(nav, [](std::mt19937& rng) {
    JacobianPoint p;
    p.xc = uniformVector(rng, 4, -50, 250);
    p.xc.tail<2>() = uniformVector(rng, 2, -10, 10);
    p.xb = uniformVector(rng, 3, -1, 1);
    p.u = uniformVector(rng, 2, -3, 3);
    p.dt = 0.1;
    return p;
  });
}

TEST(Nav2D, ProcessNoiseIsTheWhiteAccelerationModel) {
  models::Nav2D nav;
  const Eigen::MatrixXd Q = nav.processNoise(0.2);
  EXPECT_NEAR(Q(0, 0), 0.05 * 0.05 * 0.008 / 3, 1e-15);
  EXPECT_NEAR(Q(0, 2), 0.05 * 0.05 * 0.02, 1e-15);
  EXPECT_NEAR(Q(2, 2), 0.05 * 0.05 * 0.2, 1e-15);
  EXPECT_EQ(Q(0, 1), 0.0);
  EXPECT_GT(Eigen::LLT<Eigen::MatrixXd>(Q).info() == Eigen::Success, 0);
  // constant acceleration integrates exactly: u − b_a = (1, 0) over 1 s
  const Eigen::VectorXd x = nav.f(Eigen::Vector4d(0, 0, 0, 0), Eigen::Vector3d(0.5, 0, 0), Eigen::Vector2d(1.5, 0), 1.0);
  EXPECT_DOUBLE_EQ(x[0], 0.5);
  EXPECT_DOUBLE_EQ(x[2], 1.0);
}
