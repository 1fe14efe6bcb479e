#pragma once
// The χ² distribution for consistency tests (NEES, NIS: docs/DESIGN.md §1):
// its CDF through the regularized incomplete gamma function and its
// quantile by a safeguarded Newton inversion, to ~1e-12 relative for
// 1 ≤ k ≤ 10⁶ and 1e-300 ≤ p ≤ 1 − 1e-16.

namespace gssm {

/// P(a, x) = γ(a, x)/Γ(a) and Q(a, x) = 1 − P(a, x), each computed directly
/// (no cancellation in either tail). a > 0, x ≥ 0.
double regularizedGammaP(double a, double x);
double regularizedGammaQ(double a, double x);

/// P(χ²_k ≤ x).
double chiSquareCdf(double x, double k);
/// The x with P(χ²_k ≤ x) = p, 0 < p < 1, k > 0; InvalidArgument otherwise.
double chiSquareQuantile(double p, double k);

}  // namespace gssm
