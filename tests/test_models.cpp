#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "gssm/core/error.h"
#include "gssm/factors/factors.h"
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

namespace {
// The radar with its channel naming the constants h reaches.
class RadarNamingConstants final : public Model {
 public:
  explicit RadarNamingConstants(std::vector<int> used) : Model(radar_.dims(), radar_.names(), radar_.noise()) {
    MeasurementChannel ch = radar_.channel(0);
    ch.constants = std::move(used);
    setChannels({ch});
  }
  std::string name() const override { return "radar naming its constants"; }
  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                    Eigen::MatrixXd* J_f_xc = nullptr, Eigen::MatrixXd* J_f_xb = nullptr) const override {
    return radar_.f(xc, xb, u, dt, J_f_xc, J_f_xb);
  }
  using Model::h;
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc = nullptr,
                    Eigen::MatrixXd* J_h_xb = nullptr) const override {
    return radar_.h(xc, xb, J_h_xc, J_h_xb);
  }

 private:
  static inline const models::Radar2D radar_{};
};
}  // namespace

TEST(MeasurementChannel, NamedConstantsAreCheckedWhereDeclaredAndAgainstTheJacobian) {
  // The range reaches the altitude (x_b[1]), not the speed (x_b[0]).
  const RadarNamingConstants right({1});
  gssm::testing::JacobianPoint p{Eigen::VectorXd::Constant(1, 40.0), Eigen::Vector2d(100, 1000), Eigen::VectorXd(), 0.05};
  gssm::testing::expectChannelsReachOnlyTheirConstants(right, p, 0);
  const RadarNamingConstants wrong({0});
  ::testing::TestPartResultArray caught;  // the check fails on the false claim: the Jacobian and both steps
  {
    ::testing::ScopedFakeTestPartResultReporter intercept(
        ::testing::ScopedFakeTestPartResultReporter::INTERCEPT_ONLY_CURRENT_THREAD, &caught);
    gssm::testing::expectChannelsReachOnlyTheirConstants(wrong, p, 0);
  }
  ASSERT_EQ(caught.size(), 3);
  EXPECT_NE(std::string(caught.GetTestPartResult(0).message()).find("x_b[1]"), std::string::npos);
  EXPECT_NE(std::string(caught.GetTestPartResult(2).message()).find("moves with x_b[1]"), std::string::npos);
  for (const std::vector<int>& bad : {std::vector<int>{1, 0}, std::vector<int>{2}, std::vector<int>{-1}}) {
    try {
      RadarNamingConstants m(bad);
      ADD_FAILURE() << "constants accepted";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("ascending indices into x_b"), std::string::npos) << e.what();
    }
  }
  // A factor on that channel gives the batch solver only those columns.
  const MeasurementFactor f(right, 3, Eigen::VectorXd::Constant(1, 1000.0));
  ASSERT_NE(f.columnsOf(1), nullptr);
  EXPECT_EQ(*f.columnsOf(1), std::vector<int>{1});
  EXPECT_EQ(f.columnsOf(0), nullptr);
  EXPECT_EQ(MeasurementFactor(models::Radar2D(), 3, Eigen::VectorXd::Constant(1, 1000.0)).columnsOf(1), nullptr);
}
