#pragma once
// Accuracy, consistency and timing of one estimator run against the truth.
#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "gssm/core/data.h"
#include "gssm/analysis/offline.h"

namespace gssm {

/// A run's errors at measurements of a point-like channel (a GNSS antenna's
/// NED position): the model's prediction h against each measurement, the
/// first two components horizontal.
struct PointErrors {
  std::size_t count = 0;  ///< measurements scored
  double horizontal_rms = NAN, horizontal_max = NAN;
  double rms = NAN, max = NAN;  ///< of the whole vector (3-D)
};

/// One measurement's error: prediction − measurement at its time.
struct PointError {
  double t = 0;
  Eigen::VectorXd error;
};

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
  /// Against the measurements withheld from the estimators (a log's GNSS
  /// outages: the truth inside them) and against those on the same channel
  /// that were used (outside them); count 0 when the dataset withholds none.
  PointErrors withheld, used;
  /// The errors at each withheld measurement, in time order (what
  /// `withheld` summarizes).
  std::vector<PointError> withheld_errors;
};

/// Matches rows to truth by time (runErrors); throws InvalidArgument if an
/// estimate time has no truth row.
RunMetrics computeMetrics(const Model& model, const OfflineRun& run, const Truth* truth);

/// Fills the reference fields of `m` from `reference` (size n_b, NaN where
/// it says nothing), comparing `compared` (the constants in the reference's
/// terms, Model::comparableConstants; null: m.constants as they are);
/// InvalidArgument on a size mismatch.
void compareConstants(RunMetrics& m, const Eigen::VectorXd& reference, const Gaussian* compared = nullptr);

/// The run's errors at `at` (all on one channel, in time order): at each
/// measurement's time t, the newest row at or before t (causal for a
/// streaming run's rows) carried to t by the model's f under the input in
/// force (a step of at most one input interval), then h on that channel,
/// minus the measurement. Measurements before the first row are not scored.
std::vector<PointError> predictionErrorSeries(const Model& model, const OfflineRun& run,
                                              const std::vector<Input>& inputs, const std::vector<Measurement>& at);
/// An error's horizontal size: the norm of its first two components.
double horizontalNorm(const Eigen::VectorXd& error);
/// Errors' RMS and largest values, horizontal (horizontalNorm) and whole.
PointErrors summarizePointErrors(const std::vector<PointError>& errors);
/// predictionErrorSeries', summarized.
PointErrors predictionErrors(const Model& model, const OfflineRun& run, const std::vector<Input>& inputs,
                             const std::vector<Measurement>& at);

/// Percentile (0..100) of a sample, by linear interpolation; 0 for empty.
double percentile(std::vector<double> v, double p);

}  // namespace gssm
