#pragma once
// Internal: Jacobian of g at x by central differences, step eps·max(1, |x_j|).
// Used by the Jacobian checker and by models without analytic Jacobians.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "gssm/core/rotation_blocks.h"

namespace gssm::internal {

template <class Fn>
Eigen::MatrixXd centralDifferences(Fn g, const Eigen::VectorXd& x, Eigen::Index rows, double eps = 1e-6) {
  Eigen::MatrixXd J(rows, x.size());
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double step = eps * std::max(1.0, std::abs(x[j]));
    Eigen::VectorXd xp = x, xm = x;
    xp[j] += step;
    xm[j] -= step;
    J.col(j) = (g(xp) - g(xm)) / (2 * step);
  }
  return J;
}

/// The same on the tangents (docs/DESIGN.md §12): x moved by ⊕ along each
/// tangent direction, g's values compared with g(x) by ⊖, on the rotation
/// blocks `in` of x and `out` of g's value (stacked indices at the offsets).
template <class Fn>
Eigen::MatrixXd tangentDifferences(Fn g, const Eigen::VectorXd& x, Eigen::Index rows, double eps,
                                   const std::vector<int>& in, int in_offset, const std::vector<int>& out,
                                   int out_offset) {
  if (!hasRotationIn(in, x.size(), in_offset) && !hasRotationIn(out, rows, out_offset))
    return centralDifferences(g, x, rows, eps);
  const Eigen::VectorXd g0 = g(x);
  Eigen::MatrixXd J(rows, x.size());
  Eigen::VectorXd rp, rm;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double step = eps * std::max(1.0, std::abs(x[j]));
    Eigen::VectorXd xp = x, xm = x, d = Eigen::VectorXd::Zero(x.size());
    d[j] = step;
    retractBlocks(xp, d, in, in_offset);
    retractBlocks(xm, -d, in, in_offset);
    localBlocks(g(xp), g0, rp, out, out_offset);
    localBlocks(g(xm), g0, rm, out, out_offset);
    J.col(j) = (rp - rm) / (2 * step);
  }
  return J;
}

}  // namespace gssm::internal
