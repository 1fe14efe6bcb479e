#pragma once
// Accuracy, consistency and timing of one estimator run against the truth.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "gssm/core/data.h"
#include "gssm/analysis/offline.h"

namespace gssm {

struct RunMetrics {
  Method method = Method::Ekf;
  std::vector<std::string> names;  ///< stacked state names
  std::size_t rows = 0;            ///< estimates compared with the truth
  Eigen::VectorXd rmse;            ///< per stacked state (empty without truth)
  Eigen::VectorXd final_error;     ///< estimate − truth at the last row
  double mean_nees = 0;            ///< mean of eᵀP⁻¹e over rows (n = n_c + n_b)
  double latency_median = 0, latency_p99 = 0;  ///< per update, seconds
  double total_seconds = 0;
  int iterations = 0;
  bool has_truth = false;
};

/// Matches rows to truth by time (runErrors); throws InvalidArgument if an
/// estimate time has no truth row.
RunMetrics computeMetrics(const Model& model, const OfflineRun& run, const Truth* truth);

/// Percentile (0..100) of a sample, by linear interpolation; 0 for empty.
double percentile(std::vector<double> v, double p);

}  // namespace gssm
