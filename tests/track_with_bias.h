#pragma once
// A small linear GSSM the learning and late-measurement tests and benchmarks
// share: a constant-velocity track (x, ẋ) whose position sensor reads with a
// constant bias (one constant node).
#include <Eigen/Core>

#include "gssm/models/linear.h"

namespace gssm::testing {

/// Q = diag(q_pos, q_vel) per nominal step T, R = r; prior x ~ N((0, 1),
/// diag(4, 1)), bias ~ N(bias_mean, bias_var).
inline models::LinearSystem trackWithBias(double q_pos, double q_vel, double r, double T, double bias_mean = 0.0,
                                          double bias_var = 4.0) {
  models::LinearSystem s;
  s.A_c = (Eigen::Matrix2d() << 0, 1, 0, 0).finished();
  s.A_b = Eigen::MatrixXd::Zero(2, 1);
  s.B = Eigen::MatrixXd::Zero(2, 0);
  s.C_c = Eigen::RowVector2d(1, 0);
  s.C_b = Eigen::MatrixXd::Ones(1, 1);
  s.noise.T = T;
  s.noise.Q = Eigen::Vector2d(q_pos, q_vel).asDiagonal();
  s.noise.R = Eigen::MatrixXd::Constant(1, 1, r);
  s.noise.prior_state = {Eigen::Vector2d(0, 1), Eigen::Vector2d(4, 1).asDiagonal()};
  s.noise.prior_constants = {Eigen::VectorXd::Constant(1, bias_mean), Eigen::MatrixXd::Constant(1, 1, bias_var)};
  return s;
}

}  // namespace gssm::testing
