// The odometry/range-beacon model: Jacobians, robust losses against gross
// outliers (and the robust incremental smoother against the robust batch
// solve), and angles (a heading that crosses ±π many times, a heading prior
// of σ = π).
#include <gtest/gtest.h>

#include <random>

#include "gssm/analysis/errors.h"
#include "gssm/analysis/offline.h"
#include "gssm/core/angles.h"
#include "gssm/estimator/estimator.h"
#include "gssm/factors/problem.h"
#include "gssm/models/range_beacon2d.h"
#include "gssm/solvers/batch_solver.h"
#include "jacobian_check.h"
#include "reference_kalman.h"

using namespace gssm;
using gssm::testing::relativeError;

namespace {

models::RangeBeacon2D::Params circleParams() {
  models::RangeBeacon2D::Params p;
  p.beacon_ids = {0, 1, 5, 6};
  p.beacons = {{0, 0}, {60, 0}, {60, 60}, {0, 60}};
  p.range_scale = true;
  p.range_sd = 0.3;
  p.start = Eigen::Vector3d(30, 10, 0);
  p.start_sd = Eigen::Vector3d(1, 1, 0.1);
  return p;
}

// A vehicle on a circle (speed 3 m/s, turn 0.3 rad/s: the heading crosses
// ±π every 21 s), odometry at 10 Hz, one range every 2nd step, the beacons
// in turn; range scale 1.05.
SimulatedRun circleRun(const models::RangeBeacon2D& m, unsigned seed, int steps = 600) {
  SimulationSpec spec;
  spec.steps = steps;
  spec.x0 = m.priorState().mean;
  spec.xb = Eigen::VectorXd::Constant(1, 1.05);
  spec.input = [](double, const Eigen::VectorXd&) { return Eigen::Vector2d(3.0, 0.3); };
  spec.measure_every = 2;
  spec.channels = {0, 1, 2, 3};
  return simulate(m, spec, gssm::testing::normalSampler(seed));
}

double positionRmse(const OfflineRun& run, const SimulatedRun& truth_run) {
  const RunErrors e = runErrors(run, truth_run.truth(), {2});
  double sq = 0;
  for (const auto& v : e.error) sq += v.head<2>().squaredNorm();
  return std::sqrt(sq / static_cast<double>(e.error.size()));
}

}  // namespace

TEST(RangeBeacon2D, AnalyticJacobiansMatchCentralDifferences) {
  auto p = circleParams();
  p.range_offsets = p.odometry_scale = true;
  const models::RangeBeacon2D m(p);
  ASSERT_EQ(m.dims().nb, 6);
  ASSERT_EQ(m.numChannels(), 4);
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd xc(3), xb(6), u(2);
    xc << 30 + 10 * g(rng), 30 + 10 * g(rng), 3 * g(rng);
    xb << 1.05 + 0.01 * g(rng), g(rng), g(rng), g(rng), g(rng), 1 + 0.01 * g(rng);
    u << 2 + g(rng), 0.3 * g(rng);
    EXPECT_TRUE(checkJacobians(m, xc, xb, u, 0.1).ok(1e-6)) << checkJacobians(m, xc, xb, u, 0.1).worst;
    for (int c = 1; c < 4; ++c) {  // every channel's h against central differences
      Eigen::MatrixXd Jc, Jb;
      m.h(c, xc, xb, &Jc, &Jb);
      const double eps = 1e-6;
      for (int i = 0; i < 3; ++i) {
        Eigen::VectorXd a = xc, b = xc;
        a[i] += eps;
        b[i] -= eps;
        EXPECT_NEAR(Jc(0, i), (m.h(c, a, xb) - m.h(c, b, xb))[0] / (2 * eps), 1e-6) << "channel " << c;
      }
      for (int i = 0; i < 6; ++i) {
        Eigen::VectorXd a = xb, b = xb;
        a[i] += eps;
        b[i] -= eps;
        EXPECT_NEAR(Jb(0, i), (m.h(c, xc, a) - m.h(c, xc, b))[0] / (2 * eps), 1e-6) << "channel " << c;
      }
    }
  }
}

TEST(RangeBeacon2D, HeadingRateBiasJacobiansMatchCentralDifferences) {
  auto p = circleParams();
  p.range_offsets = p.odometry_scale = p.heading_rate_bias = true;
  const models::RangeBeacon2D m(p);
  ASSERT_EQ(m.dims().nb, 7);
  EXPECT_EQ(m.names().constants.back(), "heading_rate_bias");
  std::mt19937 rng(9);
  std::normal_distribution<double> g;
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd xc(3), xb(7), u(2);
    xc << 30 + 10 * g(rng), 30 + 10 * g(rng), 3 * g(rng);
    xb << 1.05 + 0.01 * g(rng), g(rng), g(rng), g(rng), g(rng), 1 + 0.01 * g(rng), 0.01 * g(rng);
    u << 2 + g(rng), 0.3 * g(rng);
    EXPECT_TRUE(checkJacobians(m, xc, xb, u, 0.1).ok(1e-6)) << checkJacobians(m, xc, xb, u, 0.1).worst;
  }
}

TEST(RangeBeacon2D, HeadingRateBiasIsRecoveredFromASimulatedLogWithAKnownDrift) {
  // The odometry's turn rate reads 0.005 rad/s high (Plaza 2's drift is
  // about 0.0054): the vehicle turns at u − 0.005.
  auto p = circleParams();
  p.heading_rate_bias = true;
  const models::RangeBeacon2D m(p);
  SimulationSpec spec;
  spec.steps = 4800;  // 8 minutes
  spec.x0 = m.priorState().mean;
  spec.xb = Eigen::Vector2d(1.05, 0.005);
  spec.input = [](double, const Eigen::VectorXd&) { return Eigen::Vector2d(3.0, 0.3); };
  spec.measure_every = 2;
  spec.channels = {0, 1, 2, 3};
  const SimulatedRun run = simulate(m, spec, gssm::testing::normalSampler(3));
  for (Method method : {Method::Batch, Method::Incremental, Method::FixedLag}) {
    const OfflineRun r = runOffline(m, EstimatorOptions(method), run.measurements, run.inputs);
    const EstimateRow& last = r.rows.back();
    const double b = last.mean[4], sd = std::sqrt(last.covariance(4, 4));
    EXPECT_LT(std::abs(b - 0.005), 2.5 * sd) << methodName(method) << ": " << b << " ± " << sd;
    EXPECT_LT(sd, 0.0015) << methodName(method);  // the prior's σ is 0.01: the log determines it
    EXPECT_GT(b, 0.0025) << methodName(method);   // nearer the drift than no drift
  }
}

TEST(RobustLoss, HuberAndCauchyResistGrossOutliersWhileGaussianDegrades) {
  const auto p = circleParams();
  const models::RangeBeacon2D gaussian(p);
  const SimulatedRun clean = circleRun(gaussian, 81);
  SimulatedRun dirty = clean;
  std::mt19937 rng(82);
  std::uniform_real_distribution<double> u01;
  int outliers = 0;
  for (auto& m : dirty.measurements)
    if (u01(rng) < 0.05) {  // 5% gross outliers: a multipath range 10–40 m long
      m.y[0] += 10 + 30 * u01(rng);
      ++outliers;
    }
  ASSERT_GT(outliers, 5);
  const auto rmse = [&](const Model& model, Method method, const SimulatedRun& run) {
    return positionRmse(runOffline(model, {method}, run.measurements, run.inputs), clean);
  };
  const double clean_rmse = rmse(gaussian, Method::Batch, clean);
  const double gaussian_dirty = rmse(gaussian, Method::Batch, dirty);
  EXPECT_GT(gaussian_dirty, 2 * clean_rmse) << "the outliers must hurt a Gaussian estimate";
  for (const auto kind : {RobustLoss::Kind::Huber, RobustLoss::Kind::Cauchy}) {
    auto rp = p;
    rp.range_loss = {kind, kind == RobustLoss::Kind::Huber ? 1.345 : 2.5};
    const models::RangeBeacon2D robust(rp);
    for (const Method method : {Method::Batch, Method::Incremental, Method::FixedLag}) {
      const double r = rmse(robust, method, dirty);
      EXPECT_LT(r, 2 * clean_rmse) << RobustLoss::name(kind) << " " << method << ": " << r << " vs clean "
                                   << clean_rmse << " (Gaussian on dirty data " << gaussian_dirty << ")";
    }
  }
  // The EKF gate rejects the gross outliers.
  auto gp = p;
  gp.ekf_gate = 16;
  const models::RangeBeacon2D gated(gp);
  const OfflineRun ekf = runOffline(gated, {Method::Ekf}, dirty.measurements, dirty.inputs);
  EXPECT_GE(ekf.rejected, outliers * 8 / 10);
  EXPECT_LT(positionRmse(ekf, clean), 2 * positionRmse(runOffline(gated, {Method::Ekf}, clean.measurements,
                                                                   clean.inputs), clean));
}

TEST(RobustLoss, RobustIncrementalEqualsRobustBatchAfterEveryUpdate) {
  auto p = circleParams();
  p.range_loss = {RobustLoss::Kind::Huber, 1.0};
  const models::RangeBeacon2D model(p);
  SimulatedRun run = circleRun(model, 83, 120);
  for (std::size_t i = 3; i < run.measurements.size(); i += 7) run.measurements[i].y[0] += 8;  // down-weighted
  EstimatorOptions o(Method::Incremental);
  o.smoother.iterate_to_convergence = true;  // the exact robust MAP after every update
  auto inc = makeEstimator(model, o);
  std::size_t next_input = 0;
  int downweighted = 0;
  for (std::size_t i = 0; i < run.measurements.size(); ++i) {
    const Measurement& m = run.measurements[i];
    for (; next_input < run.inputs.size() && run.inputs[next_input].t < m.t; ++next_input)
      inc->addInput(std::max(run.inputs[next_input].t, inc->time()), run.inputs[next_input].u);
    inc->addMeasurement(m);
    if (i % 10 != 9) continue;  // compare every 10th update (each batch solve is a whole run)
    const std::vector<Measurement> upto(run.measurements.begin(), run.measurements.begin() + static_cast<long>(i) + 1);
    const std::vector<Input> inputs(run.inputs.begin(), run.inputs.begin() + static_cast<long>(next_input));
    Problem prob = buildProblem(model, upto, inputs);
    Values x = ekfInitialGuess(model, {}, upto, inputs);
    BatchSolver batch;
    ASSERT_TRUE(batch.solve(prob.graph, x).converged);
    downweighted = 0;
    for (const auto& f : prob.graph) downweighted += f->weight(x) < 1.0 ? 1 : 0;
    const std::int64_t k = static_cast<std::int64_t>(prob.times.size()) - 1;
    Eigen::VectorXd z(4);
    z << x.at(Key::state(k)), x.at(Key::constants());
    Eigen::VectorXd e = inc->current().mean - z;
    e[2] = wrapAngle(e[2]);
    EXPECT_LT(e.norm() / (1 + z.norm()), 1e-6) << "measurement " << i;
    EXPECT_LT(relativeError(inc->current().covariance, batch.jointMarginalCovariance(stackedKeys(model, k))), 1e-5)
        << "measurement " << i;
  }
  EXPECT_GT(downweighted, 5) << "the test must exercise down-weighting";
}

TEST(Angles, HeadingCrossingPiManyTimesMatchesTheRunRotatedByTwoPi) {
  auto p = circleParams();
  const models::RangeBeacon2D model(p);
  const SimulatedRun run = circleRun(model, 85, 800);  // 80 s: the heading wraps 3-4 times
  int wraps = 0;
  for (std::size_t k = 1; k < run.states.size(); ++k)
    wraps += std::abs(run.states[k][2] - run.states[k - 1][2]) > M_PI ? 1 : 0;
  ASSERT_GE(wraps, 3);
  auto rotated = p;
  rotated.start[2] += 2 * M_PI;  // the same prior, written 2π further on
  const models::RangeBeacon2D model2(rotated);
  for (const Method method : {Method::Ekf, Method::Batch, Method::Incremental, Method::FixedLag, Method::PaperWindow}) {
    const OfflineRun a = runOffline(model, {method}, run.measurements, run.inputs);
    const OfflineRun b = runOffline(model2, {method}, run.measurements, run.inputs);
    ASSERT_EQ(a.rows.size(), b.rows.size());
    double worst = 0;
    for (std::size_t i = 0; i < a.rows.size(); ++i) {
      Eigen::VectorXd d = a.rows[i].mean - b.rows[i].mean;
      d[2] = wrapAngle(d[2]);
      worst = std::max(worst, d.cwiseAbs().maxCoeff());
      EXPECT_GT(a.rows[i].mean[2], -M_PI - 1e-12);
      EXPECT_LE(a.rows[i].mean[2], M_PI + 1e-12);
    }
    EXPECT_LT(worst, 1e-6) << method;
    EXPECT_LT(positionRmse(a, run), 1.0) << method;
  }
}

TEST(Angles, HeadingPriorOfSigmaPiConverges) {
  auto p = circleParams();
  p.start_sd[2] = M_PI;  // heading unknown
  p.start[2] = 2.0;      // and the prior mean 2 rad off the truth (0)
  const models::RangeBeacon2D model(p);
  auto truth_params = circleParams();
  const models::RangeBeacon2D truth_model(truth_params);
  const SimulatedRun run = circleRun(truth_model, 86, 400);
  for (const Method method : {Method::Batch, Method::Incremental, Method::FixedLag}) {
    const OfflineRun r = runOffline(model, {method}, run.measurements, run.inputs);
    const RunErrors e = runErrors(r, run.truth(), {2});
    const Eigen::VectorXd last = e.error.back();
    const double sd = std::sqrt(r.rows.back().covariance(2, 2));
    EXPECT_LT(std::abs(last[2]), 3 * sd) << method << ": final heading error " << last[2] << ", sd " << sd;
    EXPECT_LT(last.head<2>().norm(), 1.0) << method;
    EXPECT_NEAR(r.rows.back().mean[3], 1.05, 0.01) << method << " range scale";
    // The same answer as from a prior that knew the heading.
    const OfflineRun known = runOffline(truth_model, {method}, run.measurements, run.inputs);
    EXPECT_LT(std::abs(wrapAngle(r.rows.back().mean[2] - known.rows.back().mean[2])), 0.01) << method;
    EXPECT_LT((r.rows.back().mean.head<2>() - known.rows.back().mean.head<2>()).norm(), 0.05) << method;
  }
}

TEST(Angles, APriorAcrossTheCutIsCloseNotTwoPiAway) {
  // Truth heading −π + 0.05, prior mean π − 0.05 with σ 0.1: 1σ apart on the
  // circle, 62σ apart on the real line. Every estimator must see the former.
  auto truth_params = circleParams();
  truth_params.start[2] = -M_PI + 0.05;
  const models::RangeBeacon2D truth_model(truth_params);
  const SimulatedRun run = circleRun(truth_model, 87, 200);
  auto p = truth_params;
  p.start[2] = M_PI - 0.05;
  const models::RangeBeacon2D model(p);
  for (const Method method : {Method::Ekf, Method::Batch, Method::Incremental, Method::FixedLag, Method::PaperWindow}) {
    const OfflineRun r = runOffline(model, {method}, run.measurements, run.inputs);
    const RunErrors e = runErrors(r, run.truth(), {2});
    double worst = 0;
    for (const auto& v : e.error) worst = std::max(worst, std::abs(v[2]));
    EXPECT_LT(worst, 0.3) << method << ": heading error up to " << worst;
    EXPECT_LT(positionRmse(r, run), 1.0) << method;
  }
}
