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
  std::sort(v.begin(), v.end());
  const double pos = p / 100.0 * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const auto hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

RunMetrics computeMetrics(const Model& model, const OfflineRun& run, const Truth* truth) {
  RunMetrics m;
  m.method = run.method;
  m.names = model.stackedStateNames();
  m.latency_median = percentile(run.update_seconds, 50);
  m.latency_p99 = percentile(run.update_seconds, 99);
  m.total_seconds = run.total_seconds;
  m.iterations = run.iterations;
  if (!truth || run.rows.empty()) return m;
  m.has_truth = true;
  const RunErrors errors = runErrors(run, *truth);
  m.rows = errors.error.size();
  m.rmse = errors.rmse();
  m.final_error = errors.error.back();
  double nees = 0;
  for (double v : errors.nees) nees += v;
  m.mean_nees = nees / static_cast<double>(m.rows);
  return m;
}

}  // namespace gssm
