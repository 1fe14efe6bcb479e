#include <gtest/gtest.h>

#include "gssm/error.h"
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
