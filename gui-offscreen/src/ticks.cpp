#include "gssm/plot/ticks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gssm::plot {

Ticks niceTicks(double lo, double hi, int max_ticks) {
  if (max_ticks < 2) max_ticks = 2;
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0, hi = 1;
  if (hi < lo) std::swap(lo, hi);
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(lo))) {
    const double pad = std::max(1.0, std::abs(lo)) * 0.05;
    lo -= pad;
    hi += pad;
  }
  Ticks t;
  const double raw = (hi - lo) / (max_ticks - 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    t.step = m * mag;
    t.lo = std::floor(lo / t.step) * t.step;
    t.hi = std::ceil(hi / t.step) * t.step;
    if (std::lround((t.hi - t.lo) / t.step) + 1 <= max_ticks) break;
  }
  const long n = std::lround((t.hi - t.lo) / t.step);
  for (long i = 0; i <= n; ++i) {
    double v = t.lo + static_cast<double>(i) * t.step;
    if (std::abs(v) < 1e-9 * t.step) v = 0.0;  // no "-0" or 1e-17
    t.values.push_back(v);
  }
  return t;
}

std::string formatTick(double v, double step) {
  char buf[32];
  const double a = std::abs(v);
  if (a != 0 && (a >= 1e6 || a < 1e-4)) {
    // As many significant digits as tell one tick from the next (GPS
    // seconds, ~1.4e9 a step of 50 apart, need ten; 3 at least).
    const int digits = static_cast<int>(std::floor(std::log10(a)) - std::floor(std::log10(std::abs(step)))) + 2;
    std::snprintf(buf, sizeof buf, "%.*g", std::clamp(digits, 3, 15), v);
    return buf;
  }
  int decimals = 0;
  for (double s = step; decimals < 8 && std::abs(s - std::round(s)) > 1e-9 * std::max(1.0, s); s *= 10)
    ++decimals;
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace gssm::plot
