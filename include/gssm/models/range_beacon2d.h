#pragma once
// A wheeled vehicle with odometry ranging to radio beacons at surveyed
// positions (the CMU Plaza logs' kind; docs/DESIGN.md §9).
//   x_c = [px, py, heading] (heading an angle),
//   u   = [v, omega]: odometry as speed and turn rate over the interval (a
//         log's distance and heading increments divided by its duration, so
//         a step split by a range measurement moves in proportion),
//   px += s_d·v·dt·cos(heading), py += s_d·v·dt·sin(heading), heading += (omega − b_ω)·dt
//   range to beacon i (one channel "range_<id>" each) = s_r·‖p − b_i‖ + o_i
// The constants, each chosen in the configuration: a common range scale s_r
// (1 when off), a per-beacon range offset o_i (0 when off), an odometry
// distance scale s_d (1 when off), a heading-rate bias b_ω of the odometry's
// turn rate (a gyro-like drift; 0 when off). Process noise grows with the distance and
// the turn of each step (variances additive over split steps).
#include <vector>

#include "gssm/model/model.h"

namespace gssm::models {

class RangeBeacon2D final : public Model {
 public:
  struct Params {
    double T = 0.1;                        ///< nominal odometry period (s)
    std::vector<int> beacon_ids;           ///< as the log names them
    std::vector<Eigen::Vector2d> beacons;  ///< positions (m), same order
    bool range_scale = true;               ///< estimate a common range scale s_r
    bool range_offsets = false;            ///< estimate a range offset per beacon
    bool odometry_scale = false;           ///< estimate an odometry distance scale s_d
    bool heading_rate_bias = false;        ///< estimate a bias b_ω of the odometry's turn rate
    double range_sd = 0.5;                 ///< σ of one range (m)
    double distance_sd = 0.05;             ///< odometry position noise, m per √m travelled
    double turn_sd = 0.05;                 ///< heading noise, rad per √rad turned
    double heading_drift_sd = 0.01;        ///< heading noise, rad per √m travelled
    double position_sd_per_s = 0.01;       ///< floor: m per √s (keeps Q positive definite at rest)
    double heading_sd_per_s = 0.001;       ///< floor: rad per √s
    Eigen::Vector3d start{0, 0, 0};        ///< prior mean of [px, py, heading]
    Eigen::Vector3d start_sd{1, 1, M_PI};  ///< prior σ (σ = π: heading unknown)
    double range_scale_sd = 0.1;           ///< prior σ of s_r (mean 1)
    double range_offset_sd = 1.0;          ///< prior σ of each o_i (mean 0), m
    double odometry_scale_sd = 0.05;       ///< prior σ of s_d (mean 1)
    double heading_rate_bias_sd = 0.01;    ///< prior σ of b_ω (mean 0), rad/s
    RobustLoss range_loss;                 ///< on every range channel
    double ekf_gate = 0;                   ///< EKF NIS gate of every range channel (0: none)
  };

  explicit RangeBeacon2D(const Params& p);

  std::string name() const override { return "range_beacon_2d"; }
  const Params& params() const { return p_; }
  std::vector<Eigen::Vector2d> landmarks() const override;
  /// Index of s_r, o_<id>, s_d in x_b, or −1 when not estimated.
  int rangeScaleIndex() const { return i_scale_; }
  int rangeOffsetIndex(std::size_t beacon) const { return i_offset_ < 0 ? -1 : i_offset_ + static_cast<int>(beacon); }
  int odometryScaleIndex() const { return i_odo_; }
  int headingRateBiasIndex() const { return i_hrb_; }

  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                    Eigen::MatrixXd* J_f_xc = nullptr, Eigen::MatrixXd* J_f_xb = nullptr) const override;
  /// Channel 0 (the first beacon).
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc = nullptr,
                    Eigen::MatrixXd* J_h_xb = nullptr) const override;
  Eigen::VectorXd h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                    Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const override;
  Eigen::MatrixXd processNoise(double dt) const override;
  Eigen::MatrixXd processNoiseOf(double dt, const Eigen::VectorXd& u) const override;
  bool processNoiseDependsOnInput() const override { return true; }

 private:
  Params p_;
  int i_scale_ = -1, i_offset_ = -1, i_odo_ = -1, i_hrb_ = -1;
};

}  // namespace gssm::models
