#include "gssm/estimator/method.h"

#include <ostream>
#include <stdexcept>

namespace gssm {

const std::vector<MethodInfo>& methods() {
  static const std::vector<MethodInfo> table{
      {Method::Ekf, "ekf", "EKF", true, kEkfOptions, "ekf", 0},
      {Method::Batch, "batch", "batch MAP (smoother)", false, kBatchOptions, "batch", 1},
      {Method::Incremental, "incremental", "GSSM incremental", true, kSmootherOptions | kIncrementalOptions,
       "smoother", 3},
      {Method::FixedLag, "fixed-lag", "GSSM fixed-lag", true, kSmootherOptions | kFixedLagOptions, "fixed_lag", 2},
      {Method::PaperWindow, "paper-window", "paper window", true, kPaperWindowOptions, "paper_window", 4},
  };
  return table;
}

const MethodInfo& methodInfo(Method m) {
  for (const auto& info : methods())
    if (info.method == m) return info;
  throw std::logic_error("methodInfo: a Method missing from the table");
}

std::ostream& operator<<(std::ostream& os, Method m) { return os << methodName(m); }

std::optional<Method> methodNamed(const std::string& name) {
  for (const auto& info : methods())
    if (name == info.name) return info.method;
  return std::nullopt;
}

std::vector<Method> streamingMethods() {
  std::vector<Method> out;
  for (const auto& info : methods())
    if (info.streaming) out.push_back(info.method);
  return out;
}

std::string methodNameList(bool streaming_only) {
  std::string out;
  for (const auto& info : methods())
    if (info.streaming || !streaming_only) out += (out.empty() ? "" : ", ") + std::string(info.name);
  return out;
}

}  // namespace gssm
