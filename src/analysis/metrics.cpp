#include "gssm/analysis/metrics.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "gssm/analysis/errors.h"
#include "gssm/core/error.h"

namespace gssm {

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  const double pos = p / 100.0 * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  // The sorted v's elements lo and lo + 1 by selection, O(n): the same values as a sort's.
  const auto at_lo = v.begin() + static_cast<std::ptrdiff_t>(lo);
  std::nth_element(v.begin(), at_lo, v.end());
  const double next = lo + 1 < v.size() ? *std::min_element(at_lo + 1, v.end()) : *at_lo;
  return *at_lo + (pos - static_cast<double>(lo)) * (next - *at_lo);
}

void compareConstants(RunMetrics& m, const Eigen::VectorXd& reference, const Gaussian* compared) {
  if (reference.size() != m.constants.size() || (compared && compared->mean.size() != m.constants.size()))
    throw InvalidArgument("compareConstants: a reference of " + std::to_string(reference.size()) + " constants for " +
                          std::to_string(m.constants.size()));
  m.constants_reference = reference;
  m.constants_compared = compared ? compared->mean : m.constants;
  double sum = 0;
  m.constants_referenced = 0;
  for (Eigen::Index i = 0; i < reference.size(); ++i)
    if (std::isfinite(reference[i]))
      sum += std::pow(m.constants_compared[i] - reference[i], 2), ++m.constants_referenced;
  m.constants_reference_rms = m.constants_referenced ? std::sqrt(sum / static_cast<double>(m.constants_referenced)) : NAN;
}

RunMetrics computeMetrics(const Model& model, const OfflineRun& run, const Truth* truth) {
  RunMetrics m;
  m.method = run.method;
  m.names = model.stackedStateNames();
  m.constant_names = model.names().constants;
  m.downweighted = run.downweighted;
  m.rejected = run.rejected;
  const int nb = model.dims().nb;
  if (!run.rows.empty() && nb > 0) {
    m.constants = run.rows.back().mean.tail(nb);
    m.constants_sd = run.rows.back().covariance.diagonal().tail(nb).cwiseSqrt();
  }
  m.latency_median = percentile(run.update_seconds, 50);
  m.latency_p99 = percentile(run.update_seconds, 99);
  m.total_seconds = run.total_seconds;
  m.iterations = run.iterations;
  if (!truth || run.rows.empty()) return m;
  m.has_truth = true;
  const RunErrors errors = runErrors(run, *truth, model.angleStates());
  m.rows_without_truth = errors.without_truth;
  if (errors.error.empty()) {  // no estimate within the truth's span: nothing to compare
    m.has_truth = false;
    return m;
  }
  const auto all = model.stackedStateNames();
  m.names.clear();
  for (int c : errors.components) m.names.push_back(all[static_cast<std::size_t>(c)]);
  m.rows = errors.error.size();
  m.rmse = errors.rmse();
  m.final_error = errors.error.back();
  m.max_abs_error = Eigen::VectorXd::Zero(m.rmse.size());
  for (const auto& e : errors.error) m.max_abs_error = m.max_abs_error.cwiseMax(e.cwiseAbs());
  const auto px = std::find(m.names.begin(), m.names.end(), "px"), py = std::find(m.names.begin(), m.names.end(), "py");
  if (px != m.names.end() && py != m.names.end()) {
    const auto ix = px - m.names.begin(), iy = py - m.names.begin();
    double sq = 0, mx = 0, last = 0;
    for (const auto& e : errors.error) {
      last = std::hypot(e[ix], e[iy]);
      sq += last * last;
      mx = std::max(mx, last);
    }
    m.position_rmse = std::sqrt(sq / static_cast<double>(errors.error.size()));
    m.position_max = mx;
    m.position_final = last;
  }
  double nees = 0;
  for (double v : errors.nees) nees += v;
  m.mean_nees = nees / static_cast<double>(m.rows);
  return m;
}

}  // namespace gssm
