#include "gssm/models/strapdown_ins.h"

#include <cmath>

#include "gssm/core/error.h"
#include "gssm/core/so3.h"
#include "gssm/model/registry.h"

namespace gssm::models {

namespace {
using so3::hat;

ModelNames insNames() {
  ModelNames n;
  n.state = {"att_x", "att_y", "att_z", "vn", "ve", "vd", "pn", "pe", "pd"};
  n.constants = {"bg_x", "bg_y", "bg_z", "ba_x", "ba_y", "ba_z", "lever_f", "lever_r", "lever_d",
                 "mount_x", "mount_y", "mount_z", "imu_delay"};
  n.input = {"gx", "gy", "gz", "ax", "ay", "az"};
  n.measurement = {"gnss_n", "gnss_e", "gnss_d"};
  return n;
}

// θ: the gyro's white noise in the body tangent; (v, p): white acceleration,
// σ_a²·[[dt, dt²/2], [dt²/2, dt³/3]] on each axis (isotropic: R·σ²I·Rᵀ = σ²I).
Eigen::MatrixXd insProcessNoise(const StrapdownIns::Params& p, double dt) {
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(9, 9);
  const double g = p.gyro_sd * p.gyro_sd, a = p.accel_sd * p.accel_sd;
  for (int i = 0; i < 3; ++i) {
    Q(i, i) = g * dt;
    Q(3 + i, 3 + i) = a * dt;
    Q(3 + i, 6 + i) = Q(6 + i, 3 + i) = a * dt * dt / 2;
    Q(6 + i, 6 + i) = a * dt * dt * dt / 3;
  }
  return Q;
}

ModelNoise insNoise(const StrapdownIns::Params& p) {
  for (double v : {p.T, p.gyro_sd, p.accel_sd, p.gnss_sd, p.nhc_sd, p.zupt_sd, p.attitude_sd, p.velocity_sd,
                   p.position_sd, p.gyro_bias_sd, p.accel_bias_sd, p.lever_sd, p.mount_sd, p.delay_sd})
    if (!(v > 0) || !std::isfinite(v)) throw InvalidArgument("StrapdownIns: every σ and T must be > 0");
  ModelNoise n;
  n.T = p.T;
  n.Q = insProcessNoise(p, p.T);
  n.R = Eigen::Matrix3d::Identity() * p.gnss_sd * p.gnss_sd;
  Eigen::VectorXd mean(9), sd(9);
  mean << so3::Log(so3::fromRollPitchYaw(p.start_rpy)), p.start_velocity, p.start_position;
  sd << Eigen::Vector3d::Constant(p.attitude_sd), Eigen::Vector3d::Constant(p.velocity_sd),
      Eigen::Vector3d::Constant(p.position_sd);
  n.prior_state = {mean, Eigen::MatrixXd(sd.cwiseAbs2().asDiagonal())};
  Eigen::VectorXd bmean = Eigen::VectorXd::Zero(StrapdownIns::kConstants), bsd(StrapdownIns::kConstants);
  bmean.segment<3>(StrapdownIns::kLever) = p.lever;
  bsd << Eigen::Vector3d::Constant(p.gyro_bias_sd), Eigen::Vector3d::Constant(p.accel_bias_sd),
      Eigen::Vector3d::Constant(p.lever_sd), Eigen::Vector3d::Constant(p.mount_sd), p.delay_sd;
  n.prior_constants = {bmean, Eigen::MatrixXd(bsd.cwiseAbs2().asDiagonal())};
  return n;
}

MeasurementChannel channelOf(const std::string& name, std::vector<std::string> components, double sd,
                             std::vector<int> constants) {
  MeasurementChannel c;
  c.name = name;
  c.R = Eigen::MatrixXd::Identity(static_cast<Eigen::Index>(components.size()),
                                  static_cast<Eigen::Index>(components.size())) * sd * sd;
  c.components = std::move(components);
  c.constants = std::move(constants);
  return c;
}
}  // namespace

StrapdownIns::StrapdownIns(const Params& p)
    : Model({9, kConstants, 6, 3}, insNames(), insNoise(p)),
      p_(p),
      frame_(p.anchor),
      mount0_(so3::fromRollPitchYaw(p.mount_rpy)) {
  setChannels({channelOf("gnss", {"gnss_n", "gnss_e", "gnss_d"}, p.gnss_sd, {6, 7, 8, 9, 10, 11, kDelay}),
               channelOf("nhc", {"nhc_right", "nhc_down"}, p.nhc_sd, {9, 10, 11}),
               channelOf("zupt", {"zupt_n", "zupt_e", "zupt_d"}, p.zupt_sd, {})});
  setRotationBlocks({0});
}

Eigen::Matrix3d StrapdownIns::mounting(const Eigen::VectorXd& xb) const {
  return so3::Exp(xb.segment<3>(kMount)) * mount0_;
}

Eigen::VectorXd StrapdownIns::f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u,
                                double dt, Eigen::MatrixXd* J_f_xc, Eigen::MatrixXd* J_f_xb) const {
  strapdown::NavState x;
  x.R = so3::Exp(xc.head<3>());
  x.v = xc.segment<3>(3);
  x.p = xc.segment<3>(6);
  strapdown::StepJacobians J;
  const strapdown::NavState next = strapdown::step(x, u.head<3>(), u.tail<3>(), xb.segment<3>(kGyroBias),
                                                   xb.segment<3>(kAccelBias), dt, frame_,
                                                   J_f_xc || J_f_xb ? &J : nullptr);
  if (J_f_xc) *J_f_xc = J.J_next_x;
  if (J_f_xb) {
    J_f_xb->setZero(9, kConstants);
    J_f_xb->middleCols<3>(kGyroBias) = J.J_next_bg;
    J_f_xb->middleCols<3>(kAccelBias) = J.J_next_ba;
  }
  Eigen::VectorXd out(9);
  out << so3::Log(next.R), next.v, next.p;
  return out;
}

Eigen::VectorXd StrapdownIns::h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                                Eigen::MatrixXd* J_h_xb) const {
  return antenna(xc, xb, J_h_xc, J_h_xb);
}

Eigen::VectorXd StrapdownIns::h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                                Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  this->channel(channel);  // range check: throws, naming the channels
  if (channel == kGnss) return antenna(xc, xb, J_h_xc, J_h_xb);
  if (channel == kNhc) return vehicleVelocity(xc, xb, J_h_xc, J_h_xb);
  if (J_h_xc) {
    J_h_xc->setZero(3, 9);
    J_h_xc->middleCols<3>(3).setIdentity();
  }
  if (J_h_xb) J_h_xb->setZero(3, kConstants);
  return xc.segment<3>(3);
}

// The antenna at the GNSS time of the fix: the state at IMU time t is the
// true time t + d (d = imu_delay, added to the IMU's stamps), so to first
// order y = p + R·w − d·v, w = R_vbᵀ·ℓ = R_vb0ᵀ·Exp(−μ)·ℓ: ∂y/∂δθ = −R·[w]×,
// ∂y/∂v = −d·I, ∂y/∂ℓ = R·R_vbᵀ, ∂y/∂μ = R·R_vb0ᵀ·Exp(−μ)·[ℓ]×·Jr(−μ) (from
// ∂(Exp(φ)ℓ)/∂φ = −Exp(φ)[ℓ]×Jr(φ)), ∂y/∂d = −v.
Eigen::VectorXd StrapdownIns::antenna(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                                      Eigen::MatrixXd* J_h_xb) const {
  const Eigen::Matrix3d R = so3::Exp(xc.head<3>());
  const Eigen::Vector3d v = xc.segment<3>(3), mu = xb.segment<3>(kMount), lever = xb.segment<3>(kLever);
  const double delay = xb[kDelay];
  const Eigen::Matrix3d Emu_t = so3::Exp(-mu);
  const Eigen::Vector3d w = mount0_.transpose() * (Emu_t * lever);
  if (J_h_xc) {
    J_h_xc->setZero(3, 9);
    J_h_xc->leftCols<3>() = -R * hat(w);
    J_h_xc->middleCols<3>(3).diagonal().setConstant(-delay);
    J_h_xc->rightCols<3>().setIdentity();
  }
  if (J_h_xb) {
    J_h_xb->setZero(3, kConstants);
    J_h_xb->middleCols<3>(kLever) = R * mount0_.transpose() * Emu_t;
    J_h_xb->middleCols<3>(kMount) = R * mount0_.transpose() * Emu_t * hat(lever) * so3::rightJacobian(-mu);
    J_h_xb->col(kDelay) = -v;
  }
  return xc.segment<3>(6) + R * w - delay * v;
}

// The vehicle's velocity w = R_vb·Rᵀ·v, its right and down parts: with
// u = Rᵀv, ∂/∂δθ = R_vb·[u]×, ∂/∂v = R_vb·Rᵀ, ∂/∂μ = −Exp(μ)·[R_vb0·u]×·Jr(μ).
Eigen::VectorXd StrapdownIns::vehicleVelocity(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                                              Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  const Eigen::Matrix3d R = so3::Exp(xc.head<3>());
  const Eigen::Vector3d mu = xb.segment<3>(kMount);
  const Eigen::Matrix3d Emu = so3::Exp(mu), M = Emu * mount0_;
  const Eigen::Vector3d u = R.transpose() * xc.segment<3>(3);
  const Eigen::Vector3d w = M * u;
  if (J_h_xc) {
    J_h_xc->setZero(2, 9);
    J_h_xc->leftCols<3>() = (M * hat(u)).bottomRows<2>();
    J_h_xc->middleCols<3>(3) = (M * R.transpose()).bottomRows<2>();
  }
  if (J_h_xb) {
    J_h_xb->setZero(2, kConstants);
    J_h_xb->middleCols<3>(kMount) = (-Emu * hat(mount0_ * u) * so3::rightJacobian(mu)).bottomRows<2>();
  }
  return w.tail<2>();
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
      required(any("model", "anchor",
                   "the NED frame's origin: latitude, longitude (deg), ellipsoidal height (m), or first_fix: the "
                   "first fix of [dataset] gnss (an RTKLIB .pos, default gnss.pos)")),
      vector("model", "mount_rpy", "nominal IMU → vehicle rotation as roll, pitch, yaw (deg; vehicle axes forward, right, down)"),
      learnable(real("model", "gyro_sd", "gyro white noise, rad/s/√Hz")),
      learnable(real("model", "accel_sd", "accelerometer white noise, m/s²/√Hz")),
      learnable(real("model", "gnss_sd", "σ of each GNSS coordinate when a fix gives none (m)")),
      learnable(real("model", "nhc_sd", "σ of the vehicle's sideways and vertical velocity (m/s)")),
      learnable(real("model", "zupt_sd", "σ of the velocity while standing (m/s)")),
      vector("prior", "start_rpy", "prior mean of the IMU's roll, pitch, yaw (deg)"),
      vector("prior", "start_velocity", "prior mean of v(0), NED (m/s)"),
      vector("prior", "start_position", "prior mean of p(0), NED (m)"),
      real("prior", "attitude_sd", "prior σ of the attitude (deg)"),
      real("prior", "velocity_sd", "prior σ of v(0) (m/s)"),
      real("prior", "position_sd", "prior σ of p(0) (m)"),
      real("prior", "gyro_bias_sd", "prior σ of the gyro bias (rad/s), mean 0"),
      real("prior", "accel_bias_sd", "prior σ of the accelerometer bias (m/s²), mean 0"),
      vector("prior", "lever", "prior mean of the lever arm IMU → antenna, vehicle axes (m)"),
      real("prior", "lever_sd", "its σ (m)"),
      real("prior", "mount_sd", "prior σ of the mounting misalignment (deg), mean 0"),
      real("prior", "delay_sd", "prior σ of the IMU's time delay (s, added to its stamps), mean 0")};
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

StrapdownIns::Params readIns(const ParamSource& in) {
  StrapdownIns::Params p;
  p.anchor = readAnchor(in);
  if (in.has("model", "mount_rpy")) p.mount_rpy = in.vector("model", "mount_rpy", 3) * kDeg;
  for (auto [key, value] : {std::pair{"T", &p.T}, {"gyro_sd", &p.gyro_sd}, {"accel_sd", &p.accel_sd},
                            {"gnss_sd", &p.gnss_sd}, {"nhc_sd", &p.nhc_sd}, {"zupt_sd", &p.zupt_sd}})
    *value = in.real("model", key, *value);
  if (in.has("prior", "start_rpy")) p.start_rpy = in.vector("prior", "start_rpy", 3) * kDeg;
  if (in.has("prior", "start_velocity")) p.start_velocity = in.vector("prior", "start_velocity", 3);
  if (in.has("prior", "start_position")) p.start_position = in.vector("prior", "start_position", 3);
  if (in.has("prior", "lever")) p.lever = in.vector("prior", "lever", 3);
  p.attitude_sd = in.real("prior", "attitude_sd", p.attitude_sd / kDeg) * kDeg;
  p.mount_sd = in.real("prior", "mount_sd", p.mount_sd / kDeg) * kDeg;
  for (auto [key, value] : {std::pair{"velocity_sd", &p.velocity_sd}, {"position_sd", &p.position_sd},
                            {"gyro_bias_sd", &p.gyro_bias_sd}, {"accel_bias_sd", &p.accel_bias_sd},
                            {"lever_sd", &p.lever_sd}, {"delay_sd", &p.delay_sd}})
    *value = in.real("prior", key, *value);
  return p;
}

void writeIns(const StrapdownIns::Params& p, ParamSink& out) {
  out.real("model", "T", p.T);
  out.vector("model", "anchor", Eigen::Vector3d(p.anchor.lat / kDeg, p.anchor.lon / kDeg, p.anchor.height));
  out.vector("model", "mount_rpy", p.mount_rpy / kDeg);
  for (auto [key, value] : {std::pair{"gyro_sd", p.gyro_sd}, {"accel_sd", p.accel_sd}, {"gnss_sd", p.gnss_sd},
                            {"nhc_sd", p.nhc_sd}, {"zupt_sd", p.zupt_sd}})
    out.real("model", key, value);
  out.vector("prior", "start_rpy", p.start_rpy / kDeg);
  out.vector("prior", "start_velocity", p.start_velocity);
  out.vector("prior", "start_position", p.start_position);
  out.vector("prior", "lever", p.lever);
  for (auto [key, value] : {std::pair{"attitude_sd", p.attitude_sd / kDeg}, {"velocity_sd", p.velocity_sd},
                            {"position_sd", p.position_sd}, {"gyro_bias_sd", p.gyro_bias_sd},
                            {"accel_bias_sd", p.accel_bias_sd}, {"lever_sd", p.lever_sd}, {"mount_sd", p.mount_sd / kDeg},
                            {"delay_sd", p.delay_sd}})
    out.real("prior", key, value);
}

const ModelRegistration registration{{
    "strapdown_ins", {}, "StrapdownIns",
    "Strapdown GNSS/INS: IMU inputs, attitude on SO(3), velocity and position in an Earth-fixed NED frame; gyro "
    "and accelerometer biases, lever arm and mounting as constants; GNSS, non-holonomic and zero-velocity channels.",
    insParams(),
    [](const ParamSource& in) -> std::unique_ptr<Model> { return std::make_unique<StrapdownIns>(readIns(in)); },
    [](const Model& m, ParamSink& out) { writeIns(dynamic_cast<const StrapdownIns&>(m).params(), out); },
    [](const Model& m) { return dynamic_cast<const StrapdownIns*>(&m) != nullptr; }}};
}  // namespace

}  // namespace gssm::models
