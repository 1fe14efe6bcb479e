// Two sensors on one linear model, with a robust loss and per-measurement
// noise: a cart's position x (velocity v, both evolving) read by an odometer
// with a constant offset b (the default channel "y") and by a GPS. The
// manual's "Several sensors" lines, as a program. Exit code 0 when the
// offset is recovered within 4σ.
#include <cmath>
#include <iostream>
#include <random>

#include "gssm/estimator/estimator.h"
#include "gssm/models/linear.h"

int main() {
  using Eigen::MatrixXd;
  const double b_true = 0.8, v_true = 1.5;
  gssm::models::LinearSystem base;
  base.A_c = (MatrixXd(2, 2) << 0, 1, 0, 0).finished();  // ẋ = v, v̇ = 0 (+ noise)
  base.A_b = MatrixXd::Zero(2, 1);
  base.B = MatrixXd::Zero(2, 0);
  base.C_c = (MatrixXd(1, 2) << 1, 0).finished();         // odometer: x + b
  base.C_b = MatrixXd::Ones(1, 1);
  base.noise.T = 0.1;
  base.noise.Q = Eigen::Vector2d(1e-6, 1e-4).asDiagonal();
  base.noise.R = MatrixXd::Constant(1, 1, 0.01);
  base.noise.prior_state = {Eigen::Vector2d(0, 1), Eigen::Vector2d(1, 1).asDiagonal()};
  base.noise.prior_constants = {Eigen::VectorXd::Zero(1), MatrixXd::Constant(1, 1, 4)};
  const MatrixXd C_gps = base.C_c, Cb_gps = MatrixXd::Zero(1, 1), R_gps = MatrixXd::Constant(1, 1, 0.25);
  const MatrixXd R_reported = MatrixXd::Constant(1, 1, 0.09);
  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  // [two-sensors]
  gssm::models::LinearSystem sys = base;                // the default channel "y": C_c, C_b, R
  sys.channels = {{"gps", C_gps, Cb_gps, R_gps, {}}};   // a second sensor
  gssm::models::LinearModel model(sys);
  model.setChannelLoss(0, {gssm::RobustLoss::Kind::Huber, 1.345}, /*EKF gate*/ 16);  // before estimating
  auto est = gssm::makeEstimator(model, {gssm::Method::FixedLag});
  for (int k = 1; k <= 300; ++k) {
    const double t = 0.1 * k, x = v_true * t;
    est->addMeasurement(t, Eigen::VectorXd::Constant(1, x + b_true + 0.1 * n01(rng)));       // default channel
    if (k % 10 == 0) {
      const Eigen::VectorXd y_gps = Eigen::VectorXd::Constant(1, x + 0.5 * n01(rng));
      if (k % 20 == 0)
        est->addMeasurement(t, "gps", y_gps);           // any rate, any interleaving, same time stamps too
      else
        est->addMeasurement({t, y_gps, model.channelIndex("gps"), R_reported});  // the receiver's own accuracy
    }
  }
  // [/two-sensors]
  const gssm::StateEstimate e = est->current();
  const double b = e.mean[2], sd = std::sqrt(e.covariance(2, 2));
  std::cout << "offset " << b << " ± " << sd << " (true " << b_true << ")\n";
  return std::abs(b - b_true) < 4 * sd ? 0 : 1;
}
