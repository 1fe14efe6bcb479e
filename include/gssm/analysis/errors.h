#pragma once
// Errors of a run against the truth, the one computation behind the
// metrics of gssm-process and the Monte Carlo.
#include <Eigen/Core>
#include <vector>

#include "gssm/analysis/offline.h"
#include "gssm/core/data.h"

namespace gssm {

struct RunErrors {
  std::vector<double> times;
  std::vector<Eigen::VectorXd> error;  ///< estimate − truth (stacked [x_c; x_b]) per row
  std::vector<double> nees;            ///< eᵀP⁻¹e per row, with the row's covariance P
  /// Root mean square over the rows, per stacked state (empty without rows).
  Eigen::VectorXd rmse() const;
};

/// The error of each row of `run` against the truth row at the same instant
/// (core/time.h). Throws InvalidArgument naming the first row time that has
/// no truth row.
RunErrors runErrors(const OfflineRun& run, const Truth& truth);

}  // namespace gssm
