#pragma once
// Axis ticks at round numbers (1, 2, 2.5, 5 × 10^k) covering a data range.
#include <string>
#include <vector>

namespace gssm::plot {

struct Ticks {
  double lo = 0, hi = 1;        ///< axis range: the outermost ticks, covering the data
  double step = 1;
  std::vector<double> values;   ///< lo, lo + step, ..., hi
};

/// At most `max_ticks` (≥ 2) ticks covering [lo, hi]; lo == hi widens the range.
Ticks niceTicks(double lo, double hi, int max_ticks = 8);
/// Tick label with just enough decimals for `step` ("0.05", "1000", "2.5e+06").
std::string formatTick(double v, double step);

}  // namespace gssm::plot
