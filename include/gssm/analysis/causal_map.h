#pragma once
// The exact causal MAP at given times: what an online smoother that kept
// every state and relinearized everything at every step would estimate.
// A diagnosis of an online method's error: measured against it, what is
// left is the model's, not the solver's (docs/DESIGN.md §12).
#include <string>
#include <utility>
#include <vector>

#include "gssm/analysis/metrics.h"
#include "gssm/analysis/offline.h"

namespace gssm {

struct CausalMapErrors {
  /// At each time of `at` whose solve succeeded: the batch MAP of every
  /// input and measurement at or before it, its newest row carried to that
  /// time and compared as predictionErrorSeries compares a run's.
  std::vector<PointError> errors;
  /// The times whose solve failed, with the solver's message (a log cut
  /// where its data hold the last states loosely may not factor).
  std::vector<std::pair<double, std::string>> failed;
};

/// One batch solve (options.batch, from its EKF start) per time of `at`
/// (the withheld measurements, in time order), on `threads` threads. On a
/// linear model each equals the Kalman filter's estimate there.
CausalMapErrors causalMapErrors(const Model& model, EstimatorOptions options,
                                const std::vector<Measurement>& measurements, const std::vector<Input>& inputs,
                                const std::vector<Measurement>& at, RowTimes rows = RowTimes::Measurements,
                                int threads = 1);

}  // namespace gssm
