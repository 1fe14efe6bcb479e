#pragma once
// Time-stamped inputs and measurements as they arrive from sensors, and the
// true trajectory of a recorded or simulated run.
#include <Eigen/Core>
#include <utility>
#include <vector>

namespace gssm {

struct Measurement {
  double t = 0.0;
  Eigen::VectorXd y;
  int channel = 0;    ///< the model's measurement channel (0: the default)
  Eigen::MatrixXd R;  ///< this measurement's own noise covariance; empty: the channel's
  /// Known values h reads beside the state, as many as the channel's
  /// MeasurementChannel::regressors (empty on most channels): e.g. the gyro's
  /// reading at a GNSS velocity fix, with which the lever arm turns.
  Eigen::VectorXd regressors;

  Measurement() = default;
  Measurement(double t_, Eigen::VectorXd y_, int channel_ = 0, Eigen::MatrixXd R_ = {},
              Eigen::VectorXd regressors_ = {})
      : t(t_), y(std::move(y_)), channel(channel_), R(std::move(R_)), regressors(std::move(regressors_)) {}
};

/// An input u held constant from time t until the next input (zero-order hold).
struct Input {
  double t = 0.0;
  Eigen::VectorXd u;
};

/// Ground truth: the stacked state [x_c; x_b] at known times (increasing),
/// or only some of its components (e.g. a log's true position).
struct Truth {
  std::vector<double> times;
  std::vector<Eigen::VectorXd> states;
  std::vector<int> components;  ///< the stacked components each row gives, in order; empty: all
  /// False for a truth interpolated to the estimates' times that does not
  /// reach all of them (a motion-capture log that starts after, or stops
  /// before, the sensors): rows without a truth row are then not compared
  /// (counted) instead of an error.
  bool covers_every_row = true;
};

}  // namespace gssm
