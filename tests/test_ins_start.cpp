// The INS start from data alone (issue #37, point 5): Wahba's rotation
// against known rotations, and the start of a simulated drive — standing
// (the car pulls away) and in motion (turning, on a hill) — against its truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>

#include "expect_error.h"
#include "gssm/core/error.h"
#include "gssm/core/so3.h"
#include "gssm/models/ins_start.h"
#include "jacobian_check.h"
#include "reference_kalman.h"
#include "simulated_drive.h"

namespace gssm {
namespace {

using models::StrapdownIns;

TEST(InsStart, WahbaRecoversAKnownRotation) {
  std::mt19937 rng(3);
  for (const Eigen::Vector3d& phi : {Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0, 0, M_PI - 1e-6),
                                     Eigen::Vector3d(2.0, 1.0, -1.5), Eigen::Vector3d(1e-9, 0, 0)}) {
    const Eigen::Matrix3d R = so3::Exp(phi);
    const Eigen::Vector3d a = testing::uniformVector(rng, 3, -1, 1), b = testing::uniformVector(rng, 3, -1, 1);
    const Eigen::Matrix3d W = models::wahbaRotation({a, b}, {R * a, R * b}, {1.0, 0.5});
    EXPECT_LT(so3::minus(W, R).norm(), 1e-12) << phi.transpose();
    EXPECT_NEAR(W.determinant(), 1.0, 1e-12);
  }
  testing::expectThrowsNaming<InvalidArgument>(
      [] { models::wahbaRotation({Eigen::Vector3d::UnitX(), 2 * Eigen::Vector3d::UnitX()},
                                 {Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitY()}, {1.0, 1.0}); },
      {"parallel"});
}

StrapdownIns::Params startParams() {
  StrapdownIns::Params p;
  p.T = 0.02;
  p.anchor = {40.0 * M_PI / 180, -105.0 * M_PI / 180, 1600.0};
  p.mount_rpy = Eigen::Vector3d(M_PI, -0.12, M_PI + 0.09);
  p.gyro_sd = Eigen::VectorXd::Constant(1, 1e-3), p.accel_sd = 0.02, p.gnss_sd = 0.02;
  p.gyro_bias_sd = 2e-3, p.accel_bias_sd = 0.02, p.mount_sd = 1e-6, p.delay_sd = 1e-6;
  return p;
}

// The GNSS fixes (antenna positions) of a drive from `t0` on.
void fixesFrom(const testing::SimulatedDrive& d, double t0, std::vector<double>& t, std::vector<Eigen::Vector3d>& p) {
  for (const Measurement& m : d.measurements)
    if (m.channel == StrapdownIns::kGnss && m.t >= t0) t.push_back(m.t), p.push_back(m.y);
}

// Over 10 drives; the bounds are what the data allow: roll and pitch to
// the accelerometer bias over g (σ 2 mrad) and the GNSS velocities' noise
// over the 3 s window, yaw to the first 3 m of track of a car pulling away
// into a turn.
TEST(InsStart, StandingAndInMotionMatchTheTruth) {
  const StrapdownIns model(startParams());
  Eigen::Vector3d worst = Eigen::Vector3d::Zero();
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const testing::SimulatedDrive d = testing::simulateDrive(model, 30.0, testing::normalSampler(seed));
    for (double t0 : {0.0, 12.5}) {  // standing, then at 10 m/s turning at 0.25 rad/s on a hill
      std::vector<Input> imu;
      for (const Input& in : d.inputs)
        if (in.t >= t0) imu.push_back(in);
      std::vector<double> ft;
      std::vector<Eigen::Vector3d> fp;
      fixesFrom(d, t0, ft, fp);
      const models::InsStart s = models::insStart(t0, imu, ft, fp, model.mounting(d.constants), model.frame());
      EXPECT_EQ(s.moving, t0 > 0);
      const Eigen::Matrix3d truth = so3::Exp(d.states[static_cast<std::size_t>(std::lround(t0 / 0.02))].head<3>());
      const Eigen::Vector3d err = so3::minus(s.R_nb, truth);
      EXPECT_LT(err.head<2>().cwiseAbs().maxCoeff(), 0.03) << "seed " << seed << " t0 " << t0 << ": " << err.transpose();
      EXPECT_LT(std::abs(err.z()), 0.08) << "seed " << seed << " t0 " << t0 << ": " << err.transpose();
      worst = worst.cwiseMax(err.cwiseAbs());
    }
  }
  std::cout << "worst start error over 10 drives (about the IMU's x, y, z, rad): " << worst.transpose() << "\n";
  testing::expectThrowsNaming<InputError>(
      [&] {
        models::insStart(0.0, {}, {0.25, 0.5}, {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()},
                         Eigen::Matrix3d::Identity(), model.frame());
      },
      {"no IMU row"});
}

// A GNSS outage soon after the car pulls away (the drive's first one, 1.5 s
// after): the heading from the fixes before the gap, not from a chord
// across it, which averages the turn the car makes in the outage.
TEST(InsStart, PullingAwayIntoAnOutageTakesTheTrackBeforeIt) {
  const StrapdownIns model(startParams());
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const testing::SimulatedDrive d = testing::simulateDrive(model, 30.0, testing::normalSampler(seed));
    std::vector<double> all_t, ft;
    std::vector<Eigen::Vector3d> all_p, fp;
    fixesFrom(d, 0.0, all_t, all_p);
    double gap_from = 0;  // the outage: 10 s after the first fix 1.5 m from the start
    for (std::size_t i = 0; i < all_t.size() && gap_from == 0; ++i)
      if ((all_p[i] - all_p.front()).head<2>().norm() >= 1.5) gap_from = all_t[i] + 1e-3;
    for (std::size_t i = 0; i < all_t.size(); ++i)
      if (all_t[i] < gap_from || all_t[i] >= gap_from + 10) ft.push_back(all_t[i]), fp.push_back(all_p[i]);
    const models::InsStart s = models::insStart(0.0, d.inputs, ft, fp, model.mounting(d.constants), model.frame());
    const Eigen::Matrix3d truth = so3::Exp(d.states.front().head<3>());
    EXPECT_LT(std::abs(so3::minus(s.R_nb, truth).z()), 0.08) << "seed " << seed;
    // The chord across the gap, as the start took before: off by the turn.
    const Eigen::Vector3d across = fp[static_cast<std::size_t>(
                                       std::find_if(ft.begin(), ft.end(), [&](double t) { return t >= gap_from; }) -
                                       ft.begin())] - fp.front();
    const double yaw_across = std::atan2(across.y(), across.x());
    EXPECT_GT(std::abs(std::remainder(yaw_across - s.track_yaw, 2 * M_PI)), 0.15) << "seed " << seed;
  }
}

}  // namespace
}  // namespace gssm
