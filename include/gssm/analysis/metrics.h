#pragma once
// Accuracy, consistency and timing of one estimator run against the truth.
#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "gssm/core/data.h"
#include "gssm/analysis/offline.h"

namespace gssm {

struct RunMetrics {
  Method method = Method::Ekf;
  std::vector<std::string> names;  ///< the compared components' names (the truth's; all stacked states by default)
  std::size_t rows = 0;            ///< estimates compared with the truth
  std::size_t rows_without_truth = 0;  ///< estimates outside a partial truth's time span, not compared
  Eigen::VectorXd rmse;            ///< per compared component (empty without truth)
  Eigen::VectorXd max_abs_error;   ///< per compared component
  Eigen::VectorXd final_error;     ///< estimate − truth at the last row
  double mean_nees = 0;            ///< mean of eᵀP⁻¹e over rows (dof: the compared components)
  /// Planar position error ‖(px, py) − truth‖ when px and py are compared
  /// (NaN otherwise): RMS, largest, last.
  double position_rmse = NAN, position_max = NAN, position_final = NAN;
  std::vector<std::string> constant_names;  ///< x_b's
  Eigen::VectorXd constants, constants_sd;  ///< at the last row
  /// A calibration reference of the constants (NaN: none for that one) and
  /// the RMS of constants − reference over those it gives (compareConstants).
  Eigen::VectorXd constants_reference;
  /// The constants in the reference's terms (Model::comparableConstants;
  /// equal to `constants` unless the model says otherwise).
  Eigen::VectorXd constants_compared;
  double constants_reference_rms = NAN;
  std::size_t constants_referenced = 0;
  std::size_t downweighted = 0;             ///< see OfflineRun
  std::int64_t rejected = 0;
  double latency_median = 0, latency_p99 = 0;  ///< per update, seconds
  double total_seconds = 0;
  int iterations = 0;
  bool has_truth = false;
};

/// Matches rows to truth by time (runErrors); throws InvalidArgument if an
/// estimate time has no truth row.
RunMetrics computeMetrics(const Model& model, const OfflineRun& run, const Truth* truth);

/// Fills the reference fields of `m` from `reference` (size n_b, NaN where
/// it says nothing), comparing `compared` (the constants in the reference's
/// terms, Model::comparableConstants; null: m.constants as they are);
/// InvalidArgument on a size mismatch.
void compareConstants(RunMetrics& m, const Eigen::VectorXd& reference, const Gaussian* compared = nullptr);

/// Percentile (0..100) of a sample, by linear interpolation; 0 for empty.
double percentile(std::vector<double> v, double p);

}  // namespace gssm
