#pragma once
// One helper every model's test calls: analytic Jacobians of f and h against
// central differences at several random points (manif's common_tester idea).
#include <gtest/gtest.h>

#include <functional>
#include <random>

#include "gssm/model/model.h"

namespace gssm::testing {

/// Draws a point (x_c, x_b, u) at which to check the Jacobians.
struct JacobianPoint {
  Eigen::VectorXd xc, xb, u;
  double dt;
};
using PointSampler = std::function<JacobianPoint(std::mt19937&)>;

inline void expectJacobiansMatchDifferences(const Model& model, const PointSampler& sample,
                                            int points = 20, double tol = 1e-6) {
  std::mt19937 rng(12345);
  for (int i = 0; i < points; ++i) {
    const JacobianPoint p = sample(rng);
    const JacobianCheck c = checkJacobians(model, p.xc, p.xb, p.u, p.dt);
    EXPECT_TRUE(c.ok(tol)) << model.name() << " at point " << i << ": worst entry " << c.worst
                           << " (relative error " << c.max_rel_error << ")";
  }
}

inline Eigen::VectorXd uniformVector(std::mt19937& rng, int n, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

}  // namespace gssm::testing
