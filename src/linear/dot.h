#pragma once
// Internal: the dot product of two contiguous runs in four partial sums:
// independent additions instead of one chain through a single sum (the
// compiler may not reorder a floating-point sum itself), for the inner
// loops of the envelope Cholesky and of a clique's Householder reflections.
#include <cstddef>

namespace gssm::internal {

inline double dot4(const double* a, const double* b, std::ptrdiff_t n) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  std::ptrdiff_t k = 0;
  for (; k + 4 <= n; k += 4) {
    s0 += a[k] * b[k];
    s1 += a[k + 1] * b[k + 1];
    s2 += a[k + 2] * b[k + 2];
    s3 += a[k + 3] * b[k + 3];
  }
  for (; k < n; ++k) s0 += a[k] * b[k];
  return (s0 + s1) + (s2 + s3);
}

}  // namespace gssm::internal
