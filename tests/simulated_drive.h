#pragma once
// A simulated car drive for the strapdown GNSS/INS tests (issue #37): a
// known vehicle trajectory (standing, pulling away, turns, hills), the IMU
// mounted in it with a misalignment, readings generated through the model's
// own step so that the truth is what the model says plus its process noise,
// GNSS fixes of the antenna at 4 Hz, the vehicle constraints at 10 Hz.
#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "gssm/core/data.h"
#include "gssm/core/rotation_blocks.h"
#include "gssm/core/so3.h"
#include "gssm/model/simulation.h"
#include "gssm/models/strapdown_ins.h"

namespace gssm::testing {

struct SimulatedDrive {
  std::vector<Measurement> measurements;
  std::vector<Input> inputs;
  std::vector<Eigen::VectorXd> states;  ///< true x_c at each IMU time
  Eigen::VectorXd constants;            ///< true x_b
};

/// The vehicle's desired attitude (a pitch for the hills, a yaw for the
/// turns, a roll rocking at 0.5 Hz by roll_amplitude rad while driving) and
/// forward speed at t: standing 5 s, then driving.
inline void vehicleAt(double t, Eigen::Matrix3d& R_nv, double& speed, double roll_amplitude = 0.0) {
  const double drive = std::max(0.0, t - 5.0);
  speed = std::min(10.0, 2.0 * drive);
  const double yaw = 0.3 + (drive > 0 ? 0.25 * 30 / (2 * M_PI) * (1 - std::cos(2 * M_PI * drive / 30)) : 0.0);
  const double pitch = 0.05 * std::sin(2 * M_PI * drive / 40);
  const double roll = roll_amplitude * std::sin(2 * M_PI * drive / 2);
  R_nv = so3::fromRollPitchYaw(Eigen::Vector3d(roll, pitch, yaw));
}

/// The IMU's roll, pitch, yaw at the drive's start, mounted at `mount_rpy`
/// (IMU → vehicle): a model's prior mean for it.
inline Eigen::Vector3d driveStartRpy(const Eigen::Vector3d& mount_rpy) {
  Eigen::Matrix3d R_nv;
  double speed;
  vehicleAt(0.0, R_nv, speed);
  return so3::rollPitchYaw(R_nv * so3::fromRollPitchYaw(mount_rpy));
}

/// The IMU's velocity in vehicle axes for the vehicle's forward speed, its
/// rate Ω and the specific force F (vehicle axes): the constraints hold at
/// the model's points (Params::nhc_point, the truth's where they are
/// constants) in axes turned by its give (Params::nhc_compliance), so the
/// IMU moves sideways by −(Ω×r_side)_y − k_s·F_r·speed and vertically by
/// −(Ω×r_vert)_z − k_v·F_f·speed.
inline Eigen::Vector3d imuVelocityInVehicle(const models::StrapdownIns& model, const Eigen::VectorXd& constants,
                                            double speed, const Eigen::Vector3d& Omega, const Eigen::Vector3d& F) {
  const Eigen::Vector4d r = model.nhcPoint(constants);
  const Eigen::Vector2d k = model.nhcCompliance(constants);
  const Eigen::Vector3d side = Omega.cross(Eigen::Vector3d(r[0], 0, r[1]));
  const Eigen::Vector3d vert = Omega.cross(Eigen::Vector3d(r[2], r[3], 0));
  return {speed, -side.y() - k[0] * F.y() * speed, -vert.z() - k[1] * F.x() * speed};
}

/// The accelerometer reading whose specific force, as the model corrects it
/// ((1 − s_a)∘f̃ − b_a, then R_vb), is F in vehicle axes.
inline Eigen::Vector3d accelReadingFor(const Eigen::VectorXd& constants, const Eigen::Matrix3d& R_vb,
                                       const Eigen::Vector3d& F) {
  using Ins = models::StrapdownIns;
  return (R_vb.transpose() * F + constants.segment<3>(Ins::kAccelBias))
      .cwiseQuotient(Eigen::Vector3d::Ones() - constants.segment<3>(Ins::kAccelScale));
}

/// White noise on one IMU reading held over T: the gyro's σ per axis (one
/// for all or one each) and the accelerometer's, each /√T.
inline Eigen::VectorXd readingNoise(const models::StrapdownIns::Params& p, double T, const NormalSampler& draw) {
  Eigen::VectorXd sd(6);
  for (int i = 0; i < 3; ++i) sd[i] = p.gyroSdAbout(i) / std::sqrt(T);
  sd.tail<3>().setConstant(p.accel_sd / std::sqrt(T));
  return sampleGaussian(Eigen::VectorXd::Zero(6), Eigen::MatrixXd(sd.cwiseAbs2().asDiagonal()), draw);
}

/// Drives `seconds` with `model` (its T the IMU interval); the constants
/// drawn from the model's prior, the start its prior mean; the body rocks
/// in roll by roll_amplitude (rad) while driving. A constraint that reads
/// the IMU (Measurement::regressors) carries the step's gyro reading and
/// an accelerometer reading of the path's specific force (the vehicle's
/// acceleration along its nominal path less gravity, smooth: the body's
/// give follows it, and a give following the jittering readings would feed
/// back on itself). The noise: by default the model's process noise on the
/// state, each next reading steering back to the path (the state jitters
/// about it); with noisy_readings, white noise on the readings instead (the
/// model's gyro σ per axis and accelerometer σ, each /√T), the state on the
/// path and the constraints' zeros drawn with their σs: the noise then
/// accumulates as Q says and every channel is as noisy as R says, what a
/// noise learner needs.
inline SimulatedDrive simulateDrive(const models::StrapdownIns& model, double seconds, const NormalSampler& draw,
                                    double roll_amplitude = 0.0, bool noisy_readings = false) {
  SimulatedDrive d;
  const double T = model.nominalStep();
  d.constants = sampleGaussian(model.priorConstants().mean, model.priorConstants().covariance, draw);
  const Eigen::Matrix3d R_vb = model.mounting(d.constants);
  Eigen::Matrix3d R_nv;
  double speed;
  vehicleAt(0, R_nv, speed, roll_amplitude);
  Eigen::Vector3d path_velocity = R_nv * Eigen::Vector3d(speed, 0, 0);
  Eigen::VectorXd x(models::StrapdownIns::kStates);
  x << so3::Log(R_nv * R_vb), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.0;
  d.states.push_back(x);
  const Eigen::VectorXd bias = d.constants.head<6>();
  const int steps = static_cast<int>(std::lround(seconds / T));
  for (int k = 0; k < steps; ++k) {
    const double t = k * T;
    // The IMU's true rate and specific force that take the state to the
    // desired attitude and velocity at t + T under the model's step.
    vehicleAt(t + T, R_nv, speed, roll_amplitude);
    const Eigen::Matrix3d R = so3::Exp(x.head<3>());
    const Eigen::Matrix3d R_next = R_nv * R_vb;
    const Eigen::Vector3d w_ie = model.frame().earthRate();
    const Eigen::Vector3d gyro = so3::Log(R.transpose() * so3::Exp(w_ie * T) * R_next) / T;
    const Eigen::Vector3d v = x.segment<3>(3);
    const Eigen::Vector3d path_next = R_nv * Eigen::Vector3d(speed, 0, 0);
    const Eigen::Vector3d F = R_nv.transpose() * ((path_next - path_velocity) / T - model.frame().gravity(x.segment<3>(6)));
    path_velocity = path_next;
    const Eigen::Vector3d v_next = R_nv * imuVelocityInVehicle(model, d.constants, speed, R_vb * gyro, F);
    const Eigen::Vector3d accel =
        R.transpose() * ((v_next - v) / T - model.frame().gravity(x.segment<3>(6)) + 2 * w_ie.cross(v));
    Eigen::VectorXd u(6);
    u << gyro, accel;
    u += bias;  // what the IMU reads
    Eigen::VectorXd read = u;
    if (noisy_readings) read += readingNoise(model.params(), T, draw);
    d.inputs.push_back({t, read});
    x = model.f(x, d.constants, u, T);
    if (!noisy_readings)
      retractBlocks(x, sampleGaussian(Eigen::VectorXd::Zero(x.size()), model.processNoise(T), draw), model.rotationBlocks());
    d.states.push_back(x);
    const double tn = (k + 1) * T;
    const int n = k + 1;
    const int per_gnss = static_cast<int>(std::lround(0.25 / T)), per_constraint = static_cast<int>(std::lround(0.1 / T));
    using Ins = models::StrapdownIns;
    if (n % per_gnss == 0) {
      const Eigen::Vector3d y = model.h(Ins::kGnss, x, d.constants) +
                                sampleGaussian(Eigen::Vector3d::Zero(), model.channel(Ins::kGnss).R, draw);
      d.measurements.push_back({tn, y, Ins::kGnss, {}});
    }
    if (n % per_constraint == 0) {
      const bool standing = tn < 5.0;
      const int c = standing ? Ins::kZupt : Ins::kNhc;
      Eigen::VectorXd reading(model.channel(c).regressors);
      if (reading.size() >= 3) reading.head<3>() = read.head<3>();
      if (reading.size() == 6) reading.tail<3>() = accelReadingFor(d.constants, R_vb, F);
      // The constraint holds on the path exactly: with the noise on the
      // readings its σ is the measurement's (the model says it is noisy)
      const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.channel(c).dim());
      d.measurements.push_back({tn, noisy_readings ? sampleGaussian(zero, model.channel(c).R, draw) : zero, c, {}, reading});
    }
  }
  return d;
}

}  // namespace gssm::testing
