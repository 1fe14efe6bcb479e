// Several measurement channels per model: a linear model with two sensors at
// two rates (several measurements at one time stamp) against an independent
// Kalman filter / RTS smoother with per-measurement H and R, and the
// estimators against the batch solve of the same graph after every update.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "gssm/analysis/offline.h"
#include "gssm/checkpoint/checkpoint.h"
#include "gssm/core/error.h"
#include "gssm/estimator/estimator.h"
#include "gssm/factors/problem.h"
#include "gssm/models/linear.h"
#include "gssm/solvers/batch_solver.h"
#include "reference_kalman.h"

using namespace gssm;
using gssm::testing::relativeError;

namespace {

// n_c = 2, n_b = 1; channel 0 "y" (1-D) and channel 1 "gps" (2-D).
models::LinearModel twoSensorModel() {
  std::mt19937 rng(71);
  models::LinearSystem sys = gssm::testing::randomLinearSystem(rng, 2, 1, 1, 0.1);
  models::LinearChannel gps;
  gps.name = "gps";
  gps.C_c = Eigen::MatrixXd::Identity(2, 2);
  gps.C_b = Eigen::MatrixXd::Constant(2, 1, 0.5);
  gps.R = Eigen::Matrix2d{{0.3, 0.05}, {0.05, 0.2}};
  sys.channels = {gps};
  return models::LinearModel(sys, models::Discretization::Exact);
}

// Channel 0 every 0.1 s, channel 1 every 0.25 s (both at t = 0.5, 1.0, ...).
std::vector<Measurement> twoRateRun(const models::LinearModel& m, unsigned seed) {
  const auto draw = gssm::testing::normalSampler(seed);
  std::map<long, std::vector<int>> at;  // time in ms → channels
  for (long t = 100; t <= 3000; t += 100) at[t].push_back(0);
  for (long t = 250; t <= 3000; t += 250) at[t].push_back(1);
  Eigen::VectorXd xc = sampleGaussian(m.priorState().mean, m.priorState().covariance, draw);
  const Eigen::VectorXd xb = sampleGaussian(m.priorConstants().mean, m.priorConstants().covariance, draw);
  std::vector<Measurement> out;
  long prev = 0;
  for (const auto& [ms, channels] : at) {
    const double dt = (ms - prev) / 1000.0;
    xc = m.f(xc, xb, Eigen::VectorXd(0), dt) +
         sampleGaussian(Eigen::VectorXd::Zero(2), m.processNoise(dt), draw);
    prev = ms;
    for (int c : channels) {
      const MeasurementChannel& ch = m.channel(c);
      out.push_back({ms / 1000.0, m.h(c, xc, xb) + sampleGaussian(Eigen::VectorXd::Zero(ch.dim()), ch.R, draw), c, {}});
    }
  }
  return out;
}

// A textbook Kalman filter on z = [x_c; x_b] with one predict per distinct
// time and sequential updates, each with its channel's H and R; RTS after.
struct Reference {
  std::vector<double> times;                  // distinct, with t0 = 0 first
  std::vector<Eigen::VectorXd> zf, zs;        // per time: filtered after all its updates; smoothed
  std::vector<Eigen::MatrixXd> Pf, Ps;
  std::vector<Eigen::VectorXd> after;         // filtered after each measurement
  std::vector<Eigen::MatrixXd> after_P;
};

Reference kalman(const models::LinearModel& m, const std::vector<Measurement>& ms) {
  Reference r;
  const int n = 3;
  Eigen::VectorXd z(n);
  z << m.priorState().mean, m.priorConstants().mean;
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n, n);
  P.topLeftCorner(2, 2) = m.priorState().covariance;
  P.bottomRightCorner(1, 1) = m.priorConstants().covariance;
  std::vector<Eigen::VectorXd> zp{z};
  std::vector<Eigen::MatrixXd> Pp{P}, Fs{Eigen::MatrixXd::Identity(n, n)};
  r.times.push_back(0);
  r.zf.push_back(z);
  r.Pf.push_back(P);
  for (const auto& meas : ms) {
    if (meas.t > r.times.back()) {  // predict to a new time
      const double dt = meas.t - r.times.back();
      Eigen::MatrixXd Fc, Fb, Bk;
      m.discreteMatrices(dt, Fc, Fb, Bk);
      Eigen::MatrixXd F = Eigen::MatrixXd::Identity(n, n);
      F.topLeftCorner(2, 2) = Fc;
      F.topRightCorner(2, 1) = Fb;
      Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(n, n);
      Q.topLeftCorner(2, 2) = m.processNoise(dt);
      z = F * z;
      P = F * P * F.transpose() + Q;
      r.times.push_back(meas.t);
      zp.push_back(z);
      Pp.push_back(P);
      Fs.push_back(F);
      r.zf.push_back(z);
      r.Pf.push_back(P);
    }
    Eigen::MatrixXd Cc, Cb;
    m.outputMatrices(meas.channel, Cc, Cb);
    Eigen::MatrixXd H(Cc.rows(), n);
    H << Cc, Cb;
    const Eigen::MatrixXd& R = m.channel(meas.channel).R;
    const Eigen::MatrixXd S = H * P * H.transpose() + R;
    const Eigen::MatrixXd K = P * H.transpose() * S.inverse();
    const Eigen::MatrixXd IKH = Eigen::MatrixXd::Identity(n, n) - K * H;
    z = z + K * (meas.y - H * z);
    P = IKH * P * IKH.transpose() + K * R * K.transpose();
    r.zf.back() = z;
    r.Pf.back() = P;
    r.after.push_back(z);
    r.after_P.push_back(P);
  }
  r.zs = r.zf;
  r.Ps = r.Pf;
  for (std::size_t k = r.times.size() - 1; k-- > 0;) {
    const Eigen::MatrixXd G = r.Pf[k] * Fs[k + 1].transpose() * Pp[k + 1].inverse();
    r.zs[k] = r.zf[k] + G * (r.zs[k + 1] - zp[k + 1]);
    r.Ps[k] = r.Pf[k] + G * (r.Ps[k + 1] - Pp[k + 1]) * G.transpose();
  }
  return r;
}

}  // namespace

TEST(Channels, TwoSensorsAtTwoRatesEqualTheKalmanFilterAndRtsSmoother) {
  const models::LinearModel model = twoSensorModel();
  ASSERT_EQ(model.numChannels(), 2);
  EXPECT_EQ(model.channelIndex("gps"), 1);
  const std::vector<Measurement> ms = twoRateRun(model, 72);
  const Reference ref = kalman(model, ms);
  for (const Method method : {Method::Ekf, Method::Incremental, Method::FixedLag}) {
    EstimatorOptions o(method);
    o.fixed_lag.window = 1000;  // larger than the run: the fixed lag keeps everything
    auto est = makeEstimator(model, o);
    for (std::size_t i = 0; i < ms.size(); ++i) {
      if (ms[i].channel == 1)
        est->addMeasurement(ms[i].t, "gps", ms[i].y);  // by name
      else
        est->addMeasurement(ms[i]);
      const StateEstimate e = est->current();
      EXPECT_LT(relativeError(e.mean, ref.after[i]), 1e-9) << method << " after measurement " << i;
      EXPECT_LT(relativeError(e.covariance, ref.after_P[i]), 1e-9) << method << " after measurement " << i;
    }
    if (method == Method::Ekf) continue;
    for (std::size_t k = 0; k < ref.times.size(); ++k) {  // the smoothed history equals RTS
      const auto s = est->smoothed(static_cast<std::int64_t>(k));
      ASSERT_TRUE(s.has_value()) << method << " step " << k;
      EXPECT_LT(relativeError(s->mean, ref.zs[k]), 1e-9) << method << " step " << k;
      EXPECT_LT(relativeError(s->covariance, ref.Ps[k]), 1e-9) << method << " step " << k;
    }
  }
}

TEST(Channels, IncrementalAndFixedLagEqualTheBatchSolveAfterEveryUpdate) {
  const models::LinearModel model = twoSensorModel();
  const std::vector<Measurement> ms = twoRateRun(model, 73);
  EstimatorOptions o(Method::Incremental);
  o.fixed_lag.window = 1000;
  auto inc = makeEstimator(model, o);
  o.method = Method::FixedLag;
  auto fl = makeEstimator(model, o);
  for (std::size_t i = 0; i < ms.size(); ++i) {
    inc->addMeasurement(ms[i]);
    fl->addMeasurement(ms[i]);
    const std::vector<Measurement> upto(ms.begin(), ms.begin() + static_cast<long>(i) + 1);
    Problem p = buildProblem(model, upto);
    Values x = p.initial;
    BatchSolver batch;
    ASSERT_TRUE(batch.solve(p.graph, x).converged);
    const std::int64_t k = static_cast<std::int64_t>(p.times.size()) - 1;
    Eigen::VectorXd z(3);
    z << x.at(Key::state(k)), x.at(Key::constants());
    const Eigen::MatrixXd P = batch.jointMarginalCovariance(stackedKeys(model, k));
    EXPECT_LT(relativeError(inc->current().mean, z), 1e-9) << "measurement " << i;
    EXPECT_LT(relativeError(fl->current().mean, z), 1e-9) << "measurement " << i;
    EXPECT_LT(relativeError(inc->current().covariance, P), 1e-9) << "measurement " << i;
    EXPECT_LT(relativeError(fl->current().covariance, P), 1e-9) << "measurement " << i;
  }
}

TEST(Channels, OwnNoiseOverrideIsUsedAndChecked) {
  const models::LinearModel model = twoSensorModel();
  std::vector<Measurement> ms = twoRateRun(model, 74);
  // A measurement that reports its own accuracy: its R replaces the channel's.
  for (auto& m : ms)
    if (m.channel == 1) m.R = 4.0 * model.channel(1).R;
  models::LinearSystem sys = model.system();
  sys.channels[0].R *= 4.0;
  const models::LinearModel noisier(sys, models::Discretization::Exact);
  auto a = makeEstimator(model, {Method::Incremental}), b = makeEstimator(noisier, {Method::Incremental});
  for (const auto& m : ms) {
    a->addMeasurement(m);
    Measurement plain = m;
    plain.R.resize(0, 0);
    b->addMeasurement(plain);
  }
  EXPECT_LT(relativeError(a->current().mean, b->current().mean), 1e-12);
  EXPECT_LT(relativeError(a->current().covariance, b->current().covariance), 1e-12);
  // Bad channel input is refused with the channel named; the estimator is unchanged.
  const StateEstimate before = a->current();
  const double t = ms.back().t + 0.1;
  EXPECT_THROW(a->addMeasurement(t, "lidar", Eigen::VectorXd::Zero(1)), InvalidArgument);
  EXPECT_THROW(a->addMeasurement(t, "gps", Eigen::VectorXd::Zero(1)), InvalidArgument);
  EXPECT_THROW(a->addMeasurement(Measurement{t, Eigen::VectorXd::Zero(2), 1, Eigen::MatrixXd::Identity(3, 3)}),
               InvalidArgument);
  EXPECT_THROW(a->addMeasurement(Measurement{t, Eigen::VectorXd::Zero(2), 7, {}}), InvalidArgument);
  try {
    a->addMeasurement(t, "lidar", Eigen::VectorXd::Zero(1));
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown channel 'lidar' (channels: y, gps)"), std::string::npos) << e.what();
  }
  EXPECT_EQ(a->current().mean, before.mean);
  EXPECT_EQ(a->step(), static_cast<std::int64_t>(kalman(model, ms).times.size()) - 1);
}

TEST(Channels, CheckpointsOfMultiChannelRunsContinueBitForBit) {
  const models::LinearModel model = twoSensorModel();
  const std::vector<Measurement> ms = twoRateRun(model, 75);
  for (const Method method : streamingMethods()) {
    auto full = makeEstimator(model, {method});
    auto cut = makeEstimator(model, {method});
    const std::size_t half = ms.size() / 2;
    for (std::size_t i = 0; i < half; ++i) cut->addMeasurement(ms[i]);
    auto restored = restoreCheckpointBytes(model, checkpointBytes(*cut));
    for (std::size_t i = 0; i < ms.size(); ++i) {
      full->addMeasurement(ms[i]);
      if (i >= half) restored->addMeasurement(ms[i]);
    }
    EXPECT_EQ(full->current().mean, restored->current().mean) << method;
    EXPECT_EQ(full->current().covariance, restored->current().covariance) << method;
  }
}
