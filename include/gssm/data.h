#pragma once
// Time-stamped inputs and measurements as they arrive from sensors.
#include <Eigen/Core>
#include <vector>

namespace gssm {

struct Measurement {
  double t = 0.0;
  Eigen::VectorXd y;
};

/// An input u held constant from time t until the next input (zero-order hold).
struct Input {
  double t = 0.0;
  Eigen::VectorXd u;
};

}  // namespace gssm
