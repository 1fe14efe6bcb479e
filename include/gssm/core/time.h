#pragma once
// Time stamps: one rule for "the same instant" everywhere. State times are
// accumulated step by step (t_k + dt) or read from another file than the
// one they are compared with, so equal instants may differ by rounding:
// they match when they differ by at most 1 µs, or by kTimeTolerance relative
// to their size where that is more (a few hundred ulps: 0.14 ms at GPS
// seconds, 1.4e9 s, where one ulp is 2.4e-7 s — a GNSS fix 2.4e-7 s after an
// IMU stamp is that stamp's instant, not a state of its own whose Q(dt) is
// singular). (It was 1e-9 relative, which at GPS seconds made instants 1.4 s
// apart "the same".)
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <vector>

namespace gssm {

constexpr double kTimeTolerance = 1e-13;
constexpr double kTimeToleranceAbsolute = 1e-6;  ///< s

inline bool sameTime(double a, double b) {
  return std::abs(a - b) <= std::max(kTimeToleranceAbsolute, kTimeTolerance * std::max(std::abs(a), std::abs(b)));
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
