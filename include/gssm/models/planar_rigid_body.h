#pragma once
// A rigid body moving in a plane, carrying range tags at known lever arms,
// ranging to anchors at known positions (the UWB planar-pose logs;
// docs/DESIGN.md §9).
//   x_c = [px, py, yaw, vx, vy, omega]: the body origin, heading (an angle)
//         and their rates, constant velocity driven by white acceleration;
//   range of link (tag i, anchor j), one channel "range_<i>_<j>" each:
//         s · ‖(p + R(yaw) l_i, h + l_iz) − a_j‖ + b_ij
// with l_i the tag's lever arm in the body frame, h the known height of the
// body origin (the problem is planar: the height difference only shortens
// the horizontal part), a_j the anchor. The constants, each chosen in the
// configuration: a bias b_ij per link (one node each, only in that link's
// factors: bias_<i>_<j>), a common range scale s (1 when off), and each
// tag's antenna delay as a function of the bearing β of the anchor in the
// body frame, g_i(β) = Σ_{k=2..K} a_ik cos kβ + b_ik sin kβ (the first
// harmonic is a lever-arm error; antenna_<i>_c<k>, antenna_<i>_s<k>; only in
// tag i's factors):
//   range = s · ‖…‖ + b_ij + g_i(β_ij).
#include <vector>

#include <Eigen/Core>

#include "gssm/model/model.h"

namespace gssm::models {

class PlanarRigidBody final : public Model {
 public:
  struct Params {
    double T = 0.01;                        ///< nominal step (s)
    std::vector<int> tag_ids, anchor_ids;   ///< as the log names them
    std::vector<Eigen::Vector3d> tags;      ///< lever arms in the body frame (m)
    std::vector<Eigen::Vector3d> anchors;   ///< positions in the world frame (m)
    double height = 0.0;                    ///< the body origin's known height (m)
    double accel_sd = 1.0;                  ///< white acceleration, m/s² per √Hz, each axis
    double yaw_accel_sd = 1.0;              ///< white angular acceleration, rad/s² per √Hz
    /// σ of one range (m); with [colored_noise] on the links, its white part
    double range_sd = 0.07;
    bool link_biases = true;                ///< a bias per link
    bool range_scale = false;               ///< a common range scale
    /// K: harmonics of each tag's bearing-dependent antenna delay (0: none)
    int antenna_harmonics = 0;
    RobustLoss range_loss;                  ///< on every range
    double ekf_gate = 0;                    ///< EKF NIS gate of every range (0: none)
    Eigen::Vector3d start{0, 0, 0};         ///< prior mean of [px, py, yaw]
    double position_sd = 3.0, yaw_sd = M_PI, velocity_sd = 1.0, omega_sd = 1.0;  ///< prior σ
    /// Prior of the biases, mean 0: b_ij = c + d_ij with a part c every link
    /// shares (σ bias_common_sd; UWB links all read long by antenna delay)
    /// and each link's own part d_ij (σ bias_sd), i.e. covariance
    /// bias_sd²·I + bias_common_sd²·11ᵀ (m).
    double bias_sd = 0.3;
    double bias_common_sd = 0.0;
    double range_scale_sd = 0.05;           ///< prior σ of the scale (mean 1)
    double antenna_sd = 0.03;               ///< prior σ of each harmonic's coefficient (mean 0), m
  };

  explicit PlanarRigidBody(const Params& p);

  std::string name() const override { return "planar_rigid_body"; }
  bool processIsAffine() const override { return true; }  // constant velocity
  const Params& params() const { return p_; }
  std::vector<Eigen::Vector2d> landmarks() const override;
  /// The tags in the world frame: p + R(yaw)·l_i.
  std::vector<Eigen::Vector2d> bodyPoints(const Eigen::VectorXd& xc) const override;
  std::vector<std::string> bodyPointNames() const override;
  /// A calibration file's rows (tag, anchor, bias, slope: range error =
  /// bias + slope·distance): each link's bias at its mean true distance
  /// along `truth`, the bias-only constant the calibration implies.
  std::vector<std::string> referenceColumns() const override { return {"tag", "anchor", "bias", "slope"}; }
  Eigen::VectorXd referenceConstants(const Eigen::MatrixXd& rows, const Truth& truth) const override;
  /// With a range scale s, each link's range error at its mean true
  /// distance d̄ (what a bias-only calibration constant is): b + (s − 1)·d̄,
  /// the scale itself unchanged; without one, x_b.
  Gaussian comparableConstants(const Gaussian& xb, const Truth& truth) const override;
  /// The channel of link (tag i, anchor j), by their positions in the lists.
  int channelOf(std::size_t tag, std::size_t anchor) const { return static_cast<int>(tag * p_.anchors.size() + anchor); }
  /// Index in x_b of link c's bias, −1 without link biases.
  int biasIndex(int channel) const { return i_bias_ < 0 ? -1 : i_bias_ + channel; }

  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                    Eigen::MatrixXd* J_f_xc = nullptr, Eigen::MatrixXd* J_f_xb = nullptr) const override;
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc = nullptr,
                    Eigen::MatrixXd* J_h_xb = nullptr) const override;
  Eigen::VectorXd h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                    Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const override;
  void hInto(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::VectorXd& out,
             Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const override;
  /// White acceleration over dt on (px, vx), (py, vy), (yaw, omega):
  /// q²·[[dt³/3, dt²/2], [dt²/2, dt]] each.
  Eigen::MatrixXd processNoise(double dt) const override;

 private:
  /// Each link's mean geometric distance along the truth's rows.
  Eigen::VectorXd meanTrueDistances(const Truth& truth) const;
  Params p_;
  /// g_t(β) of tag t for the tag-to-anchor offset d (world, horizontal) at
  /// yaw (cos, sin) c, s; its derivatives added to J_h_xc's row and written
  /// into J_h_xb.
  double antennaDelay(std::size_t t, double c, double s, const Eigen::Vector2d& d, const Eigen::VectorXd& xb,
                      Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const;
  int i_bias_ = -1, i_scale_ = -1, i_antenna_ = -1;
};

}  // namespace gssm::models
