#include "gssm/io/metrics_json.h"

#include <cmath>
#include <sstream>

#include "gssm/io/ini.h"
#include "gssm/io/json_text.h"

namespace gssm::io {

namespace {
std::string num(double v) { return jsonNumber(v); }
std::string perState(const std::vector<std::string>& names, const Eigen::VectorXd& v) {
  std::string out = "{";
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i ? ", " : "") + jsonQuoted(names[i]) + ": " + num(v[static_cast<Eigen::Index>(i)]);
  return out + "}";
}
}  // namespace

std::string metricsJson(const std::vector<RunMetrics>& runs, const std::string& dataset,
                        const DatasetStatus& status) {
  std::ostringstream os;
  os << "{\n  \"dataset\": " << jsonQuoted(dataset) << ",\n  \"partial\": " << (status.partial ? "true" : "false");
  if (status.partial) os << ",\n  \"stopped_at\": " << jsonQuoted(status.stopped_at);
  os << ",\n  \"out_of_order_rows\": " << status.late_rows << ",\n  \"max_lateness_s\": " << num(status.max_lateness);
  os << ",\n  \"skipped_rows\": " << status.skipped.size() << ",\n  \"skipped\": [";
  for (std::size_t i = 0; i < status.skipped.size(); ++i) os << (i ? ", " : "") << jsonQuoted(status.skipped[i]);
  os << "],\n  \"methods\": {";
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const RunMetrics& m = runs[r];
    os << (r ? "," : "") << "\n    " << jsonQuoted(methodName(m.method)) << ": {\n";
    os << "      \"rows\": " << m.rows << ",\n";
    if (m.rows_without_truth) os << "      \"rows_without_truth\": " << m.rows_without_truth << ",\n";
    if (m.has_truth) {
      os << "      \"rmse\": " << perState(m.names, m.rmse) << ",\n";
      os << "      \"final_error\": " << perState(m.names, m.final_error) << ",\n";
      os << "      \"mean_nees\": " << num(m.mean_nees) << ",\n";
      os << "      \"nees_dof\": " << m.names.size() << ",\n";
      os << "      \"max_abs_error\": " << perState(m.names, m.max_abs_error) << ",\n";
      if (std::isfinite(m.position_rmse))
        os << "      \"position_error_m\": {\"rmse\": " << num(m.position_rmse) << ", \"max\": " << num(m.position_max)
           << ", \"final\": " << num(m.position_final) << "},\n";
    }
    if (!m.constant_names.empty() && m.constants.size()) {
      os << "      \"constants\": " << perState(m.constant_names, m.constants) << ",\n";
      os << "      \"constants_sd\": " << perState(m.constant_names, m.constants_sd) << ",\n";
      if (m.constants_referenced > 0)
        os << "      \"constants_reference\": " << perState(m.constant_names, m.constants_reference)
           << ",\n      \"constants_compared\": " << perState(m.constant_names, m.constants_compared)
           << ",\n      \"constants_reference_rms\": " << num(m.constants_reference_rms)
           << ",\n      \"constants_referenced\": " << m.constants_referenced << ",\n";
    }
    const auto points = [&](const char* name, const PointErrors& e) {
      os << "      \"" << name << "\": {\"count\": " << e.count << ", \"horizontal_rms_m\": " << num(e.horizontal_rms)
         << ", \"horizontal_max_m\": " << num(e.horizontal_max) << ", \"rms_3d_m\": " << num(e.rms)
         << ", \"max_3d_m\": " << num(e.max) << "},\n";
    };
    if (m.withheld.count) points("withheld", m.withheld), points("used", m.used);
    os << "      \"downweighted\": " << m.downweighted << ",\n";
    os << "      \"rejected\": " << m.rejected << ",\n";
    os << "      \"latency_median_s\": " << num(m.latency_median) << ",\n";
    os << "      \"latency_p99_s\": " << num(m.latency_p99) << ",\n";
    os << "      \"total_s\": " << num(m.total_seconds) << ",\n";
    os << "      \"iterations\": " << m.iterations << "\n    }";
  }
  os << "\n  }\n}\n";
  return os.str();
}

}  // namespace gssm::io
