#pragma once
// Strapdown GNSS/INS (issue #37; docs/DESIGN.md §12): one state per IMU
// sample (or every imu_per_state samples and at every measurement), the
// IMU's rates and specific forces as inputs held over each interval, attitude on SO(3) (a rotation block), velocity and position in
// a NED frame fixed to the Earth at an anchor (strapdown.h). The sensor's
// constants are single nodes, each only in the factors that involve it:
//
//   x_c = [θ (IMU → NED, rotation block), v (m/s, NED), p (m, NED),
//          c (the IMU clock's time since the start, s: f adds dt),
//          β_g (with gyro_bias_walk > 0: the gyro bias's slowly varying
//            part, a random walk from 0; the bias is then b_g + β_g)]
//   x_b = [b_g (rad/s), b_a (m/s²), ℓ (IMU → antenna in the IMU's axes, m:
//            GNSS sees it so, whatever the mounting; in vehicle axes,
//            R_vb·ℓ, it would bend with the weakly seen mounting roll and
//            make a curved valley that Gauss–Newton crawls along),
//          μ (mounting misalignment about the vehicle's axes, rad:
//            R_vb = Rx(μ_r)·Ry(μ_p)·Rz(μ_y)·R_vb0, roll outermost: the
//            vehicle's forward axis in the IMU's axes then depends on μ_p
//            and μ_y alone, so the weakly seen roll does not bend the two
//            that the non-holonomic constraint sees well),
//          d (the IMU's time delay, s: added to its stamps gives GNSS time),
//          s_g, s_a (the gyro's and accelerometer's scale factor errors per
//            axis: a reading is (1 + s)∘true + b),
//          ρ (the IMU clock's rate error: its delay at clock time c is
//            d + ρ·c; a logger mapping a millisecond counter linearly onto
//            GPS time leaves one of order 1e-4)]
//   u   = [ω̃ (rad/s), f̃ (m/s²)] in the IMU's axes (imu_per_state = N > 1:
//          N of them, each after its duration, integrated in turn)
//
// Channels: `gnss` (the antenna's NED position at the fix's time,
// p + R_nb·ℓ − (d + ρ·c)·v), `nhc`
// (the vehicle's sideways and vertical velocity, zero: [R_vb·R_nbᵀ·v]_y,z
// at the IMU, or at the points Params::nhc_point from it, in axes turned
// by the body's give Params::nhc_compliance),
// `zupt` (the velocity, zero while standing), `zaru` (the gyro's mean
// reading while standing: b_g + R_nbᵀ·ω_ie), `gnss_vel` (the antenna's NED
// velocity at the fix's time, v + R_nb·(ω×ℓ) − δ·a: it reads the IMU's mean
// rates ω̃ and the velocity's rate of change a (NED) at the fix,
// Measurement::regressors). R_vb
// maps the IMU's axes to the vehicle's (forward, right, down); R_vb0 is its
// nominal value.
#include <Eigen/Core>
#include <array>

#include "gssm/model/model.h"
#include "gssm/models/geodesy.h"
#include "gssm/models/strapdown.h"

namespace gssm::models {

class StrapdownIns final : public Model {
 public:
  struct Params {
    double T = 0.01;                           ///< nominal IMU interval (s)
    geodesy::Geodetic anchor;                  ///< the frame's origin (rad, rad, m)
    Eigen::Vector3d mount_rpy{0, 0, 0};        ///< R_vb0 as roll, pitch, yaw (rad), IMU → vehicle
    /// Gyro white noise, rad/s/√Hz: one σ for every axis, or one per IMU
    /// axis (x, y, z): an engine shakes a strapped-down IMU about some axes
    /// more than about others.
    Eigen::VectorXd gyro_sd = Eigen::VectorXd::Constant(1, 1e-3);
    /// The gyro's σ about IMU axis `axis` (0, 1, 2) of gyro_sd.
    double gyroSdAbout(int axis) const { return gyro_sd[gyro_sd.size() == 3 ? axis : 0]; }
    double accel_sd = 1e-2;                    ///< accelerometer white noise, m/s²/√Hz
    double gnss_sd = 0.02;                     ///< σ of each GNSS coordinate (m) unless a fix gives its own
    double gnss_sd_scale = 1;                  ///< factor on the σs a fix gives (learnable: the receiver's honesty)
    double gnss_vel_sd = 0.05;                 ///< σ of each GNSS velocity component (m/s) unless a fix gives its own
    double gnss_vel_sd_scale = 1;              ///< factor on the velocity σs a fix gives
    /// How long a fix's velocity lags its time (s): a receiver's filtered or
    /// interval-averaged Doppler velocity (learnable, > 0; 0: instantaneous).
    double gnss_vel_latency = 0;
    double nhc_sd = 0.1;                       ///< σ of the vehicle's sideways velocity at the IMU (m/s)
    double nhc_down_sd = 0.1;                  ///< σ of its vertical velocity (m/s)
    /// Where the vehicle constraints hold, from the IMU in vehicle axes (m):
    /// the sideways one's point forward and down (a body rolls about a
    /// centre near the ground, the rear axle does not slide), the vertical
    /// one's point forward and right (the body pitches about a point
    /// between the axles), in that order. Prior means, and their σs: a
    /// component with σ > 0 is a constant node (`nhc_side_f`,
    /// `nhc_side_d`, `nhc_vert_f`, `nhc_vert_r`), one with σ 0 is held at
    /// its mean. With any point off the IMU the `nhc` channel reads the
    /// gyro's mean reading at the constraint (Measurement::regressors).
    Eigen::Vector4d nhc_point{0, 0, 0, 0}, nhc_point_sd{0, 0, 0, 0};
    /// The body's give on its tyres and springs (rad per m/s²): the car's
    /// body turns against its path in proportion to the specific force
    /// the tyres carry, so the constraints hold in axes turned from the
    /// body's by k_s·F_r about down (the slip angle under a lateral
    /// force) and by k_v·F_f about right (the pitch on the springs as the
    /// car brakes, accelerates or climbs), F = R_vb·f the specific force
    /// in vehicle axes: sideways k_s·F_r·w_f and vertically k_v·F_f·w_f
    /// are added to the velocity w at the constraints' points, in that
    /// order (k_s, k_v). Prior means and σs as nhc_point's: σ > 0 makes a
    /// constant node (`nhc_side_k`, `nhc_vert_k`). With either in use the
    /// `nhc` channel reads the IMU's mean reading (gyro, accelerometer).
    Eigen::Vector2d nhc_compliance{0, 0}, nhc_compliance_sd{0, 0};
    double zupt_sd = 0.01;                     ///< σ of the velocity while standing (m/s)
    double zaru_sd = 0.005;                    ///< σ of the gyro's mean reading while standing (rad/s)
    /// Robust loss on the vehicle constraints (`nhc`): a bump or a skid
    /// breaks them for a moment (none: Gaussian).
    RobustLoss nhc_loss;
    /// The EKF, which has no loss, rejects a constraint whose NIS exceeds
    /// this (MeasurementChannel::ekf_gate; 0: none).
    double nhc_ekf_gate = 0;
    Eigen::Vector3d start_rpy{0, 0, 0};        ///< prior mean of the IMU's attitude, roll, pitch, yaw (rad)
    Eigen::Vector3d start_velocity{0, 0, 0};   ///< prior mean of v(0) (m/s, NED)
    Eigen::Vector3d start_position{0, 0, 0};   ///< prior mean of p(0) (m, NED)
    double attitude_sd = 0.1, velocity_sd = 1.0, position_sd = 1.0;  ///< their σ (rad, m/s, m)
    /// A further σ of the start attitude about the vertical (rad): a start
    /// heading from the car's track holds the IMU's heading only through the
    /// nominal mounting, whose yaw is uncertain by mount_sd ([prior]
    /// heading_sd; docs/DESIGN.md §12).
    double start_heading_sd = 0;
    double gyro_bias_sd = 0.01;                ///< prior σ of b_g (rad/s)
    double accel_bias_sd = 0.1;                ///< prior σ of b_a (m/s²)
    /// Prior means of the IMU's own constants, in its axes: a calibration
    /// (the gyro's and accelerometer's biases, rad/s and m/s²; their scale
    /// factor errors, 1 = 100 %), the delay at the start (s) and the clock's
    /// rate error (s/s). 0 by default: the IMU as its datasheet has it.
    Eigen::Vector3d gyro_bias{0, 0, 0}, accel_bias{0, 0, 0}, gyro_scale{0, 0, 0}, accel_scale{0, 0, 0};
    double delay = 0, clock_rate = 0;
    Eigen::Vector3d lever{0, 0, 0};            ///< prior mean of the lever arm in vehicle axes (m; x_b holds R_vb0ᵀ·it)
    double lever_sd = 0.1;                     ///< its σ (m)
    double mount_sd = 0.1;                     ///< prior σ of μ (rad), mean 0
    double delay_sd = 0.1;                     ///< prior σ of d (s)
    double gyro_scale_sd = 0.01;               ///< prior σ of the gyro's scale factor errors
    double accel_scale_sd = 0.01;              ///< prior σ of the accelerometer's scale factor errors
    double clock_rate_sd = 1e-3;               ///< prior σ of ρ (s/s)
    double clock_wander_sd = 1e-4;             ///< the clock's random walk beyond ρ (s/√s)
    /// The gyro bias's random walk beyond the constant b_g (rad/s/√s); 0:
    /// the bias is constant (x_c has no β_g)
    double gyro_bias_walk = 0;
    /// IMU readings per state (1: a state at every sample; N > 1: the input
    /// packs N readings with their durations, packed_inputs.h, and f
    /// integrates them in turn: a state every N samples and at each
    /// measurement)
    int imu_per_state = 1;
  };

  explicit StrapdownIns(const Params& p);
  std::string name() const override { return "strapdown_ins"; }
  const Params& params() const { return p_; }
  const strapdown::NavFrame& frame() const { return frame_; }
  /// R_vb = Rx(μ_r)·Ry(μ_p)·Rz(μ_y)·R_vb0 at the constants x_b; J_out_mu:
  /// R_vb(μ + δ) = R_vb·Exp(J·δ) to first order.
  Eigen::Matrix3d mounting(const Eigen::VectorXd& xb, Eigen::Matrix3d* J_out_mu = nullptr) const;

  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                    Eigen::MatrixXd* J_f_xc = nullptr, Eigen::MatrixXd* J_f_xb = nullptr) const override;
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc = nullptr,
                    Eigen::MatrixXd* J_h_xb = nullptr) const override;
  Eigen::VectorXd h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                    Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const override;
  /// The `gnss_vel` channel: h given [ω̃, a] at the fix (the IMU's mean
  /// rates, the velocity's rate of change in NED).
  void hRegressedInto(int channel, const Eigen::VectorXd& regressors, const Eigen::VectorXd& xc,
                      const Eigen::VectorXd& xb, Eigen::VectorXd& out, Eigen::MatrixXd* J_h_xc,
                      Eigen::MatrixXd* J_h_xb) const override;
  Eigen::MatrixXd processNoise(double dt) const override;
  int readingsPerStep() const override { return p_.imu_per_state; }
  /// lat, lon (deg), height (m) of the antenna; vn, ve, vd (m/s); the
  /// vehicle's roll, pitch, yaw w.r.t. NED (deg); the biases; the lever arm
  /// in vehicle axes (m); imu_delay (s); the mounting R_vb as roll, pitch,
  /// yaw (deg, ZYX, IMU → vehicle). Standard deviations to first order.
  std::vector<std::string> reportNames() const override;
  void report(const Eigen::VectorXd& mean, const Eigen::MatrixXd& covariance, Eigen::VectorXd& value,
              Eigen::VectorXd& sd) const override;
  /// The point in the frame (NED from the anchor, m).
  std::optional<Eigen::Vector3d> localPosition(double lat, double lon, double height) const override {
    return frame_.local().toNed({lat, lon, height});
  }

  // Where each part of x_b starts: the constants every INS has, then the
  // vehicle constraints' points whose σ > 0 (nhcPointIndex), then the
  // body's give whose σ > 0 (nhcComplianceIndex).
  static constexpr int kGyroBias = 0, kAccelBias = 3, kLever = 6, kMount = 9, kDelay = 12, kGyroScale = 13,
                       kAccelScale = 16, kClockRate = 19, kConstants = 20;
  // In x_c: the navigation states (kStates of them), then β_g when the
  // gyro bias walks (dims().nc = kStates + 3).
  static constexpr int kClock = 9, kStates = 10, kGyroWalk = 10;
  bool gyroBiasWalks() const { return p_.gyro_bias_walk > 0; }
  /// Where component i of Params::nhc_point is in x_b (−1: held at its mean).
  int nhcPointIndex(int i) const { return nhc_point_index_[static_cast<std::size_t>(i)]; }
  /// The constraints' points off the IMU (any nhc_point or σ not 0): the
  /// `nhc` channel then reads the gyro's mean reading.
  bool nhcPointsOffImu() const { return nhc_points_off_imu_; }
  /// The constraints' points at the constants x_b, as Params::nhc_point
  /// (side f, d; vertical f, r; m, vehicle axes from the IMU).
  Eigen::Vector4d nhcPoint(const Eigen::VectorXd& xb) const;
  /// Where component i of Params::nhc_compliance is in x_b (−1: held at its mean).
  int nhcComplianceIndex(int i) const { return nhc_compliance_index_[static_cast<std::size_t>(i)]; }
  /// The body's give in use (any nhc_compliance or σ not 0): the `nhc`
  /// channel then reads the accelerometer's mean reading too.
  bool nhcCompliant() const { return nhc_compliant_; }
  /// The give (k_s, k_v) at the constants x_b, as Params::nhc_compliance.
  Eigen::Vector2d nhcCompliance(const Eigen::VectorXd& xb) const;
  /// The gyro bias at state x_c: b_g (+ β_g when it walks).
  Eigen::Vector3d gyroBias(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb) const {
    Eigen::Vector3d b = xb.segment<3>(kGyroBias);
    if (gyroBiasWalks()) b += xc.segment<3>(kGyroWalk);
    return b;
  }
  enum Channel : int { kGnss = 0, kNhc = 1, kZupt = 2, kZaru = 3, kGnssVelocity = 4 };

 private:
  // One strapdown step under one reading u = [ω̃, f̃] (the f of N = 1).
  Eigen::VectorXd step(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::Ref<const Eigen::VectorXd>& u,
                       double dt, Eigen::MatrixXd* J_f_xc, Eigen::MatrixXd* J_f_xb) const;
  Eigen::VectorXd stepResult(const Eigen::VectorXd& xc, const strapdown::NavState& next, double dt,
                             const Eigen::Matrix<double, 9, 9>& Jx, const Eigen::Matrix<double, 9, 12>& Jb,
                             Eigen::MatrixXd* J_f_xc, Eigen::MatrixXd* J_f_xb) const;
  Eigen::VectorXd antenna(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                          Eigen::MatrixXd* J_h_xb) const;
  Eigen::VectorXd restingGyro(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                              Eigen::MatrixXd* J_h_xb) const;
  Eigen::VectorXd vehicleVelocity(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                                  const Eigen::VectorXd& reading, Eigen::MatrixXd* J_h_xc,
                                  Eigen::MatrixXd* J_h_xb) const;
  void addTurnAtPoints(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::Vector3d& gyro,
                       const Eigen::Matrix3d& M, const Eigen::Matrix3d& E, Eigen::Vector2d& out,
                       Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const;
  void addCompliance(const Eigen::Matrix3d& R, const Eigen::VectorXd& xb, const Eigen::Vector3d& accel,
                     const Eigen::Vector3d& u, const Eigen::Matrix3d& M, const Eigen::Matrix3d& E,
                     Eigen::Vector2d& out, Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const;
  Params p_;
  strapdown::NavFrame frame_;
  Eigen::Matrix3d mount0_;  // R_vb0
  std::array<int, 4> nhc_point_index_;
  std::array<int, 2> nhc_compliance_index_;
  bool nhc_points_off_imu_, nhc_compliant_;
};

}  // namespace gssm::models
