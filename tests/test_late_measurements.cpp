// Measurements out of sequence (a sensor's buffer, a radio writing blocks
// late): the smoothers attach a late measurement to the state at its time
// and end where the same data fed in order (and the batch solve) end; what
// they cannot take is refused with the estimator unchanged, or dropped and
// counted.
#include <gtest/gtest.h>

#include "gssm/analysis/offline.h"
#include "gssm/checkpoint/checkpoint.h"
#include "gssm/core/error.h"
#include "gssm/estimator/estimator.h"
#include "gssm/models/linear.h"
#include "gssm/models/radar2d.h"
#include "gssm/models/range_beacon2d.h"
#include "reference_kalman.h"
#include "track_with_bias.h"

namespace gssm {
namespace {

// Position and velocity, a constant bias on the position sensor "y", and a
// second, unbiased position sensor "gps" read at the same instants.
models::LinearModel twoSensors() {
  models::LinearSystem s = testing::trackWithBias(0.01, 0.04, 0.25, 0.5);
  s.channels.push_back({"gps", Eigen::RowVector2d(1, 0), Eigen::MatrixXd::Zero(1, 1), Eigen::MatrixXd::Constant(1, 1, 1.0), {}});
  return models::LinearModel(s);
}

struct Log {
  std::vector<Measurement> in_order;  // y and gps of each instant, instant by instant
  std::vector<Measurement> arrival;   // each gps reading `delay` instants late
};

Log twoSensorLog(const Model& m, int steps, int delay) {
  SimulationSpec spec;
  spec.steps = steps;
  const SimulatedRun run = simulate(m, spec, testing::normalSampler(7));
  auto draw = testing::normalSampler(8);
  Log log;
  std::vector<Measurement> gps;
  for (const auto& y : run.measurements) {
    const std::size_t k = static_cast<std::size_t>(std::llround(y.t / m.nominalStep()));
    gps.push_back({y.t, Eigen::VectorXd::Constant(1, run.states[k][0] + draw()), 1, {}});
    log.in_order.push_back(y);
    log.in_order.push_back(gps.back());
  }
  for (std::size_t k = 0; k < run.measurements.size(); ++k) {
    log.arrival.push_back(run.measurements[k]);
    if (k >= static_cast<std::size_t>(delay)) log.arrival.push_back(gps[k - static_cast<std::size_t>(delay)]);
  }
  for (std::size_t k = gps.size() - static_cast<std::size_t>(delay); k < gps.size(); ++k) log.arrival.push_back(gps[k]);
  return log;
}

std::unique_ptr<Estimator> feed(const Model& m, EstimatorOptions o, const std::vector<Measurement>& ms) {
  auto est = makeEstimator(m, o);
  for (const auto& x : ms) est->addMeasurement(x);
  return est;
}

void expectNear(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double tol, const std::string& what) {
  ASSERT_EQ(a.rows(), b.rows()) << what;
  EXPECT_LE((a - b).cwiseAbs().maxCoeff(), tol * (1.0 + b.cwiseAbs().maxCoeff())) << what << "\n" << a << "\nvs\n" << b;
}

TEST(LateMeasurements, SmoothersFedOutOfOrderEndAsFedInOrderAndAsTheBatch) {
  const auto m = twoSensors();
  const Log log = twoSensorLog(m, 60, 4);
  const OfflineRun batch = runOffline(m, {Method::Batch}, log.in_order);
  for (Method method : {Method::Incremental, Method::FixedLag}) {
    EstimatorOptions o(method);
    o.fixed_lag.window = 10;
    auto late = feed(m, o, log.arrival);
    auto ordered = feed(m, o, log.in_order);
    EXPECT_EQ(late->report().late, 59) << method;  // the last gps reading comes with its own instant
    ASSERT_EQ(batch.rows.size(), 60u);  // one row per instant
    EXPECT_EQ(late->report().measurements, 120) << method;
    expectNear(late->current().mean, ordered->current().mean, 1e-9, methodName(method));
    expectNear(late->current().covariance, ordered->current().covariance, 1e-9, methodName(method));
    for (std::int64_t k = late->step() - 8; k <= late->step(); ++k)
      expectNear(late->smoothed(k)->mean, ordered->smoothed(k)->mean, 1e-9, std::string(methodName(method)) + " x_c(k)");
    if (method == Method::Incremental)  // the whole history equals the batch solve of all the data
      for (std::int64_t k = 1; k <= late->step(); k += 7)
        expectNear(late->smoothed(k)->mean, batch.rows[static_cast<std::size_t>(k - 1)].mean, 1e-8, "batch");
  }
}

TEST(LateMeasurements, WhatCannotBeTakenIsRefusedUnchangedOrDroppedAndCounted) {
  const auto m = twoSensors();
  const Log log = twoSensorLog(m, 40, 12);  // older than a 10-state window
  for (Method method : {Method::FixedLag, Method::Ekf, Method::PaperWindow}) {
    EstimatorOptions o(method);
    o.fixed_lag.window = o.paper_window.window = 10;
    auto est = makeEstimator(m, o);
    std::size_t i = 0;
    for (; log.arrival[i].channel == 0; ++i) est->addMeasurement(log.arrival[i]);
    const Eigen::VectorXd mean = est->current().mean;
    const std::int64_t taken = est->report().measurements;
    try {
      est->addMeasurement(log.arrival[i]);
      FAIL() << method << ": a measurement 12 states late must be refused";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("is before the newest state"), std::string::npos) << e.what();
      if (method == Method::FixedLag) {
        EXPECT_NE(std::string(e.what()).find("older than the window"), std::string::npos) << e.what();
      }
    }
    EXPECT_EQ(est->current().mean, mean) << method;
    EXPECT_EQ(est->report().measurements, taken) << method;
    o.drop_late = true;
    auto dropping = feed(m, o, log.arrival);
    // Taken: every y, and the gps readings still at a held state's time: the
    // fixed lag's window holds x_c(31..40) when the last readings arrive,
    // the EKF and the paper window only the newest (x_c(40)).
    const double first_taken = (method == Method::FixedLag ? 31 : 40) * m.nominalStep();
    std::vector<Measurement> taken_only;
    for (const auto& x : log.arrival)
      if (x.channel == 0 || x.t >= first_taken - 1e-9) taken_only.push_back(x);
    const std::int64_t expect_dropped = static_cast<std::int64_t>(log.arrival.size() - taken_only.size());
    EXPECT_EQ(dropping->report().late_dropped, expect_dropped) << method;
    EXPECT_EQ(dropping->report().measurements, static_cast<std::int64_t>(taken_only.size())) << method;
    EXPECT_EQ(dropping->current().mean, feed(m, o, taken_only)->current().mean) << method;
  }
}

TEST(LateMeasurements, ACheckpointTakenWithLateMeasurementsInFlightResumesExactly) {
  const auto m = twoSensors();
  const Log log = twoSensorLog(m, 50, 3);
  for (Method method : {Method::Incremental, Method::FixedLag}) {
    EstimatorOptions o(method);
    o.fixed_lag.window = 10;
    auto whole = feed(m, o, log.arrival);
    auto first = makeEstimator(m, o);
    const std::size_t half = log.arrival.size() / 2;
    for (std::size_t i = 0; i < half; ++i) first->addMeasurement(log.arrival[i]);
    auto resumed = restoreCheckpointBytes(m, checkpointBytes(*first));
    EXPECT_EQ(resumed->report().late, first->report().late) << method;
    for (std::size_t i = half; i < log.arrival.size(); ++i) resumed->addMeasurement(log.arrival[i]);
    EXPECT_EQ(resumed->report().late, whole->report().late) << method;
    EXPECT_EQ(resumed->current().mean, whole->current().mean) << method;
  }
}

}  // namespace
}  // namespace gssm

namespace gssm {
namespace {

TEST(LateMeasurements, OnTheNonlinearRadarTheIteratedIncrementalEqualsTheBatch) {
  // Two readings of each instant, the second arriving three instants late;
  // iterated to convergence the incremental smoother is the batch MAP.
  const models::Radar2D radar;
  SimulationSpec spec;
  spec.steps = 40;
  const SimulatedRun run = simulate(radar, spec, testing::normalSampler(4));
  auto draw = testing::normalSampler(5);
  std::vector<Measurement> in_order, arrival, second;
  for (const auto& y : run.measurements) {
    second.push_back({y.t, y.y + Eigen::VectorXd::Constant(1, 3.0 * draw()), 0, {}});
    in_order.push_back(y), in_order.push_back(second.back());
  }
  for (std::size_t k = 0; k < run.measurements.size(); ++k) {
    arrival.push_back(run.measurements[k]);
    if (k >= 3) arrival.push_back(second[k - 3]);
  }
  for (std::size_t k = second.size() - 3; k < second.size(); ++k) arrival.push_back(second[k]);
  EstimatorOptions o(Method::Incremental);
  o.smoother.iterate_to_convergence = true;
  auto est = feed(radar, o, arrival);
  const OfflineRun batch = runOffline(radar, {Method::Batch}, in_order);
  ASSERT_EQ(batch.rows.size(), 40u);
  for (std::int64_t k = 1; k <= est->step(); ++k)
    expectNear(est->smoothed(k)->mean, batch.rows[static_cast<std::size_t>(k - 1)].mean, 1e-7, "x_c(k) and x_b");
}

}  // namespace
}  // namespace gssm

namespace gssm {
namespace {

TEST(LateMeasurements, BetweenTwoStatesTheSmoothersInsertAState) {
  // gps read halfway between the y instants, each reading 3 instants late:
  // the incremental smoother inserts a state at its time (the process factor
  // there split in two) and ends as the run with every state from the start.
  const auto m = twoSensors();
  SimulationSpec spec;
  spec.steps = 40;
  const SimulatedRun run = simulate(m, spec, testing::normalSampler(11));
  auto draw = testing::normalSampler(12);
  std::vector<Measurement> in_order, arrival, gps;
  for (std::size_t k = 0; k < run.measurements.size(); ++k) {
    const double t = run.measurements[k].t + 0.5 * m.nominalStep();
    const Eigen::VectorXd x = run.states[k + 1];  // (the truth between is not needed: any reading will do)
    gps.push_back({t, Eigen::VectorXd::Constant(1, x[0] + draw()), 1, {}});
  }
  for (std::size_t k = 0; k < run.measurements.size(); ++k) {
    in_order.push_back(run.measurements[k]);
    if (k + 1 < run.measurements.size()) in_order.push_back(gps[k]);  // the last one would be after every y
    arrival.push_back(run.measurements[k]);
    if (k >= 4) arrival.push_back(gps[k - 4]);
  }
  for (std::size_t k = run.measurements.size() - 4; k + 1 < run.measurements.size(); ++k) arrival.push_back(gps[k]);
  // The fixed lag (window 12 regular states) takes them too: each is 4 instants late.
  {
    EstimatorOptions o(Method::FixedLag);
    o.fixed_lag.window = 12;
    auto late = feed(m, o, arrival);
    EXPECT_EQ(late->report().late, 39);
    EXPECT_EQ(late->report().late_dropped, 0);
    // In order, the window holds the gps states too: compare with a long
    // window, where marginalization has not yet reached what the late run
    // still held; the newest estimate is exact either way (linear).
    EstimatorOptions wide = o;
    wide.fixed_lag.window = 200;
    auto ordered = feed(m, wide, in_order);
    expectNear(late->current().mean, ordered->current().mean, 1e-9, "fixed lag: newest state and x_b");
    expectNear(late->current().covariance, ordered->current().covariance, 1e-9, "fixed lag: their covariance");
    auto restored = restoreCheckpointBytes(m, checkpointBytes(*late));
    EXPECT_EQ(restored->current().mean, late->current().mean);
  }
  EstimatorOptions o(Method::Incremental);
  auto late = feed(m, o, arrival);
  auto ordered = feed(m, o, in_order);
  EXPECT_EQ(late->report().late, 39);
  EXPECT_EQ(late->report().measurements, 79);
  expectNear(late->current().mean, ordered->current().mean, 1e-9, "newest state and x_b");
  expectNear(late->current().covariance, ordered->current().covariance, 1e-9, "their covariance");
  const OfflineRun batch = runOffline(m, {Method::Batch}, in_order);
  for (std::int64_t k = 1; k <= late->step(); k += 3) {
    const StateEstimate e = *late->smoothed(k);
    const auto row = std::find_if(batch.rows.begin(), batch.rows.end(), [&](const EstimateRow& r) { return r.t == e.t; });
    ASSERT_NE(row, batch.rows.end()) << e.t;
    expectNear(e.mean, row->mean, 1e-8, "x_c at t = " + std::to_string(e.t) + " and x_b vs the batch");
  }
  // Saved and restored with inserted states in it: the same estimates, and it goes on.
  auto restored = restoreCheckpointBytes(m, checkpointBytes(*late));
  EXPECT_EQ(restored->current().mean, late->current().mean);
  EXPECT_EQ(restored->report().late, 39);
}

}  // namespace
}  // namespace gssm

namespace gssm {
namespace {

TEST(LateMeasurements, AnInsertedStateCarriesTheOdometryOfTheIntervalItSplits) {
  // RangeBeacon2D (odometry in): ranges between odometry rows, each 5 rows
  // late; iterated to convergence the incremental smoother is the batch MAP
  // of the same data, whose states sit at every odometry and range time.
  models::RangeBeacon2D::Params p;
  p.beacon_ids = {0, 1, 5, 6};
  p.beacons = {{-33.6, 27.0}, {-68.9, 18.4}, {1.7, -5.8}, {-37.6, 69.2}};
  p.start = Eigen::Vector3d(-34, 55, 0);
  p.start_sd = Eigen::Vector3d(1, 1, 0.5);
  const models::RangeBeacon2D m(p);
  SimulationSpec spec;
  spec.steps = 60;
  spec.input = [](double, const Eigen::VectorXd&) { return Eigen::Vector2d(3.0, 0.1); };
  spec.measure_every = 2;
  spec.channels = {0, 1, 2, 3};
  SimulatedRun run = simulate(m, spec, testing::normalSampler(31));
  for (auto& r : run.measurements) r.t -= 0.04;  // between odometry rows (every 0.1 s)
  EstimatorOptions o(Method::Incremental);
  o.smoother.iterate_to_convergence = true;
  auto est = makeEstimator(m, o);
  std::size_t next_range = 0;
  for (std::size_t i = 0; i < run.inputs.size(); ++i) {
    est->addInput(run.inputs[i].t, run.inputs[i].u);
    while (next_range < run.measurements.size() && run.measurements[next_range].t < run.inputs[i].t - 0.45)
      est->addMeasurement(run.measurements[next_range++]);  // 5 rows late
  }
  while (next_range < run.measurements.size()) est->addMeasurement(run.measurements[next_range++]);
  EXPECT_GT(est->report().late, 20);
  const OfflineRun batch = runOffline(m, {Method::Batch}, run.measurements, run.inputs, {}, {}, RowTimes::Inputs);
  for (std::int64_t k = 5; k <= est->step(); k += 9) {
    const StateEstimate e = *est->smoothed(k);
    const auto row = std::find_if(batch.rows.begin(), batch.rows.end(),
                                  [&](const EstimateRow& r) { return std::abs(r.t - e.t) < 1e-9; });
    ASSERT_NE(row, batch.rows.end()) << e.t;
    expectNear(e.mean, row->mean, 1e-6, "pose and range scale at t = " + std::to_string(e.t));
  }
}

}  // namespace
}  // namespace gssm
