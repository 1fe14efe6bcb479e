#pragma once
// Errors of a run against the truth, the one computation behind the
// metrics of gssm-process and the Monte Carlo.
#include <Eigen/Core>
#include <vector>

#include "gssm/analysis/offline.h"
#include "gssm/core/data.h"

namespace gssm {

struct RunErrors {
  std::vector<int> components;         ///< the stacked components compared (the truth's)
  std::vector<double> times;
  std::vector<Eigen::VectorXd> error;  ///< estimate − truth on those components, angles wrapped, per row
  std::vector<double> nees;            ///< eᵀP⁻¹e per row, with the row's covariance P of those components
  std::size_t without_truth = 0;       ///< rows outside a partial truth's span (Truth::covers_every_row)
  /// Root mean square over the rows, per stacked state (empty without rows).
  Eigen::VectorXd rmse() const;
};

/// The error of each row of `run` against the truth row at the same instant
/// (core/time.h), on the components the truth gives; `angles` (stacked
/// indices, Model::angleStates) are wrapped to (−π, π]. Throws
/// InvalidArgument naming the first row time that has no truth row, unless
/// the truth says it does not cover every row (then such rows are counted).
RunErrors runErrors(const OfflineRun& run, const Truth& truth, const std::vector<int>& angles = {});

}  // namespace gssm
