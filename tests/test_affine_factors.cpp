// A model that declares f (or h) affine lets the smoothers skip those
// factors' linearization check (Model::processIsAffine,
// measurementIsAffine): the estimates must be those of the same model
// undeclared, which checks every factor.
#include <gtest/gtest.h>

#include <random>

#include "gssm/analysis/offline.h"
#include "gssm/model/simulation.h"
#include "gssm/models/linear.h"
#include "gssm/models/radar2d.h"

using namespace gssm;

namespace {
// `inner` with nothing declared affine (Model's defaults).
class Undeclared final : public Model {
 public:
  explicit Undeclared(const Model& inner) : Model(inner.dims(), inner.names(), inner.noise()), inner_(inner) {}
  std::string name() const override { return "undeclared"; }
  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                    Eigen::MatrixXd* J_f_xc, Eigen::MatrixXd* J_f_xb) const override {
    return inner_.f(xc, xb, u, dt, J_f_xc, J_f_xb);
  }
  using Model::h;
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                    Eigen::MatrixXd* J_h_xb) const override {
    return inner_.h(xc, xb, J_h_xc, J_h_xb);
  }
  Eigen::MatrixXd processNoise(double dt) const override { return inner_.processNoise(dt); }

 private:
  const Model& inner_;
};

void expectSameEstimates(const Model& declared, const SimulatedRun& run) {
  const Undeclared undeclared(declared);
  ASSERT_FALSE(undeclared.processIsAffine());
  for (Method method : {Method::FixedLag, Method::Incremental}) {
    EstimatorOptions o(method);
    o.fixed_lag.window = 10;
    const OfflineRun a = runOffline(declared, o, run.measurements);
    const OfflineRun b = runOffline(undeclared, o, run.measurements);
    ASSERT_EQ(a.rows.size(), b.rows.size());
    double worst = 0;
    for (std::size_t i = 0; i < a.rows.size(); ++i) {
      const Eigen::ArrayXd scale = b.rows[i].mean.array().abs() + 1e-3;
      worst = std::max(worst, ((a.rows[i].mean - b.rows[i].mean).array().abs() / scale).maxCoeff());
      const Eigen::ArrayXXd cov_scale = b.rows[i].covariance.array().abs() + 1e-12;
      worst = std::max(worst, ((a.rows[i].covariance - b.rows[i].covariance).array().abs() / cov_scale).maxCoeff());
    }
    EXPECT_LE(worst, 1e-12) << methodName(method) << ": the largest relative difference over every row";
  }
}
}  // namespace

TEST(AffineFactors, TheRadarsAffineProcessSkipsChecksWithoutChangingAnEstimate) {
  const models::Radar2D radar;
  ASSERT_TRUE(radar.processIsAffine());
  ASSERT_FALSE(radar.measurementIsAffine(0));
  SimulationSpec spec;
  spec.steps = 300;
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  expectSameEstimates(radar, simulate(radar, spec, [&] { return n01(rng); }));
}

TEST(AffineFactors, ALinearModelsFactorsSkipChecksWithoutChangingAnEstimate) {
  models::LinearSystem sys;  // position and velocity, a constant bias on the position reading
  sys.A_c = (Eigen::MatrixXd(2, 2) << 0, 1, 0, 0).finished();
  sys.A_b = Eigen::MatrixXd::Zero(2, 1);
  sys.B = Eigen::MatrixXd::Zero(2, 0);
  sys.C_c = (Eigen::MatrixXd(1, 2) << 1, 0).finished();
  sys.C_b = Eigen::MatrixXd::Ones(1, 1);
  sys.noise.T = 0.1;
  sys.noise.Q = Eigen::Vector2d(1e-4, 1e-2).asDiagonal();
  sys.noise.R = Eigen::MatrixXd::Constant(1, 1, 0.04);
  sys.noise.prior_state = {Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity()};
  sys.noise.prior_constants = {Eigen::VectorXd::Zero(1), Eigen::MatrixXd::Identity(1, 1)};
  const models::LinearModel model(sys);
  ASSERT_TRUE(model.processIsAffine() && model.measurementIsAffine(0));
  SimulationSpec spec;
  spec.steps = 300;
  std::mt19937 rng(11);
  std::normal_distribution<double> n01;
  expectSameEstimates(model, simulate(model, spec, [&] { return n01(rng); }));
}
