#include "gssm/analysis/chi_square.h"

#include <cmath>
#include <limits>
#include <string>

#include "gssm/core/error.h"

namespace gssm {

namespace {
constexpr double kEps = 1e-16;

// ln(1 + t) − t without cancellation for small t.
double log1pmx(double t) {
  if (std::fabs(t) >= 0.5) return std::log1p(t) - t;
  double power = t * t, sum = 0;
  for (int n = 2; n < 200; ++n, power *= t) {
    const double term = power / n * (n % 2 == 0 ? -1 : 1);
    sum += term;
    if (std::fabs(term) < kEps * std::fabs(sum)) break;
  }
  return sum;
}

// lnΓ(a) − [(a − ½) ln a − a + ½ ln 2π], Stirling's series for large a.
double stirlingError(double a) {
  const double a2 = a * a;
  return (1.0 / 12 - (1.0 / 360 - (1.0 / 1260 - 1.0 / (1680 * a2)) / a2) / a2) / a;
}

// ln(x^a e^−x / Γ(a)): the factor both expansions share. For large a, as
// a·(ln(1 + t) − t) + ½ ln(a/2π) − stirlingError(a), t = (x − a)/a, which
// keeps its relative accuracy where a ln x − x − lnΓ(a) would cancel.
double logPrefactor(double a, double x) {
  if (a < 10) return a * std::log(x) - x - std::lgamma(a);
  return a * log1pmx((x - a) / a) + 0.5 * std::log(a / (2 * M_PI)) - stirlingError(a);
}

// P(a, x) by its series Σ x^n / (a (a+1) ... (a+n)), for x < a + 1.
double gammaSeries(double a, double x) {
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < 100000000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (term < sum * kEps) break;
  }
  return sum * std::exp(logPrefactor(a, x));
}

// Q(a, x) by its continued fraction (modified Lentz), for x ≥ a + 1.
double gammaContinuedFraction(double a, double x) {
  const double tiny = 1e-300;
  double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
  for (int i = 1; i < 100000000; ++i) {
    const double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::fabs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1 / d;
    const double step = d * c;
    h *= step;
    if (std::fabs(step - 1) < kEps) break;
  }
  return h * std::exp(logPrefactor(a, x));
}

void requireArguments(double a, double x, const char* fn) {
  if (!(a > 0) || !(x >= 0) || !std::isfinite(a))
    throw InvalidArgument(std::string(fn) + ": need a > 0 and x >= 0, got a = " + std::to_string(a) +
                          ", x = " + std::to_string(x));
}
}  // namespace

double regularizedGammaP(double a, double x) {
  requireArguments(a, x, "regularizedGammaP");
  if (x == 0) return 0;
  if (std::isinf(x)) return 1;
  return x < a + 1 ? gammaSeries(a, x) : 1 - gammaContinuedFraction(a, x);
}

double regularizedGammaQ(double a, double x) {
  requireArguments(a, x, "regularizedGammaQ");
  if (x == 0) return 1;
  if (std::isinf(x)) return 0;
  return x < a + 1 ? 1 - gammaSeries(a, x) : gammaContinuedFraction(a, x);
}

double chiSquareCdf(double x, double k) { return x <= 0 ? 0 : regularizedGammaP(k / 2, x / 2); }

namespace {
// A rough standard normal quantile (Newton on erfc): only a starting point.
double normalQuantile(double p) {
  double q = 0;
  for (int i = 0; i < 100; ++i) {
    const double f = 0.5 * std::erfc(-q / std::sqrt(2.0)) - p;
    const double pdf = std::exp(-0.5 * q * q) / std::sqrt(2 * M_PI);
    if (pdf < 1e-300) break;
    const double next = std::max(-40.0, std::min(40.0, q - f / pdf));
    if (std::fabs(next - q) < 1e-10) return next;
    q = next;
  }
  return q;
}

// Where the inversion starts (y = x/2): Wilson–Hilferty, or in the lower
// tail the leading term of the series, P(a, y) ≈ y^a / Γ(a + 1), if smaller.
double startingPoint(double p, double a) {
  const double h = 1.0 / (9.0 * a);
  double y = a * std::pow(std::max(1 - h + normalQuantile(p) * std::sqrt(h), 1e-3), 3);
  const double leading = std::exp((std::log(p) + std::lgamma(a + 1)) / a);
  if (p < 0.5 && leading < y) y = leading;
  return y;
}
}  // namespace

double chiSquareQuantile(double p, double k) {
  if (!(p > 0 && p < 1) || !(k > 0) || !std::isfinite(k))
    throw InvalidArgument("chiSquareQuantile: need 0 < p < 1 and dof > 0, got p = " + std::to_string(p) +
                          ", dof = " + std::to_string(k));
  const double a = k / 2;
  // In the tail that is small, so that the residual has no cancellation:
  // P(a, y) − p below the median, (1 − p) − Q(a, y) above it; both increase with y.
  const bool upper = p > 0.5;
  auto residual = [&](double y) { return upper ? (1 - p) - regularizedGammaQ(a, y) : regularizedGammaP(a, y) - p; };
  double y = startingPoint(p, a);
  double lo = 0, hi = std::max(2 * y, 1.0);
  while (residual(hi) < 0) lo = hi, hi *= 2;
  // Newton steps kept inside the bracket; bisection where a step leaves it.
  for (int i = 0; i < 300; ++i) {
    const double r = residual(y);
    if (r == 0) break;
    (r < 0 ? lo : hi) = y;
    const double density = std::exp(logPrefactor(a, y)) / y;  // dP/dy
    double next = y - r / density;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::fabs(next - y) <= 4 * kEps * y) return 2 * next;
    y = next;
  }
  return 2 * y;
}

}  // namespace gssm
