#include "gssm/metrics.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "gssm/error.h"
#include "gssm/io/ini.h"

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
      throw InvalidArgument("metrics: no truth row at t = " + io::formatDouble(row.t));
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

namespace {
std::string num(double v) { return std::isfinite(v) ? io::formatDouble(v) : "null"; }
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}
std::string perState(const std::vector<std::string>& names, const Eigen::VectorXd& v) {
  std::string out = "{";
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i ? ", " : "") + quoted(names[i]) + ": " + num(v[static_cast<Eigen::Index>(i)]);
  return out + "}";
}
}  // namespace

std::string metricsJson(const std::vector<RunMetrics>& runs, const std::string& dataset,
                        const DatasetStatus& status) {
  std::ostringstream os;
  os << "{\n  \"dataset\": " << quoted(dataset) << ",\n  \"partial\": " << (status.partial ? "true" : "false");
  if (status.partial) os << ",\n  \"stopped_at\": " << quoted(status.stopped_at);
  os << ",\n  \"skipped_rows\": " << status.skipped.size() << ",\n  \"skipped\": [";
  for (std::size_t i = 0; i < status.skipped.size(); ++i) os << (i ? ", " : "") << quoted(status.skipped[i]);
  os << "],\n  \"methods\": {";
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const RunMetrics& m = runs[r];
    os << (r ? "," : "") << "\n    " << quoted(methodName(m.method)) << ": {\n";
    os << "      \"rows\": " << m.rows << ",\n";
    if (m.has_truth) {
      os << "      \"rmse\": " << perState(m.names, m.rmse) << ",\n";
      os << "      \"final_error\": " << perState(m.names, m.final_error) << ",\n";
      os << "      \"mean_nees\": " << num(m.mean_nees) << ",\n";
      os << "      \"nees_dof\": " << m.names.size() << ",\n";
    }
    os << "      \"latency_median_s\": " << num(m.latency_median) << ",\n";
    os << "      \"latency_p99_s\": " << num(m.latency_p99) << ",\n";
    os << "      \"total_s\": " << num(m.total_seconds) << ",\n";
    os << "      \"iterations\": " << m.iterations << "\n    }";
  }
  os << "\n  }\n}\n";
  return os.str();
}

}  // namespace gssm
