#pragma once
// 2-D inertial/radio navigation: position and velocity are the time series,
// the accelerometer bias and a range bias common to all beacons (a
// receiver-clock-like bias) are the constants.
//   x_c = [px, py, vx, vy], u = [ax, ay] (measured acceleration),
//   x_b = [bax, bay, brho]
//   p(k+1) = p + v·T + ½(u − b_a)·T²,  v(k+1) = v + (u − b_a)·T
//   y_i = ‖p − beacon_i‖ + brho, i = 1..4
#include <vector>

#include "gssm/model/model.h"

namespace gssm::models {

class Nav2D final : public Model {
 public:
  struct Params {
    double T = 0.1;
    double accel_noise = 0.05;  ///< white acceleration noise density (m/s²/√Hz): Q from a white-noise-acceleration model
    double range_sigma = 0.5;   ///< m
    std::vector<Eigen::Vector2d> beacons{{0, 0}, {200, 0}, {200, 200}, {0, 200}};
    Eigen::Vector4d prior_state{150, 100, 0, 5};  ///< on a 50 m circle about the beacons' centre
    Eigen::Vector4d prior_state_sd{5, 5, 1, 1};
    Eigen::Vector3d prior_constants{0, 0, 0};
    Eigen::Vector3d prior_constants_sd{0.1, 0.1, 5};
  };

  Nav2D() : Nav2D(Params{}) {}
  explicit Nav2D(const Params& p);
  /// Any noise and priors (e.g. from a config file) with the given beacons.
  Nav2D(const ModelNoise& noise, std::vector<Eigen::Vector2d> beacons, double accel_noise);

  std::string name() const override { return "nav_2d"; }
  const std::vector<Eigen::Vector2d>& beacons() const { return beacons_; }
  double accelNoise() const { return accel_noise_; }
  std::vector<Eigen::Vector2d> landmarks() const override;

  /// White-noise acceleration over dt: q·[[dt³/3 I, dt²/2 I], [dt²/2 I, dt I]].
  Eigen::MatrixXd processNoise(double dt) const override;

  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                    Eigen::MatrixXd* J_f_xc = nullptr, Eigen::MatrixXd* J_f_xb = nullptr) const override;
  using Model::h;  // h(channel, ...) for channel 0
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc = nullptr,
                    Eigen::MatrixXd* J_h_xb = nullptr) const override;

 private:
  std::vector<Eigen::Vector2d> beacons_;
  double accel_noise_;
};

}  // namespace gssm::models
