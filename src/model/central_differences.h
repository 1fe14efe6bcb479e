#pragma once
// Internal: Jacobian of g at x by central differences, step eps·max(1, |x_j|).
// Used by the Jacobian checker and by models without analytic Jacobians.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

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

}  // namespace gssm::internal
