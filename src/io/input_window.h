#pragma once
// Internal: the inputs' readings over a time window, summed (what a
// measurement that reads the inputs around its time carries as its known
// values, Measurement::regressors).
#include <vector>

#include "gssm/core/data.h"

namespace gssm::io {

/// The sum of the inputs' first k components from `first` up to time `to`
/// (inclusive) into `sum`; returns how many readings.
inline int sumInputs(std::vector<Input>::const_iterator first, const std::vector<Input>& inputs, double to, int k,
                     Eigen::VectorXd& sum) {
  sum.setZero(k);
  int n = 0;
  for (; first != inputs.end() && first->t <= to; ++first, ++n) sum += first->u.head(k);
  return n;
}

}  // namespace gssm::io
