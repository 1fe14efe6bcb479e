#pragma once
// One helper every model's test calls: analytic Jacobians of f and h against
// central differences at several random points (manif's common_tester idea).
#include <gtest/gtest.h>

#include <algorithm>
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

/// A channel that names its constants (MeasurementChannel::constants): h
/// neither moves with any other constant (each perturbed by 1e-3 and by 1)
/// nor has a nonzero Jacobian entry outside them (a channel that reads known
/// values gets made-up ones, 0.3·(j + 1) − 1).
inline void expectChannelsReachOnlyTheirConstants(const Model& model, const JacobianPoint& p, int point) {
  for (int c = 0; c < model.numChannels(); ++c) {
    const std::vector<int>& used = model.channel(c).constants;
    if (used.empty()) continue;
    Eigen::VectorXd known(model.channel(c).regressors);
    for (Eigen::Index j = 0; j < known.size(); ++j) known[j] = 0.3 * static_cast<double>(j + 1) - 1;
    Eigen::MatrixXd J_xc, J_xb;
    const Eigen::VectorXd y = model.hWith(c, known, p.xc, p.xb, &J_xc, &J_xb);
    for (int j = 0; j < model.dims().nb; ++j) {
      if (std::find(used.begin(), used.end(), j) != used.end()) continue;
      EXPECT_TRUE((J_xb.col(j).array() == 0.0).all())
          << model.name() << " channel '" << model.channel(c).name << "' at point " << point << ": ∂h/∂x_b[" << j << "]";
      for (double step : {1e-3, 1.0}) {
        Eigen::VectorXd xb = p.xb;
        xb[j] += step;
        EXPECT_EQ(model.hWith(c, known, p.xc, xb), y)
            << model.name() << " channel '" << model.channel(c).name << "' at point " << point << " moves with x_b[" << j << "]";
      }
    }
  }
}

inline void expectJacobiansMatchDifferences(const Model& model, const PointSampler& sample,
                                            int points = 20, double tol = 1e-6) {
  std::mt19937 rng(12345);
  for (int i = 0; i < points; ++i) {
    const JacobianPoint p = sample(rng);
    const JacobianCheck c = checkJacobians(model, p.xc, p.xb, p.u, p.dt);
    EXPECT_TRUE(c.ok(tol)) << model.name() << " at point " << i << ": worst entry " << c.worst
                           << " (relative error " << c.max_rel_error << ")";
    expectChannelsReachOnlyTheirConstants(model, p, i);
  }
}

inline Eigen::VectorXd uniformVector(std::mt19937& rng, int n, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

}  // namespace gssm::testing
