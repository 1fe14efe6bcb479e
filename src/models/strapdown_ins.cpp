#include "gssm/models/strapdown_ins.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/core/so3.h"
#include "gssm/model/noise_params.h"
#include "gssm/model/packed_inputs.h"
#include "gssm/model/registry.h"
#include "gssm/models/ins_start.h"

namespace gssm::models {

namespace {
using so3::hat;

int insStates(const StrapdownIns::Params& p) { return StrapdownIns::kStates + (p.gyro_bias_walk > 0 ? 3 : 0); }

const char* const kNhcShapeNames[6] = {"nhc_side_f", "nhc_side_d", "nhc_vert_f", "nhc_vert_r", "nhc_side_k", "nhc_vert_k"};

// The constraints' optional constants in x_b's order: the points' four,
// then the body's give's two (their prior means, their σs).
Eigen::Matrix<double, 6, 1> nhcShapeMeans(const StrapdownIns::Params& p) {
  return (Eigen::Matrix<double, 6, 1>() << p.nhc_point, p.nhc_compliance).finished();
}
Eigen::Matrix<double, 6, 1> nhcShapeSds(const StrapdownIns::Params& p) {
  return (Eigen::Matrix<double, 6, 1>() << p.nhc_point_sd, p.nhc_compliance_sd).finished();
}

// Where each of them is in x_b: after every INS's constants, one per
// component with σ > 0 in turn (−1: held at its mean).
std::array<int, 6> nhcShapeIndices(const StrapdownIns::Params& p) {
  std::array<int, 6> index;
  const Eigen::Matrix<double, 6, 1> sd = nhcShapeSds(p);
  for (int i = 0, b = StrapdownIns::kConstants; i < 6; ++i) index[static_cast<std::size_t>(i)] = sd[i] > 0 ? b++ : -1;
  return index;
}

int insConstants(const StrapdownIns::Params& p) {
  return StrapdownIns::kConstants + static_cast<int>((nhcShapeSds(p).array() > 0).count());
}

ModelNames insNames(const StrapdownIns::Params& p) {
  ModelNames n;
  n.state = {"att_x", "att_y", "att_z", "vn", "ve", "vd", "pn", "pe", "pd", "clock"};
  if (p.gyro_bias_walk > 0) n.state.insert(n.state.end(), {"bgw_x", "bgw_y", "bgw_z"});
  n.constants = {"bg_x", "bg_y", "bg_z", "ba_x", "ba_y", "ba_z", "lever_x", "lever_y", "lever_z",
                 "mount_roll", "mount_pitch", "mount_yaw", "imu_delay", "sg_x", "sg_y", "sg_z", "sa_x", "sa_y", "sa_z", "clock_rate"};
  const Eigen::Matrix<double, 6, 1> shape_sd = nhcShapeSds(p);
  for (int i = 0; i < 6; ++i)
    if (shape_sd[i] > 0) n.constants.push_back(kNhcShapeNames[i]);
  n.input = {"gx", "gy", "gz", "ax", "ay", "az"};
  if (p.imu_per_state > 1) {  // dt_j, then the reading j: packed_inputs.h
    std::vector<std::string> packed;
    for (int j = 1; j <= p.imu_per_state; ++j) {
      packed.push_back("dt_" + std::to_string(j));
      for (const auto& c : n.input) packed.push_back(c + "_" + std::to_string(j));
    }
    n.input = packed;
  }
  n.measurement = {"gnss_n", "gnss_e", "gnss_d"};
  return n;
}

// θ: the gyro's white noise in the body tangent; (v, p): white acceleration,
// σ_a²·[[dt, dt²/2], [dt²/2, dt³/3]] on each axis (isotropic: R·σ²I·Rᵀ = σ²I);
// the clock: its wander beyond the constant rate; β_g: its walk.
Eigen::MatrixXd insProcessNoise(const StrapdownIns::Params& p, double dt) {
  const int nc = insStates(p);
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(nc, nc);
  Q(9, 9) = p.clock_wander_sd * p.clock_wander_sd * dt;
  if (nc > StrapdownIns::kStates)
    Q.block<3, 3>(StrapdownIns::kGyroWalk, StrapdownIns::kGyroWalk).diagonal().setConstant(
        p.gyro_bias_walk * p.gyro_bias_walk * dt);
  const double a = p.accel_sd * p.accel_sd;
  for (int i = 0; i < 3; ++i) {
    const double g = p.gyroSdAbout(i);  // θ is in the IMU's axes
    Q(i, i) = g * g * dt;
    Q(3 + i, 3 + i) = a * dt;
    Q(3 + i, 6 + i) = Q(6 + i, 3 + i) = a * dt * dt / 2;
    Q(6 + i, 6 + i) = a * dt * dt * dt / 3;
  }
  return Q;
}

ModelNoise insNoise(const StrapdownIns::Params& p) {
  if ((p.gyro_sd.size() != 1 && p.gyro_sd.size() != 3) || !(p.gyro_sd.array() > 0).all() || !p.gyro_sd.allFinite())
    throw InvalidArgument("StrapdownIns: gyro_sd must be one σ > 0 (every axis) or three (the IMU's x, y, z), got " +
                          std::to_string(p.gyro_sd.size()) + " values");
  for (double v : {p.T, p.accel_sd, p.gnss_sd, p.gnss_sd_scale, p.gnss_vel_sd, p.gnss_vel_sd_scale,
                   p.nhc_sd, p.nhc_down_sd, p.zupt_sd, p.zaru_sd, p.attitude_sd, p.velocity_sd,
                   p.position_sd, p.gyro_bias_sd, p.accel_bias_sd, p.lever_sd, p.mount_sd, p.delay_sd,
                   p.gyro_scale_sd, p.accel_scale_sd, p.clock_rate_sd, p.clock_wander_sd})
    if (!(v > 0) || !std::isfinite(v)) throw InvalidArgument("StrapdownIns: every σ and T must be > 0");
  if (p.imu_per_state < 1 || p.imu_per_state > 1000)
    throw InvalidArgument("StrapdownIns: imu_per_state = " + std::to_string(p.imu_per_state) + ": expected 1..1000");
  if (!(p.start_heading_sd >= 0) || !std::isfinite(p.start_heading_sd))
    throw InvalidArgument("StrapdownIns: start_heading_sd must be >= 0");
  if (!(p.gnss_vel_latency >= 0) || !std::isfinite(p.gnss_vel_latency))
    throw InvalidArgument("StrapdownIns: gnss_vel_latency must be >= 0 (s)");
  if (!(p.nhc_ekf_gate >= 0) || !std::isfinite(p.nhc_ekf_gate))
    throw InvalidArgument("StrapdownIns: nhc_ekf_gate must be >= 0 (0: no gate)");
  if (!(p.nhc_point_sd.array() >= 0).all() || !p.nhc_point_sd.allFinite() || !p.nhc_point.allFinite())
    throw InvalidArgument("StrapdownIns: nhc_point must be finite and nhc_point_sd >= 0 (0: held at its mean)");
  if (!(p.nhc_compliance_sd.array() >= 0).all() || !p.nhc_compliance_sd.allFinite() || !p.nhc_compliance.allFinite())
    throw InvalidArgument(
        "StrapdownIns: nhc_compliance must be finite and nhc_compliance_sd >= 0 (0: held at its mean)");
  if (!(p.gyro_bias_walk >= 0) || !std::isfinite(p.gyro_bias_walk))
    throw InvalidArgument("StrapdownIns: gyro_bias_walk must be >= 0 (0: a constant gyro bias)");
  ModelNoise n;
  n.T = p.T;
  n.Q = insProcessNoise(p, p.T);
  n.R = Eigen::Matrix3d::Identity() * p.gnss_sd * p.gnss_sd;
  const int nc = insStates(p);
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(nc), sd(nc);
  const Eigen::Matrix3d R0 = so3::fromRollPitchYaw(p.start_rpy);
  mean.head<StrapdownIns::kStates>() << so3::Log(R0), p.start_velocity, p.start_position, 0.0;
  sd.head<StrapdownIns::kStates>() << Eigen::Vector3d::Constant(p.attitude_sd), Eigen::Vector3d::Constant(p.velocity_sd),
      Eigen::Vector3d::Constant(p.position_sd), p.clock_wander_sd * std::sqrt(p.T);  // the clock starts at 0
  // β_g starts at 0 (b_g holds the bias at the start), as firmly as the clock.
  if (nc > StrapdownIns::kStates) sd.tail<3>().setConstant(p.gyro_bias_walk * std::sqrt(p.T));
  n.prior_state = {mean, Eigen::MatrixXd(sd.cwiseAbs2().asDiagonal())};
  // The heading's further variance on the tangent δθ (R ⊕ δθ = R·Exp(δθ)):
  // a turn ψ about the frame's down is δθ = ψ·Rᵀe_d.
  const Eigen::Vector3d down_in_body = R0.transpose() * Eigen::Vector3d::UnitZ();
  n.prior_state.covariance.topLeftCorner<3, 3>() +=
      p.start_heading_sd * p.start_heading_sd * down_in_body * down_in_body.transpose();
  Eigen::VectorXd bmean = Eigen::VectorXd::Zero(insConstants(p)), bsd(insConstants(p));
  bmean.segment<3>(StrapdownIns::kGyroBias) = p.gyro_bias;
  bmean.segment<3>(StrapdownIns::kAccelBias) = p.accel_bias;
  bmean.segment<3>(StrapdownIns::kLever) = so3::fromRollPitchYaw(p.mount_rpy).transpose() * p.lever;  // IMU axes
  bmean(StrapdownIns::kDelay) = p.delay;
  bmean.segment<3>(StrapdownIns::kGyroScale) = p.gyro_scale;
  bmean.segment<3>(StrapdownIns::kAccelScale) = p.accel_scale;
  bmean(StrapdownIns::kClockRate) = p.clock_rate;
  bsd.head(StrapdownIns::kConstants) << Eigen::Vector3d::Constant(p.gyro_bias_sd),
      Eigen::Vector3d::Constant(p.accel_bias_sd), Eigen::Vector3d::Constant(p.lever_sd),
      Eigen::Vector3d::Constant(p.mount_sd), p.delay_sd, Eigen::Vector3d::Constant(p.gyro_scale_sd),
      Eigen::Vector3d::Constant(p.accel_scale_sd), p.clock_rate_sd;  // then the constraints' points' and give's
  const std::array<int, 6> shape = nhcShapeIndices(p);
  for (std::size_t i = 0; i < 6; ++i)
    if (shape[i] >= 0) {
      bmean[shape[i]] = nhcShapeMeans(p)[static_cast<Eigen::Index>(i)];
      bsd[shape[i]] = nhcShapeSds(p)[static_cast<Eigen::Index>(i)];
    }
  n.prior_constants = {bmean, Eigen::MatrixXd(bsd.cwiseAbs2().asDiagonal())};
  return n;
}

MeasurementChannel channelOf(const std::string& name, std::vector<std::string> components,
                             const Eigen::VectorXd& sd, std::vector<int> constants) {
  MeasurementChannel c;
  c.name = name;
  c.R = sd.cwiseAbs2().asDiagonal();
  c.components = std::move(components);
  c.constants = std::move(constants);
  return c;
}

// The antenna's velocity: it reads the IMU's mean rates and the velocity's
// rate of change at the fix (6 regressors), and the gyro's constants, the
// lever arm and the clock's.
MeasurementChannel gnssVelocityChannel(const StrapdownIns::Params& p) {
  using S = StrapdownIns;
  MeasurementChannel c = channelOf("gnss_vel", {"gnss_vn", "gnss_ve", "gnss_vd"}, Eigen::Vector3d::Constant(p.gnss_vel_sd),
                                   {0, 1, 2, 6, 7, 8, S::kDelay, 13, 14, 15, S::kClockRate});
  c.regressors = 6;
  c.own_R_scale = p.gnss_vel_sd_scale * p.gnss_vel_sd_scale;
  return c;
}
}  // namespace

StrapdownIns::StrapdownIns(const Params& p)
    : Model({insStates(p), insConstants(p), p.imu_per_state == 1 ? 6 : 7 * p.imu_per_state, 3}, insNames(p),
            insNoise(p)),
      p_(p),
      frame_(p.anchor),
      mount0_(so3::fromRollPitchYaw(p.mount_rpy)),
      nhc_points_off_imu_(!p.nhc_point.isZero() || !p.nhc_point_sd.isZero()),
      nhc_compliant_(!p.nhc_compliance.isZero() || !p.nhc_compliance_sd.isZero()) {
  const std::array<int, 6> shape = nhcShapeIndices(p);
  std::copy(shape.begin(), shape.begin() + 4, nhc_point_index_.begin());
  std::copy(shape.begin() + 4, shape.end(), nhc_compliance_index_.begin());
  MeasurementChannel gnss =
      channelOf("gnss", {"gnss_n", "gnss_e", "gnss_d"}, Eigen::Vector3d::Constant(p.gnss_sd), {6, 7, 8, kDelay, kClockRate});
  gnss.own_R_scale = p.gnss_sd_scale * p.gnss_sd_scale;
  MeasurementChannel nhc = channelOf("nhc", {"nhc_right", "nhc_down"}, Eigen::Vector2d(p.nhc_sd, p.nhc_down_sd), {9, 10, 11});
  if (nhc_points_off_imu_) {  // the points turn with the body: the gyro's reading, its bias and scale
    nhc.regressors = 3;
    nhc.constants.insert(nhc.constants.end(),
                         {kGyroBias, kGyroBias + 1, kGyroBias + 2, kGyroScale, kGyroScale + 1, kGyroScale + 2});
  }
  if (nhc_compliant_) {  // the give follows the specific force: the accelerometer's reading too
    nhc.regressors = 6;
    nhc.constants.insert(nhc.constants.end(),
                         {kAccelBias, kAccelBias + 1, kAccelBias + 2, kAccelScale, kAccelScale + 1, kAccelScale + 2});
  }
  for (int b = kConstants; b < insConstants(p); ++b) nhc.constants.push_back(b);
  std::sort(nhc.constants.begin(), nhc.constants.end());
  nhc.loss = p.nhc_loss;
  nhc.ekf_gate = p.nhc_ekf_gate;
  setChannels({std::move(gnss), std::move(nhc),
               channelOf("zupt", {"zupt_n", "zupt_e", "zupt_d"}, Eigen::Vector3d::Constant(p.zupt_sd), {}),
               channelOf("zaru", {"zaru_x", "zaru_y", "zaru_z"}, Eigen::Vector3d::Constant(p.zaru_sd), {0, 1, 2}),
               gnssVelocityChannel(p)});
  setRotationBlocks({0});
}

// R_vb = Rx(μ_r)·Ry(μ_p)·Rz(μ_y)·R_vb0: the vehicle's forward axis in the
// IMU's axes, R_vbᵀ·e_x = R_vb0ᵀ·Rz(−μ_y)·Ry(−μ_p)·e_x, does not depend on
// the roll μ_r. Right Jacobian: Mᵀ∂M = [(Ry·Rz)ᵀe_x, Rzᵀe_y, e_z] (M the
// misalignment), moved to R_vb's tangent by R_vb0ᵀ.
Eigen::Matrix3d StrapdownIns::mounting(const Eigen::VectorXd& xb, Eigen::Matrix3d* J_out_mu) const {
  const Eigen::Vector3d mu = xb.segment<3>(kMount);
  const Eigen::Matrix3d Rx = Eigen::AngleAxisd(mu.x(), Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d Ry = Eigen::AngleAxisd(mu.y(), Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(mu.z(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  if (J_out_mu) {
    Eigen::Matrix3d J;
    J << (Ry * Rz).transpose().col(0), Rz.transpose().col(1), Eigen::Vector3d::UnitZ();
    *J_out_mu = mount0_.transpose() * J;
  }
  return Rx * Ry * Rz * mount0_;
}

// N = 1: one step. N > 1: the readings in turn on the navigation state
// (no rotation vector between them), the Jacobians chained over its nine
// rows: J_x ← J_j·J_x, J_b ← J_j·J_b + J_j,b (b: the gyro's and the
// accelerometer's biases and scale factors, those f reaches); the clock
// adds dt.
Eigen::VectorXd StrapdownIns::f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u,
                                double dt, Eigen::MatrixXd* J_f_xc, Eigen::MatrixXd* J_f_xb) const {
  if (p_.imu_per_state == 1) return step(xc, xb, u, dt, J_f_xc, J_f_xb);
  strapdown::NavState x{so3::Exp(xc.head<3>()), xc.segment<3>(3), xc.segment<3>(6)};
  const bool jac = J_f_xc || J_f_xb;
  Eigen::Matrix<double, 9, 9> Jx = Eigen::Matrix<double, 9, 9>::Identity();
  Eigen::Matrix<double, 9, 12> Jb = Eigen::Matrix<double, 9, 12>::Zero(), jb;  // b_g, b_a, s_g, s_a
  strapdown::StepJacobians J;
  const Eigen::Vector3d sg = xb.segment<3>(kGyroScale), sa = xb.segment<3>(kAccelScale);
  const Eigen::Vector3d bg = gyroBias(xc, xb), ba = xb.segment<3>(kAccelBias);
  const strapdown::LocalGravity gravity(frame_, x.p);  // one geodetic evaluation a pack
  forEachPackedReading(u, p_.imu_per_state, dt, [&](const auto& reading, double h) {
    const Eigen::Vector3d gyro = reading.template head<3>(), accel = reading.template tail<3>();
    x = strapdown::step(x, gyro - sg.cwiseProduct(gyro), accel - sa.cwiseProduct(accel), bg, ba, h, frame_, gravity,
                        jac ? &J : nullptr);
    if (!jac) return;
    jb << J.J_next_bg, J.J_next_ba, J.J_next_bg * gyro.asDiagonal(), J.J_next_ba * accel.asDiagonal();
    // The step's block structure (Eigen's blocked product had taken a third
    // of a filter pass, its dense coefficient-wise product a fifth).
    Jb = J.leftMultiply(Jb) + jb;
    Jx = J.leftMultiply(Jx);
  });
  return stepResult(xc, x, dt, Jx, Jb, J_f_xc, J_f_xb);
}

// x_c after a step to the navigation state `next` over dt (the clock adds dt,
// β_g stays), and f's Jacobians from those of the nine navigation rows: Jx
// on them, Jb on [b_g, b_a, s_g, s_a] (β_g enters as b_g does).
Eigen::VectorXd StrapdownIns::stepResult(const Eigen::VectorXd& xc, const strapdown::NavState& next, double dt,
                                         const Eigen::Matrix<double, 9, 9>& Jx,
                                         const Eigen::Matrix<double, 9, 12>& Jb, Eigen::MatrixXd* J_f_xc,
                                         Eigen::MatrixXd* J_f_xb) const {
  const int nc = dims().nc;
  if (J_f_xc) {
    J_f_xc->setZero(nc, nc);
    J_f_xc->topLeftCorner<9, 9>() = Jx;
    (*J_f_xc)(kClock, kClock) = 1;
    if (gyroBiasWalks()) {
      J_f_xc->block<9, 3>(0, kGyroWalk) = Jb.leftCols<3>();
      J_f_xc->block<3, 3>(kGyroWalk, kGyroWalk).setIdentity();
    }
  }
  if (J_f_xb) {
    J_f_xb->setZero(nc, dims().nb);
    J_f_xb->block<9, 6>(0, kGyroBias) = Jb.leftCols<6>();  // b_g then b_a
    J_f_xb->block<9, 6>(0, kGyroScale) = Jb.rightCols<6>();  // s_g then s_a
  }
  Eigen::VectorXd out(nc);
  out.head<kStates>() << so3::Log(next.R), next.v, next.p, xc[kClock] + dt;
  if (gyroBiasWalks()) out.tail<3>() = xc.segment<3>(kGyroWalk);
  return out;
}

Eigen::VectorXd StrapdownIns::step(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                                   const Eigen::Ref<const Eigen::VectorXd>& u, double dt, Eigen::MatrixXd* J_f_xc,
                                   Eigen::MatrixXd* J_f_xb) const {
  strapdown::NavState x;
  x.R = so3::Exp(xc.head<3>());
  x.v = xc.segment<3>(3);
  x.p = xc.segment<3>(6);
  strapdown::StepJacobians J;
  // A reading is (1 + s)∘(true) + b: to first order true = reading − b − s∘reading.
  const Eigen::Vector3d gyro = u.head<3>(), accel = u.tail<3>();
  const Eigen::Vector3d gyro_c = gyro - xb.segment<3>(kGyroScale).cwiseProduct(gyro);
  const Eigen::Vector3d accel_c = accel - xb.segment<3>(kAccelScale).cwiseProduct(accel);
  const bool jac = J_f_xc || J_f_xb;
  const strapdown::NavState next = strapdown::step(x, gyro_c, accel_c, gyroBias(xc, xb), xb.segment<3>(kAccelBias),
                                                   dt, frame_, jac ? &J : nullptr);
  Eigen::Matrix<double, 9, 12> jb;  // b_g, b_a, s_g, s_a
  if (jac) jb << J.J_next_bg, J.J_next_ba, J.J_next_bg * gyro.asDiagonal(), J.J_next_ba * accel.asDiagonal();
  return stepResult(xc, next, dt, J.J_next_x, jb, J_f_xc, J_f_xb);
}

Eigen::VectorXd StrapdownIns::h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                                Eigen::MatrixXd* J_h_xb) const {
  return antenna(xc, xb, J_h_xc, J_h_xb);
}

Eigen::VectorXd StrapdownIns::h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                                Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  this->channel(channel);  // range check: throws, naming the channels
  if (channel == kGnss) return antenna(xc, xb, J_h_xc, J_h_xb);
  if (channel == kNhc && this->channel(kNhc).regressors == 0)
    return vehicleVelocity(xc, xb, Eigen::VectorXd(), J_h_xc, J_h_xb);
  if (channel == kNhc)
    throw InvalidArgument("StrapdownIns: channel 'nhc' holds at points off the IMU or with the body's give ([prior] "
                          "nhc_point, nhc_compliance): it reads the IMU's mean reading there, evaluate it by hWith");
  if (channel == kZaru) return restingGyro(xc, xb, J_h_xc, J_h_xb);
  if (channel == kGnssVelocity)
    throw InvalidArgument("StrapdownIns: channel 'gnss_vel' reads the IMU's reading at the fix: evaluate it by hWith");
  if (J_h_xc) {
    J_h_xc->setZero(3, dims().nc);
    J_h_xc->middleCols<3>(3).setIdentity();
  }
  if (J_h_xb) J_h_xb->setZero(3, dims().nb);
  return xc.segment<3>(3);
}

// The antenna at the GNSS time of the fix: the state at IMU time t is the
// true time t + δ, δ = d + ρ·c the IMU's delay then (d = imu_delay at the
// start, ρ = clock_rate, c = the state's clock, the time since the start),
// so to first order y = p + R·ℓ − δ·v (ℓ in the IMU's axes):
// ∂y/∂δθ = −R·[ℓ]×, ∂y/∂v = −δ·I, ∂y/∂c = −ρ·v, ∂y/∂ℓ = R, ∂y/∂d = −v,
// ∂y/∂ρ = −c·v.
Eigen::VectorXd StrapdownIns::antenna(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                                      Eigen::MatrixXd* J_h_xb) const {
  const Eigen::Matrix3d R = so3::Exp(xc.head<3>());
  const Eigen::Vector3d v = xc.segment<3>(3), w = xb.segment<3>(kLever);
  const double delay = xb[kDelay] + xb[kClockRate] * xc[kClock];
  if (J_h_xc) {
    J_h_xc->setZero(3, dims().nc);
    J_h_xc->leftCols<3>() = -R * hat(w);
    J_h_xc->middleCols<3>(3).diagonal().setConstant(-delay);
    J_h_xc->middleCols<3>(6).setIdentity();
    J_h_xc->col(kClock) = -xb[kClockRate] * v;
  }
  if (J_h_xb) {
    J_h_xb->setZero(3, dims().nb);
    J_h_xb->middleCols<3>(kLever) = R;
    J_h_xb->col(kDelay) = -v;
    J_h_xb->col(kClockRate) = -xc[kClock] * v;
  }
  return xc.segment<3>(6) + R * w - delay * v;
}

// The constraints' points (side f, d; vertical f, r) at the constants x_b.
Eigen::Vector4d StrapdownIns::nhcPoint(const Eigen::VectorXd& xb) const {
  Eigen::Vector4d r = p_.nhc_point;
  for (int i = 0; i < 4; ++i)
    if (nhcPointIndex(i) >= 0) r[i] = xb[nhcPointIndex(i)];
  return r;
}

// The vehicle's velocity w = R_vb·Rᵀ·v at the IMU, its right and down
// parts: with u = Rᵀv, ∂w/∂δθ = R_vb·[u]×, ∂w/∂v = R_vb·Rᵀ, ∂w/∂μ =
// −R_vb·[u]×·E; with the body's give, in axes turned by it
// (addCompliance); at points off the IMU, the body's turn there added
// (addTurnAtPoints). reading: the IMU's mean reading at the constraint
// (gyro, then accelerometer; as many as the channel reads).
Eigen::VectorXd StrapdownIns::vehicleVelocity(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                                              const Eigen::VectorXd& reading, Eigen::MatrixXd* J_h_xc,
                                              Eigen::MatrixXd* J_h_xb) const {
  const Eigen::Matrix3d R = so3::Exp(xc.head<3>());
  Eigen::Matrix3d E;
  const Eigen::Matrix3d M = mounting(xb, &E);
  const Eigen::Vector3d u = R.transpose() * xc.segment<3>(3), w = M * u;
  Eigen::Vector2d out = w.tail<2>();
  if (J_h_xc) {
    J_h_xc->setZero(2, dims().nc);
    J_h_xc->leftCols<3>() = (M * hat(u)).bottomRows<2>();
    J_h_xc->middleCols<3>(3) = (M * R.transpose()).bottomRows<2>();
  }
  if (J_h_xb) {
    J_h_xb->setZero(2, dims().nb);
    J_h_xb->middleCols<3>(kMount) = (-M * hat(u) * E).bottomRows<2>();
  }
  if (nhcCompliant()) addCompliance(R, xb, reading.segment<3>(3), u, M, E, out, J_h_xc, J_h_xb);
  if (nhcPointsOffImu()) addTurnAtPoints(xc, xb, reading.head<3>(), M, E, out, J_h_xc, J_h_xb);
  return out;
}

// The body's give (Params::nhc_compliance): the constraints hold in axes
// turned by k_s·F_r about down and k_v·F_f about right, F = R_vb·f the
// specific force in vehicle axes (f = (1 − s_a)∘f̃ − b_a), so sideways
// k_s·F_r·w_f and vertically k_v·F_f·w_f are added (to first order in the
// small angles). ∂F/∂μ = −R_vb·[f]×·E, ∂F/∂b_a = −R_vb,
// ∂F/∂s_a = −R_vb·diag(f̃); w_f = (R_vb·u)_x as in vehicleVelocity (R:
// the attitude).
void StrapdownIns::addCompliance(const Eigen::Matrix3d& R, const Eigen::VectorXd& xb, const Eigen::Vector3d& accel,
                                 const Eigen::Vector3d& u, const Eigen::Matrix3d& M, const Eigen::Matrix3d& E,
                                 Eigen::Vector2d& out, Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  const Eigen::Vector3d f = accel - xb.segment<3>(kAccelScale).cwiseProduct(accel) - xb.segment<3>(kAccelBias);
  const Eigen::Vector3d F = M * f;
  const Eigen::Vector2d k = nhcCompliance(xb);
  const double w_f = M.row(0).dot(u);
  const Eigen::Vector2d J_out_wf(k[0] * F.y(), k[1] * F.x());
  out += J_out_wf * w_f;
  if (J_h_xc) {
    J_h_xc->leftCols<3>() += J_out_wf * (M * hat(u)).row(0);
    J_h_xc->middleCols<3>(3) += J_out_wf * (M * R.transpose()).row(0);
  }
  if (!J_h_xb) return;
  J_h_xb->middleCols<3>(kMount) -= J_out_wf * (M * hat(u) * E).row(0);
  Eigen::Matrix<double, 2, 3> J_out_F;
  J_out_F << 0, k[0] * w_f, 0, k[1] * w_f, 0, 0;
  J_h_xb->middleCols<3>(kMount) -= J_out_F * M * hat(f) * E;
  J_h_xb->middleCols<3>(kAccelBias) = -J_out_F * M;
  J_h_xb->middleCols<3>(kAccelScale) = -J_out_F * M * accel.asDiagonal();
  if (nhcComplianceIndex(0) >= 0) J_h_xb->col(nhcComplianceIndex(0)) = Eigen::Vector2d(F.y() * w_f, 0);
  if (nhcComplianceIndex(1) >= 0) J_h_xb->col(nhcComplianceIndex(1)) = Eigen::Vector2d(0, F.x() * w_f);
}

Eigen::Vector2d StrapdownIns::nhcCompliance(const Eigen::VectorXd& xb) const {
  Eigen::Vector2d k = p_.nhc_compliance;
  for (int i = 0; i < 2; ++i)
    if (nhcComplianceIndex(i) >= 0) k[i] = xb[nhcComplianceIndex(i)];
  return k;
}

// Ω×r at a point r from the IMU in vehicle axes, Ω = R_vb·ω the body's rate
// (ω = (1 − s_g)∘ω̃ − b_g): sideways, r = (f, 0, d), Ω_z·f − Ω_x·d;
// vertical, r = (f, r, 0), Ω_x·r − Ω_y·f. ∂Ω/∂μ = −R_vb·[ω]×·E,
// ∂Ω/∂b_g = ∂Ω/∂β_g = −R_vb, ∂Ω/∂s_g = −R_vb·diag(ω̃).
void StrapdownIns::addTurnAtPoints(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::Vector3d& gyro,
                                   const Eigen::Matrix3d& M, const Eigen::Matrix3d& E, Eigen::Vector2d& out,
                                   Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  const Eigen::Vector3d omega = gyro - xb.segment<3>(kGyroScale).cwiseProduct(gyro) - gyroBias(xc, xb);
  const Eigen::Vector3d W = M * omega;
  const Eigen::Vector4d r = nhcPoint(xb);
  Eigen::Matrix<double, 2, 3> J_out_W;  // ∂(Ω×r)/∂Ω, its sideways and vertical rows
  J_out_W << -r[1], 0, r[0], r[3], -r[2], 0;
  out += J_out_W * W;
  if (J_h_xc && gyroBiasWalks()) J_h_xc->middleCols<3>(kGyroWalk) = -J_out_W * M;
  if (!J_h_xb) return;
  J_h_xb->middleCols<3>(kMount) -= J_out_W * M * hat(omega) * E;
  J_h_xb->middleCols<3>(kGyroBias) = -J_out_W * M;
  J_h_xb->middleCols<3>(kGyroScale) = -J_out_W * M * gyro.asDiagonal();
  Eigen::Matrix<double, 2, 4> J_out_r;  // ∂(Ω×r)/∂(f, d, f, r)
  J_out_r << W.z(), -W.x(), 0, 0, 0, 0, -W.y(), W.x();
  for (int i = 0; i < 4; ++i)
    if (nhcPointIndex(i) >= 0) J_h_xb->col(nhcPointIndex(i)) = J_out_r.col(i);
}

// What the gyro reads while the car stands: its bias and the Earth's rate in
// the IMU's axes (the scale factor's part of it, 1e-7 rad/s, left out):
// y = b_g (+ β_g) + Rᵀ·ω_ie; ∂y/∂δθ = [Rᵀ·ω_ie]×, ∂y/∂b_g = ∂y/∂β_g = I.
Eigen::VectorXd StrapdownIns::restingGyro(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                                          Eigen::MatrixXd* J_h_xb) const {
  const Eigen::Vector3d w = so3::Exp(xc.head<3>()).transpose() * frame_.earthRate();
  if (J_h_xc) {
    J_h_xc->setZero(3, dims().nc);
    J_h_xc->leftCols<3>() = hat(w);
    if (gyroBiasWalks()) J_h_xc->middleCols<3>(kGyroWalk).setIdentity();
  }
  if (J_h_xb) {
    J_h_xb->setZero(3, dims().nb);
    J_h_xb->middleCols<3>(kGyroBias).setIdentity();
  }
  return gyroBias(xc, xb) + w;
}

// The antenna's velocity at the GNSS time of the fix, given the IMU's mean
// rates ω̃ there and the velocity's rate of change a (NED, from the fixes'
// own velocities: data, so that the delay's term does not tie the attitude
// to gravity through R·f + g): with ω = (1 − s_g)∘ω̃ − b_g the antenna turns
// about the IMU at R·(ω×ℓ), and the state at IMU time t is the true time
// t + δ, so y = v + R·(ω×ℓ) − δ·a (a velocity that lags its fix by
// τ = gnss_vel_latency: δ + τ for δ). ∂y/∂δθ = −R·[ω×ℓ]×, ∂y/∂v = I,
// ∂y/∂c = −ρ·a, ∂y/∂b_g = R·[ℓ]×, ∂y/∂s_g = R·[ℓ]×·diag(ω̃), ∂y/∂ℓ = R·[ω]×,
// ∂y/∂d = −a, ∂y/∂ρ = −c·a.
void StrapdownIns::hRegressedInto(int channel, const Eigen::VectorXd& regressors, const Eigen::VectorXd& xc,
                                  const Eigen::VectorXd& xb, Eigen::VectorXd& out, Eigen::MatrixXd* J_h_xc,
                                  Eigen::MatrixXd* J_h_xb) const {
  if (channel == kNhc && this->channel(kNhc).regressors > 0) {
    out = vehicleVelocity(xc, xb, regressors, J_h_xc, J_h_xb);
    return;
  }
  if (channel != kGnssVelocity) return Model::hRegressedInto(channel, regressors, xc, xb, out, J_h_xc, J_h_xb);
  const Eigen::Vector3d gyro = regressors.head<3>(), a = regressors.tail<3>();
  const Eigen::Vector3d w = gyro - xb.segment<3>(kGyroScale).cwiseProduct(gyro) - gyroBias(xc, xb);
  const Eigen::Matrix3d R = so3::Exp(xc.head<3>());
  const Eigen::Vector3d lever = xb.segment<3>(kLever), turn = w.cross(lever);
  const double delay = xb[kDelay] + xb[kClockRate] * xc[kClock] + p_.gnss_vel_latency;
  out = xc.segment<3>(3) + R * turn - delay * a;
  if (J_h_xc) {
    J_h_xc->setZero(3, dims().nc);
    J_h_xc->leftCols<3>() = -R * hat(turn);
    J_h_xc->middleCols<3>(3).setIdentity();
    J_h_xc->col(kClock) = -xb[kClockRate] * a;
    if (gyroBiasWalks()) J_h_xc->middleCols<3>(kGyroWalk) = R * hat(lever);
  }
  if (J_h_xb) {
    J_h_xb->setZero(3, dims().nb);
    J_h_xb->middleCols<3>(kGyroBias) = R * hat(lever);
    J_h_xb->middleCols<3>(kLever) = R * hat(w);
    J_h_xb->col(kDelay) = -a;
    J_h_xb->middleCols<3>(kGyroScale) = R * hat(lever) * gyro.asDiagonal();
    J_h_xb->col(kClockRate) = -xc[kClock] * a;
  }
}

Eigen::MatrixXd StrapdownIns::processNoise(double dt) const { return insProcessNoise(p_, dt); }

}  // namespace gssm::models

namespace gssm::models {

namespace {
constexpr double kDeg = M_PI / 180;

std::vector<ParamSpec> insParams() {
  using namespace param;
  std::vector<ParamSpec> p{
      real("model", "T", "nominal IMU interval (s)"),
      real("model", "imu_per_state",
           "IMU readings per state (1: a state at every sample; N: a state every N samples and at every "
           "measurement, the readings between integrated in turn)"),
      required(any("model", "anchor",
                   "the NED frame's origin: latitude, longitude (deg), ellipsoidal height (m), or first_fix: the "
                   "first fix of [dataset] gnss (an RTKLIB .pos, default gnss.pos)")),
      vector("model", "mount_rpy", "nominal IMU → vehicle rotation as roll, pitch, yaw (deg; vehicle axes forward, right, down)"),
      learnable(vector("model", "gyro_sd",
                       "gyro white noise, rad/s/√Hz: one σ for every axis, or three, one per IMU axis (x, y, z)")),
      learnable(real("model", "accel_sd", "accelerometer white noise, m/s²/√Hz")),
      learnable(real("model", "gnss_sd", "σ of each GNSS coordinate when a fix gives none (m)")),
      learnable(real("model", "gnss_sd_scale", "factor on the σs each GNSS fix reports (1: as reported)")),
      learnable(real("model", "gnss_vel_sd",
                     "σ of each GNSS velocity component when a fix gives none (m/s; [dataset] gnss_velocity_channel)")),
      learnable(real("model", "gnss_vel_sd_scale", "factor on the velocity σs each GNSS fix reports (1: as reported)")),
      learnable(real("model", "gnss_vel_latency",
                     "how long each fix's velocity lags its time (s; a receiver's filtered or averaged Doppler "
                     "velocity; 0: instantaneous)")),
      learnable(real("model", "nhc_sd", "σ of the vehicle's sideways velocity at the IMU (m/s)")),
      learnable(real("model", "nhc_down_sd",
                     "σ of its vertical velocity (m/s; with one σ for both the constraint is blind to the mounting's "
                     "roll, which turns one into the other)")),
      learnable(real("model", "zupt_sd", "σ of the velocity while standing (m/s)")),
      learnable(real("model", "zaru_sd", "σ of the gyro's mean reading while standing (rad/s)")),
      any("prior", "start",
          "data: the start's attitude, velocity and position from the log (roll and pitch from the specific "
          "force, yaw from the GNSS track; [dataset] inputs, input_columns, gnss, start_time), instead of "
          "start_rpy, start_velocity and start_position"),
      vector("prior", "start_rpy", "prior mean of the IMU's roll, pitch, yaw (deg)"),
      vector("prior", "start_velocity", "prior mean of v(0), NED (m/s)"),
      vector("prior", "start_position", "prior mean of p(0), NED (m)"),
      real("prior", "attitude_sd", "prior σ of the attitude (deg)"),
      real("prior", "heading_sd",
           "a further prior σ of the start attitude about the vertical (deg, default 0; with start = data the "
           "track's heading holds the IMU's only through the mounting: mount_sd accounts for that)"),
      real("prior", "velocity_sd", "prior σ of v(0) (m/s)"),
      real("prior", "position_sd", "prior σ of p(0) (m)"),
      vector("prior", "gyro_bias", "prior mean of the gyro bias, IMU axes (rad/s; default 0: a calibration)"),
      real("prior", "gyro_bias_sd", "prior σ of the gyro bias (rad/s)"),
      vector("prior", "accel_bias", "prior mean of the accelerometer bias, IMU axes (m/s²; default 0)"),
      real("prior", "accel_bias_sd", "prior σ of the accelerometer bias (m/s²)"),
      vector("prior", "lever", "prior mean of the lever arm IMU → antenna, vehicle axes (m)"),
      real("prior", "lever_sd", "its σ (m)"),
      real("prior", "mount_sd", "prior σ of the mounting misalignment (deg), mean 0"),
      real("prior", "delay", "prior mean of the IMU's time delay at the start (s, added to its stamps; default 0)"),
      real("prior", "delay_sd", "prior σ of the IMU's time delay at the start (s)"),
      real("prior", "clock_rate", "prior mean of the IMU clock's rate error (s/s: the delay grows by it; default 0)"),
      real("prior", "clock_rate_sd", "prior σ of the IMU clock's rate error (s/s)"),
      real("model", "clock_wander_sd", "the IMU clock's wander beyond its constant rate (s/√s)"),
      learnable(real("model", "gyro_bias_walk",
                     "the gyro bias's random walk beyond its constant part (rad/s/√s; 0: a constant bias)")),
      vector("prior", "gyro_scale", "prior mean of each gyro axis's scale factor error (1 = 100 %; default 0)"),
      real("prior", "gyro_scale_sd", "prior σ of each gyro axis's scale factor error (1 = 100 %)"),
      vector("prior", "accel_scale", "prior mean of each accelerometer axis's scale factor error (default 0)"),
      real("prior", "accel_scale_sd", "prior σ of each accelerometer axis's scale factor error"),
      vector("prior", "nhc_point",
             "where the vehicle constraints hold, from the IMU in vehicle axes (m): the sideways one's point "
             "forward and down, the vertical one's forward and right (default 0 0 0 0: at the IMU)"),
      vector("prior", "nhc_point_sd",
             "their prior σs (m): each > 0 is a constant node, learnt with the others; 0 holds it at its mean"),
      vector("prior", "nhc_compliance",
             "the body's give on its tyres and springs (rad per m/s²): the constraints' axes turn from the body's by "
             "k_s·(lateral specific force) about down, a slip angle, and by k_v·(forward specific force) about "
             "right, a pitch on the springs; k_s k_v (default 0 0: none)"),
      vector("prior", "nhc_compliance_sd",
             "their prior σs (rad per m/s²): each > 0 is a constant node; 0 holds it at its mean")};
  for (auto& l : lossParams("model", "nhc_", "the vehicle constraints (nhc: a bump or a skid breaks them)"))
    p.push_back(l);
  p.push_back(param::real("model", "nhc_ekf_gate",
                          "the EKF (no loss) rejects a constraint whose NIS exceeds this (2 dof; 0: no gate)"));
  return p;
}

// [model] anchor: "lat lon height", or first_fix (of the log's GNSS file:
// the same scenario.ini then serves any log of the data set).
geodesy::Geodetic readAnchor(const ParamSource& in) {
  Eigen::VectorXd a;
  bool first_fix = false;
  try {  // a word, or numbers (a keyword source holding numbers has no text)
    first_fix = in.text("model", "anchor") == "first_fix";
  } catch (const InvalidArgument&) {
  }
  if (first_fix) {
    const Eigen::MatrixXd fixes = in.dataFile(in.text("dataset", "gnss", "gnss.pos"), {"lat", "lon", "height"});
    if (fixes.rows() == 0) throw InputError(in.where("model", "anchor") + " = first_fix: the GNSS file has no fix");
    a = fixes.row(0).transpose();
  } else {
    a = in.vector("model", "anchor", 3);
  }
  return {a[0] * kDeg, a[1] * kDeg, a[2]};
}

std::vector<std::string> splitWords(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// The IMU rows of [dataset] inputs from t0 on, and t0 ([dataset] start_time:
// a number or first_input).
std::vector<Input> startImu(const ParamSource& in, double& t0) {
  std::vector<std::string> cols{"t"};
  for (const auto& c : splitWords(in.text("dataset", "input_columns"))) cols.push_back(c);
  if (cols.size() != 7)
    throw InputError(in.where("dataset", "input_columns") + ": expected 6 columns (gyro x y z, accelerometer x y z)");
  const Eigen::MatrixXd imu = in.dataFile(in.text("dataset", "inputs"), cols);
  if (imu.rows() == 0) throw InputError(in.where("prior", "start") + " = data: the IMU file has no row");
  t0 = in.text("dataset", "start_time", "0") == "first_input" ? imu(0, 0) : in.real("dataset", "start_time");
  std::vector<Input> out;
  for (Eigen::Index r = 0; r < imu.rows(); ++r)
    if (imu(r, 0) >= t0) out.push_back({imu(r, 0), imu.row(r).tail<6>().transpose()});
  return out;
}

// [prior] start = data: the start from the log (ins_start.h), from the
// fixes the estimators see (after t0, of an accepted quality, outside the
// outages), the position that of the IMU (the antenna's less the prior lever).
void startFromData(const ParamSource& in, StrapdownIns::Params& p) {
  double t0 = 0;
  std::vector<Input> imu = startImu(in, t0);
  for (Input& r : imu) {  // the readings as the calibration of the prior means has them (f's correction)
    r.u.head<3>() -= p.gyro_scale.cwiseProduct(r.u.head<3>()) + p.gyro_bias;
    r.u.tail<3>() -= p.accel_scale.cwiseProduct(r.u.tail<3>()) + p.accel_bias;
  }
  const Eigen::MatrixXd fixes = in.dataFile(in.text("dataset", "gnss", "gnss.pos"), {"t", "lat", "lon", "height", "q"});
  Eigen::MatrixXd outages(0, 2);
  if (in.has("dataset", "gnss_outages") && in.hasDataFile(in.text("dataset", "gnss_outages")))  // none: none withheld
    outages = in.dataFile(in.text("dataset", "gnss_outages"), {"start", "end"});
  const double max_quality = in.real("dataset", "gnss_max_quality", 1);
  const strapdown::NavFrame frame(p.anchor);
  std::vector<double> ft;
  std::vector<Eigen::Vector3d> fp;
  for (Eigen::Index r = 0; r < fixes.rows(); ++r) {
    const double t = fixes(r, 0);
    bool withheld = false;
    for (Eigen::Index o = 0; o < outages.rows(); ++o) withheld |= t >= outages(o, 0) && t < outages(o, 1);
    if (t <= t0 || withheld || fixes(r, 4) > max_quality) continue;
    ft.push_back(t);
    fp.push_back(frame.local().toNed({fixes(r, 1) * kDeg, fixes(r, 2) * kDeg, fixes(r, 3)}));
  }
  const Eigen::Matrix3d R_vb0 = so3::fromRollPitchYaw(p.mount_rpy);
  const InsStart s = insStart(t0, imu, ft, fp, R_vb0, frame);
  p.start_rpy = so3::rollPitchYaw(s.R_nb);
  p.start_velocity = s.velocity;
  p.start_position = s.position - s.R_nb * R_vb0.transpose() * p.lever;
}

// The keys read and written as they are, one table for both directions
// (P: Params, or const Params to write); the angles, read in degrees, and
// T are apart.
template <class P>
auto modelReals(P& p) {
  return std::array{std::pair{"accel_sd", &p.accel_sd},
                    std::pair{"gnss_sd", &p.gnss_sd}, std::pair{"gnss_sd_scale", &p.gnss_sd_scale},
                    std::pair{"gnss_vel_sd", &p.gnss_vel_sd}, std::pair{"gnss_vel_sd_scale", &p.gnss_vel_sd_scale},
                    std::pair{"gnss_vel_latency", &p.gnss_vel_latency}, std::pair{"nhc_sd", &p.nhc_sd},
                    std::pair{"nhc_down_sd", &p.nhc_down_sd}, std::pair{"zupt_sd", &p.zupt_sd},
                    std::pair{"zaru_sd", &p.zaru_sd}, std::pair{"clock_wander_sd", &p.clock_wander_sd},
                    std::pair{"gyro_bias_walk", &p.gyro_bias_walk}, std::pair{"nhc_ekf_gate", &p.nhc_ekf_gate}};
}

// The calibration's prior means in [prior], 3 values each.
template <class P>
auto calibrationPriors(P& p) {
  return std::array{std::pair{"lever", &p.lever}, std::pair{"gyro_bias", &p.gyro_bias},
                    std::pair{"accel_bias", &p.accel_bias}, std::pair{"gyro_scale", &p.gyro_scale},
                    std::pair{"accel_scale", &p.accel_scale}};
}

// The prior's angular σs, in degrees in the INI.
template <class P>
auto angleSds(P& p) {
  return std::array{std::pair{"attitude_sd", &p.attitude_sd}, std::pair{"heading_sd", &p.start_heading_sd},
                    std::pair{"mount_sd", &p.mount_sd}};
}

// The prior's other σs, in their own units.
template <class P>
auto priorSds(P& p) {
  return std::array{std::pair{"velocity_sd", &p.velocity_sd}, std::pair{"position_sd", &p.position_sd},
                    std::pair{"gyro_bias_sd", &p.gyro_bias_sd}, std::pair{"accel_bias_sd", &p.accel_bias_sd},
                    std::pair{"lever_sd", &p.lever_sd}, std::pair{"delay_sd", &p.delay_sd},
                    std::pair{"gyro_scale_sd", &p.gyro_scale_sd}, std::pair{"accel_scale_sd", &p.accel_scale_sd},
                    std::pair{"clock_rate_sd", &p.clock_rate_sd}};
}

StrapdownIns::Params readIns(const ParamSource& in) {
  StrapdownIns::Params p;
  p.anchor = readAnchor(in);
  if (in.has("model", "mount_rpy")) p.mount_rpy = in.vector("model", "mount_rpy", 3) * kDeg;
  p.T = in.real("model", "T", p.T);
  for (auto [key, value] : modelReals(p)) *value = in.real("model", key, *value);
  if (in.has("model", "gyro_sd")) p.gyro_sd = in.vector("model", "gyro_sd");
  if (p.gyro_sd.size() != 1 && p.gyro_sd.size() != 3)
    throw InputError(in.where("model", "gyro_sd") + ": expected one σ (every axis) or three (the IMU's x, y, z), got " +
                     std::to_string(p.gyro_sd.size()));
  for (auto [key, value] : calibrationPriors(p))
    if (in.has("prior", key)) *value = in.vector("prior", key, 3);
  for (auto [key, value] : {std::pair{"nhc_point", &p.nhc_point}, {"nhc_point_sd", &p.nhc_point_sd}})
    if (in.has("prior", key)) *value = in.vector("prior", key, 4);
  for (auto [key, value] : {std::pair{"nhc_compliance", &p.nhc_compliance}, {"nhc_compliance_sd", &p.nhc_compliance_sd}})
    if (in.has("prior", key)) *value = in.vector("prior", key, 2);
  p.delay = in.real("prior", "delay", p.delay);
  p.clock_rate = in.real("prior", "clock_rate", p.clock_rate);
  p.nhc_loss = readLoss(in, "model", "nhc_");
  const double per_state = in.real("model", "imu_per_state", 1);
  if (!(per_state >= 1 && per_state <= 1000 && per_state == std::floor(per_state)))
    throw InputError(in.where("model", "imu_per_state") + " = " + std::to_string(per_state) +
                     ": expected a whole number of IMU readings, 1..1000");
  p.imu_per_state = static_cast<int>(per_state);
  const bool from_data = in.has("prior", "start") && in.text("prior", "start") == "data";
  if (in.has("prior", "start") && !from_data)
    throw InputError(in.where("prior", "start") + " = '" + in.text("prior", "start") + "': expected data");
  for (const char* key : {"start_rpy", "start_velocity", "start_position"})
    if (from_data && in.has("prior", key))
      throw InputError(in.where("prior", key) + ": given with start = data (one or the other)");
  if (from_data) startFromData(in, p);
  if (in.has("prior", "start_rpy")) p.start_rpy = in.vector("prior", "start_rpy", 3) * kDeg;
  if (in.has("prior", "start_velocity")) p.start_velocity = in.vector("prior", "start_velocity", 3);
  if (in.has("prior", "start_position")) p.start_position = in.vector("prior", "start_position", 3);
  for (auto [key, value] : angleSds(p)) *value = in.real("prior", key, *value / kDeg) * kDeg;
  for (auto [key, value] : priorSds(p)) *value = in.real("prior", key, *value);
  return p;
}

void writeIns(const StrapdownIns::Params& p, ParamSink& out) {
  out.real("model", "T", p.T);
  out.real("model", "imu_per_state", p.imu_per_state);
  out.vector("model", "anchor", Eigen::Vector3d(p.anchor.lat / kDeg, p.anchor.lon / kDeg, p.anchor.height));
  out.vector("model", "mount_rpy", p.mount_rpy / kDeg);
  for (auto [key, value] : modelReals(p)) out.real("model", key, *value);
  out.vector("model", "gyro_sd", p.gyro_sd);
  writeLoss(p.nhc_loss, "model", out, "nhc_");
  out.vector("prior", "start_rpy", p.start_rpy / kDeg);
  out.vector("prior", "start_velocity", p.start_velocity);
  out.vector("prior", "start_position", p.start_position);
  for (auto [key, value] : calibrationPriors(p)) out.vector("prior", key, *value);
  out.vector("prior", "nhc_point", p.nhc_point);
  out.vector("prior", "nhc_point_sd", p.nhc_point_sd);
  out.vector("prior", "nhc_compliance", p.nhc_compliance);
  out.vector("prior", "nhc_compliance_sd", p.nhc_compliance_sd);
  out.real("prior", "delay", p.delay);
  out.real("prior", "clock_rate", p.clock_rate);
  for (auto [key, value] : angleSds(p)) out.real("prior", key, *value / kDeg);
  for (auto [key, value] : priorSds(p)) out.real("prior", key, *value);
}

const ModelRegistration strapdown_ins_registration{{
    "strapdown_ins", {}, "StrapdownIns",
    "Strapdown GNSS/INS: IMU inputs, attitude on SO(3), velocity and position in an Earth-fixed NED frame; gyro "
    "and accelerometer biases, lever arm and mounting as constants; GNSS, non-holonomic and zero-velocity channels.",
    insParams(),
    [](const ParamSource& in) -> std::unique_ptr<Model> { return std::make_unique<StrapdownIns>(readIns(in)); },
    [](const Model& m, ParamSink& out) { writeIns(dynamic_cast<const StrapdownIns&>(m).params(), out); },
    [](const Model& m) { return dynamic_cast<const StrapdownIns*>(&m) != nullptr; },
    [](ParamSink& out) { writeIns(StrapdownIns::Params{}, out); }}};
}  // namespace

}  // namespace gssm::models
