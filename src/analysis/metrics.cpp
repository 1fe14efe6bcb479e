#include "gssm/analysis/metrics.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

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
  const Eigen::Index n = static_cast<Eigen::Index>(m.names.size());
  Eigen::VectorXd sq = Eigen::VectorXd::Zero(n);
  double nees = 0;
  std::size_t j = 0;
  for (const auto& row : run.rows) {
    while (j < truth->times.size() && truth->times[j] < row.t - 1e-9) ++j;
    if (j == truth->times.size() || std::abs(truth->times[j] - row.t) > 1e-9)
      {
      std::ostringstream os;
      os << std::setprecision(17) << "metrics: no truth row at t = " << row.t;
      throw InvalidArgument(os.str());
    }
    const Eigen::VectorXd e = row.mean - truth->states[j];
    sq += e.cwiseAbs2();
    nees += e.dot(row.covariance.ldlt().solve(e));
    m.final_error = e;
    ++m.rows;
  }
  m.rmse = (sq / static_cast<double>(m.rows)).cwiseSqrt();
  m.mean_nees = nees / static_cast<double>(m.rows);
  return m;
}

}  // namespace gssm
