#pragma once
// The estimation methods, as a type. One table (methods()) says, for each,
// its name (command lines, file names, reports), its label (figures),
// whether it streams (makeEstimator) or needs the whole run (the batch
// solver), which option groups of EstimatorOptions it reads, and the INI
// section that holds its own settings. Text becomes a Method only at the
// edge (io::parseMethod, the checkpoint reader); nothing else compares names.
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace gssm {

enum class Method {
  Ekf,          ///< the EKF baseline (stacked state, constants as a time series)
  Batch,        ///< the batch MAP of the whole run (the reference; not streaming)
  Incremental,  ///< full-history incremental smoother (Bayes tree)
  FixedLag,     ///< fixed-lag smoother with exact marginalization
  PaperWindow,  ///< the paper's window re-solve (reproduction mode)
};

/// Option groups of EstimatorOptions, as bits of MethodInfo::reads.
enum MethodOptions : unsigned {
  kEkfOptions = 1u << 0,          ///< EstimatorOptions::ekf
  kSmootherOptions = 1u << 1,     ///< EstimatorOptions::smoother (relinearization policy)
  kIncrementalOptions = 1u << 2,  ///< EstimatorOptions::incremental (ordering)
  kFixedLagOptions = 1u << 3,     ///< EstimatorOptions::fixed_lag (window)
  kPaperWindowOptions = 1u << 4,  ///< EstimatorOptions::paper_window (window)
  kBatchOptions = 1u << 5,        ///< EstimatorOptions::batch
};

struct MethodInfo {
  Method method;
  const char* name;         ///< "fixed-lag"
  const char* label;        ///< "GSSM fixed-lag", for figure legends
  bool streaming;           ///< makeEstimator builds it; false: needs the whole run
  unsigned reads;           ///< MethodOptions bits it reads
  const char* ini_section;  ///< its own INI section ("" if none)
  /// Work over a run relative to the others (higher: more): methods run
  /// side by side start the costliest first, so that the cheap ones fill
  /// in at the end (a window re-solve per step > a smoother's update >
  /// one batch solve > a filter's update).
  int cost_rank;
};

/// Every method, in the order "all" runs them.
const std::vector<MethodInfo>& methods();
const MethodInfo& methodInfo(Method m);
inline const char* methodName(Method m) { return methodInfo(m).name; }
/// Writes the method's name.
std::ostream& operator<<(std::ostream& os, Method m);
/// The method called `name`, if any (table lookup; io::parseMethod turns a
/// miss into an error naming the source).
std::optional<Method> methodNamed(const std::string& name);
/// The methods makeEstimator builds, in table order.
std::vector<Method> streamingMethods();
/// "ekf, batch, incremental, fixed-lag, paper-window" (for messages).
std::string methodNameList(bool streaming_only = false);

}  // namespace gssm
