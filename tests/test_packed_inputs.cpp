// Packed inputs (docs/DESIGN.md §12, "States between IMU samples"): the
// packing of raw readings into steps against the readings and cuts it was
// given, the INS's f over a pack against its one-reading steps in turn,
// its chained Jacobians against differences on the manifold, and a whole
// filter pass against the filter at every sample.
#include <gtest/gtest.h>

#include <cmath>

#include "gssm/core/error.h"
#include "gssm/core/so3.h"
#include "gssm/factors/problem.h"
#include "gssm/model/packed_inputs.h"
#include "gssm/models/strapdown_ins.h"
#include "gssm/solvers/ekf.h"
#include "jacobian_check.h"
#include "reference_kalman.h"
#include "simulated_drive.h"

namespace gssm {
namespace {

using models::StrapdownIns;

std::vector<Input> rawReadings(int n, double T) {
  std::vector<Input> raw;
  for (int i = 0; i < n; ++i) raw.push_back({i * T, Eigen::Vector2d(i, -i)});
  return raw;
}

// The raw reading in force at t (held from its time).
Eigen::VectorXd inForce(const std::vector<Input>& raw, double t) {
  const Input* last = nullptr;  // found first, copied once
  for (const auto& in : raw)
    if (in.t <= t + 1e-12) last = &in;
  return last ? last->u : Eigen::VectorXd::Zero(raw.front().u.size());
}

TEST(PackedInputs, StepsEndAtEveryCutAndHoldAtMostNReadings) {
  const double T = 0.01;
  const std::vector<Input> raw = rawReadings(51, T);  // 0 … 0.5 s
  const std::vector<double> cuts{0.105, 0.25, 0.3, 0.3, 0.4449};
  const int N = 4;
  const std::vector<Input> packed = packInputs(raw, cuts, N, 0.0);
  ASSERT_GT(packed.size(), 10u);
  EXPECT_EQ(packed.front().t, 0.0);
  EXPECT_NEAR(packed.back().t, 0.5, 1e-12);
  for (double c : cuts) {  // every cut starts a step
    bool found = false;
    for (const auto& p : packed) found = found || std::abs(p.t - c) < 1e-12;
    EXPECT_TRUE(found) << "cut " << c;
  }
  for (std::size_t k = 0; k + 1 < packed.size(); ++k) {
    const Eigen::VectorXd& u = packed[k].u;
    ASSERT_EQ(u.size(), N * 3);
    double t = packed[k].t, sum = 0;
    for (int j = 0; j < N; ++j) {
      const double dj = u[3 * j];
      EXPECT_GE(dj, 0.0);
      if (dj > 0) {
        EXPECT_EQ(Eigen::VectorXd(u.segment(3 * j + 1, 2)), inForce(raw, t)) << "step " << k << " slot " << j;
      }
      t += dj, sum += dj;
    }
    EXPECT_NEAR(sum, packed[k + 1].t - packed[k].t, 1e-12) << "step " << k;
    EXPECT_GT(u[0], 0.0);
  }
  // Without cuts: N readings a step, so N·T.
  const std::vector<Input> plain = packInputs(raw, {}, 5, 0.0);
  ASSERT_EQ(plain.size(), 11u);
  for (std::size_t k = 0; k < plain.size(); ++k) EXPECT_NEAR(plain[k].t, 0.05 * static_cast<double>(k), 1e-12);
  EXPECT_THROW(packInputs(raw, {}, 0, 0.0), InvalidArgument);
}

StrapdownIns::Params insParams(int per_state) {
  StrapdownIns::Params p;
  p.T = 0.01;
  p.anchor = {40.0 * M_PI / 180, -105.0 * M_PI / 180, 1600.0};
  p.mount_rpy = Eigen::Vector3d(M_PI, 0.0, M_PI);
  p.start_rpy = testing::driveStartRpy(p.mount_rpy);
  p.imu_per_state = per_state;
  return p;
}

// A pack of `n` readings with durations 0.004 … 0.013 s, then unused slots.
Eigen::VectorXd randomPack(std::mt19937& rng, int slots, int n) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(7 * slots);
  std::uniform_real_distribution<double> dur(0.004, 0.013);
  for (int j = 0; j < slots; ++j) {
    u.segment<6>(7 * j + 1) = testing::uniformVector(rng, 6, -1, 1);
    u[7 * j + 6] -= 9.8;
    if (j < n) u[7 * j] = dur(rng);
    else u.segment<6>(7 * j + 1) = u.segment<6>(7 * (n - 1) + 1);
  }
  return u;
}

TEST(PackedInputs, InsOverAPackIsItsOneReadingStepsInTurn) {
  const StrapdownIns one(insParams(1)), packed(insParams(10));
  EXPECT_EQ(packed.dims().nu, 70);
  EXPECT_EQ(packed.readingsPerStep(), 10);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 1 + trial % 10;
    const Eigen::VectorXd u = randomPack(rng, 10, n);
    Eigen::VectorXd xc = testing::uniformVector(rng, 10, -5, 5);
    xc.head<3>() = so3::Log(so3::fromRollPitchYaw(testing::uniformVector(rng, 3, -3, 3)));
    const Eigen::VectorXd xb = testing::uniformVector(rng, StrapdownIns::kConstants, -0.05, 0.05);
    double total = 0;
    for (int j = 0; j < n; ++j) total += u[7 * j];
    // All of it, part of it (the last reading cut short), and past its end (the last held).
    for (double dt : {total, 0.6 * total, total + 0.02}) {
      Eigen::VectorXd x = xc;
      double left = dt;
      for (int j = 0; j < 10 && left > 1e-15; ++j) {
        const double h = (j + 1 == n || j + 1 == 10) ? left : std::min(u[7 * j], left);
        x = one.f(x, xb, u.segment<6>(7 * j + 1), h);
        left -= h;
      }
      const Eigen::VectorXd y = packed.f(xc, xb, u, dt);
      // The pack takes gravity from its start point and the field's slope
      // (strapdown::LocalGravity), the steps from each reading's point: a
      // few 1e-8 m/s² over the metre moved, ~1e-9 m/s in velocity. A
      // reading skipped or cut wrong moves it by 1e-3 and more.
      EXPECT_LT((y - x).cwiseAbs().maxCoeff(), 1e-8) << "trial " << trial << " dt " << dt;
    }
  }
}

TEST(PackedInputs, InsJacobiansOverAPackMatchTangentDifferences) {
  for (double walk : {0.0, 1e-4}) {  // with β_g in x_c, as b_g
  StrapdownIns::Params params = insParams(10);
  params.gyro_bias_walk = walk;
  const StrapdownIns model(params);
  const std::vector<Eigen::Vector3d> rpy{{0.01, -0.02, 0.3}, {0.3, M_PI / 2, 1.0}, {0.0, 0.0, -M_PI + 1e-6}};
  testing::expectJacobiansMatchDifferences(model, [&](std::mt19937& rng) {
    testing::JacobianPoint p;
    p.xc = testing::uniformVector(rng, model.dims().nc, -20, 20);
    if (walk > 0) p.xc.tail<3>() *= 1e-4;
    p.xc.head<3>() = so3::Log(so3::fromRollPitchYaw(rpy[std::uniform_int_distribution<std::size_t>(0, 2)(rng)]));
    p.xb = testing::uniformVector(rng, StrapdownIns::kConstants, -0.1, 0.1);
    p.u = randomPack(rng, 10, 7);
    p.dt = 0;
    for (int j = 0; j < 7; ++j) p.dt += p.u[7 * j];
    return p;
  }, 20, 1e-5);
  }
}

// With (almost) no process noise the filter over packed steps is the filter
// at every sample: the same f composed, the same chained Jacobians, updates
// at the same times.
TEST(PackedInputs, AFilterOverPacksIsTheFilterAtEverySample) {
  StrapdownIns::Params p = insParams(1);
  p.gyro_sd = Eigen::VectorXd::Constant(1, 1e-10), p.accel_sd = 1e-10, p.clock_wander_sd = 1e-12;
  const StrapdownIns one(p);
  p.imu_per_state = 10;
  const StrapdownIns packed(p);
  const testing::SimulatedDrive d = testing::simulateDrive(one, 20.0, testing::normalSampler(8));
  std::vector<double> cuts;
  for (const auto& m : d.measurements) cuts.push_back(m.t);
  const std::vector<Input> packs = packInputs(d.inputs, cuts, 10, 0.0);
  EXPECT_LT(packs.size(), d.inputs.size() / 3);
  ExtendedKalmanFilter a(one, {}, 0.0), b(packed, {}, 0.0);
  filterAlong(a, stepSchedule(d.measurements, d.inputs, 0.0), d.measurements, d.inputs);
  filterAlong(b, stepSchedule(d.measurements, packs, 0.0), d.measurements, packs);
  ASSERT_EQ(a.mean().size(), b.mean().size());
  const Eigen::VectorXd sd = a.covariance().diagonal().cwiseSqrt();
  EXPECT_LT((a.mean() - b.mean()).cwiseQuotient(sd).cwiseAbs().maxCoeff(), 1e-4)
      << (a.mean() - b.mean()).transpose() << "\n" << sd.transpose();
  EXPECT_LT((a.covariance() - b.covariance()).cwiseAbs().maxCoeff() / a.covariance().cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_NEAR(a.logLikelihood(), b.logLikelihood(), 1e-6 * std::abs(a.logLikelihood()));
}

}  // namespace
}  // namespace gssm
