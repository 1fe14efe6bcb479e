#pragma once
// Time stamps: one rule for "the same instant" everywhere. State times are
// accumulated step by step (t_k + dt) or read from another file than the
// one they are compared with, so equal instants may differ by rounding:
// they match when they differ by at most kTimeTolerance relative to their
// size (absolute below 1 s).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <vector>

namespace gssm {

constexpr double kTimeTolerance = 1e-9;

inline bool sameTime(double a, double b) {
  return std::abs(a - b) <= kTimeTolerance * std::max({1.0, std::abs(a), std::abs(b)});
}

/// Finds rows of increasing `times` (e.g. a truth file) at increasing query
/// times, walking forward: O(rows + queries) over a whole run.
class TimeMatcher {
 public:
  explicit TimeMatcher(const std::vector<double>& times) : times_(times) {}
  /// The index of the row at the same instant as t, or nullopt if there is
  /// none. Queries must not go back in time.
  std::optional<std::size_t> find(double t) {
    while (next_ < times_.size() && times_[next_] < t && !sameTime(times_[next_], t)) ++next_;
    if (next_ < times_.size() && sameTime(times_[next_], t)) return next_;
    return std::nullopt;
  }

 private:
  const std::vector<double>& times_;
  std::size_t next_ = 0;
};

}  // namespace gssm
