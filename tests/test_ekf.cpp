#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "gssm/solvers/ekf.h"
#include "gssm/core/error.h"
#include "gssm/models/linear.h"
#include "gssm/models/radar2d.h"
#include "gssm/model/simulation.h"
#include "reference_kalman.h"

using namespace gssm;
using gssm::testing::relativeError;

namespace {
using gssm::testing::normalSampler;

// A random linear model (3 states, 2 constants, exact discretization), a
// simulated run of it and the textbook Kalman filter and RTS smoother on it.
struct LinearCase {
  std::unique_ptr<models::LinearModel> model;
  SimulatedRun run;
  gssm::testing::KalmanRun ref;
};
LinearCase linearCase(unsigned system_seed, int steps, unsigned noise_seed) {
  std::mt19937 rng(system_seed);
  LinearCase c;
  c.model = std::make_unique<models::LinearModel>(gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1),
                                                  models::Discretization::Exact);
  SimulationSpec spec;
  spec.steps = steps;
  c.run = simulate(*c.model, spec, normalSampler(noise_seed));
  c.ref = gssm::testing::kalmanAndRts(gssm::testing::stack(*c.model, 0.1), c.run.measurements);
  return c;
}
}  // namespace

TEST(ExtendedKalmanFilter, EqualsLinearKalmanFilterOnLinearModel) {
  const LinearCase c = linearCase(21, 80, 4);
  const SimulatedRun& run = c.run;
  const auto& ref = c.ref;
  ExtendedKalmanFilter ekf(*c.model);
  for (std::size_t i = 0; i < run.measurements.size(); ++i) {
    ekf.predict(run.measurements[i].t, Eigen::VectorXd(0));
    ekf.update(run.measurements[i].y);
    EXPECT_LT(relativeError(ekf.mean(), ref.zf[i + 1]), 1e-10) << "step " << i + 1;
    EXPECT_LT(relativeError(ekf.covariance(), ref.Pf[i + 1]), 1e-10) << "step " << i + 1;
  }
}

TEST(ExtendedKalmanFilter, JosephAndSimpleFormAgree) {
  const models::Radar2D radar;
  SimulationSpec spec;
  spec.steps = 50;
  const SimulatedRun run = simulate(radar, spec, normalSampler(5));
  ExtendedKalmanFilterOptions simple;
  simple.joseph_form = false;
  ExtendedKalmanFilter a(radar), b(radar, simple);
  for (const auto& m : run.measurements) {
    a.predict(m.t, Eigen::VectorXd(0));
    b.predict(m.t, Eigen::VectorXd(0));
    a.update(m.y);
    b.update(m.y);
  }
  EXPECT_LT(relativeError(a.mean(), b.mean()), 1e-8);
  EXPECT_LT(relativeError(a.covariance(), b.covariance()), 1e-6);
}

// The prediction symmetrizes only P_cc once P is exactly symmetric, which
// every update must leave it: Joseph's form, the simple form and the
// outlier mixture's (w < 1), on a model with constants; the prior's
// asymmetry is taken out by the first prediction.
TEST(ExtendedKalmanFilter, CovarianceIsExactlySymmetricAfterEveryStep) {
  const LinearCase c = linearCase(21, 40, 4);
  for (const int form : {0, 1, 2}) {
    ExtendedKalmanFilterOptions o;
    o.joseph_form = form != 1;
    if (form == 2) o.outlier_probability = 0.2, o.outlier_log_density = {std::log(1e-3)};
    ExtendedKalmanFilter ekf(*c.model, o);
    const auto symmetric = [&ekf] { return ekf.covariance() == ekf.covariance().transpose(); };
    for (std::size_t i = 0; i < c.run.measurements.size(); ++i) {
      ekf.predict(c.run.measurements[i].t, Eigen::VectorXd(0));
      EXPECT_TRUE(symmetric()) << "form " << form << " predicted " << i;
      ekf.update(c.run.measurements[i].y);
      EXPECT_TRUE(symmetric()) << "form " << form << " updated " << i;
    }
  }
}

TEST(ExtendedKalmanFilter, ConstantProcessNoiseInflatesOnlyThatConstant) {
  const models::Radar2D radar;
  ExtendedKalmanFilterOptions o;
  o.constant_process_noise = Eigen::Vector2d(0.005 * 0.005, 0.0);
  ExtendedKalmanFilter plain(radar), noisy(radar, o);
  plain.predict(0.05, Eigen::VectorXd(0));
  noisy.predict(0.05, Eigen::VectorXd(0));
  EXPECT_NEAR(noisy.covariance()(1, 1) - plain.covariance()(1, 1), 0.005 * 0.005, 1e-15);
  EXPECT_EQ(noisy.covariance()(2, 2), plain.covariance()(2, 2));
}

TEST(ExtendedKalmanFilter, BadCallsThrowAndLeaveTheFilterUnchanged) {
  const models::Radar2D radar;
  ExtendedKalmanFilter ekf(radar);
  ekf.predict(0.05, Eigen::VectorXd(0));
  ekf.update(Eigen::VectorXd::Constant(1, 2000));
  const Eigen::VectorXd z = ekf.mean();
  const Eigen::MatrixXd P = ekf.covariance();
  EXPECT_THROW(ekf.predict(0.05, Eigen::VectorXd(0)), InvalidArgument);  // time not after
  EXPECT_THROW(ekf.update(Eigen::VectorXd::Constant(1, NAN)), InvalidArgument);
  EXPECT_THROW(ekf.update(Eigen::VectorXd::Constant(2, 1.0)), InvalidArgument);
  EXPECT_EQ(ekf.mean(), z);
  EXPECT_EQ(ekf.covariance(), P);
  EXPECT_DOUBLE_EQ(ekf.time(), 0.05);
  ExtendedKalmanFilterOptions bad;
  bad.constant_process_noise = Eigen::VectorXd::Constant(3, 0.0);
  EXPECT_THROW(ExtendedKalmanFilter(radar, bad), InvalidArgument);
}

// The batch's start: on a linear model the smoothed guess is the RTS
// smoother of the stacked Kalman model (the batch's answer) at every step,
// the constants at the filter's final estimate; the filtered guess is the
// filter's estimate at every step.
TEST(EkfInitialGuess, SmoothedIsTheRtsSmootherAndFilteredTheFilterOnALinearModel) {
  const int steps = 70;
  const LinearCase c = linearCase(8, steps, 9);
  const auto& ref = c.ref;
  const Values smoothed = ekfInitialGuess(*c.model, {}, c.run.measurements);
  const Values filtered = ekfInitialGuess(*c.model, {}, c.run.measurements, {}, 0.0, false);
  ASSERT_EQ(smoothed.size(), static_cast<std::size_t>(steps + 2));
  for (int k = 0; k <= steps; ++k) {
    EXPECT_LT(relativeError(smoothed.at(Key::state(k)), ref.zs[k].head(3)), 1e-9) << "step " << k;
    EXPECT_LT(relativeError(filtered.at(Key::state(k)), ref.zf[k].head(3)), 1e-9) << "step " << k;
  }
  EXPECT_LT(relativeError(smoothed.at(Key::constants()), ref.zf.back().tail(2)), 1e-10);
  EXPECT_LT(relativeError(smoothed.at(Key::constants()), ref.zs.front().tail(2)), 1e-8);
  EXPECT_EQ(filtered.at(Key::constants()), smoothed.at(Key::constants()));
}
