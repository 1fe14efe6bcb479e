#pragma once
// Internal: the second-order terms of a factor's Hessian, for Newton steps
// (solvers/newton.h).
#include <Eigen/Core>

#include "gssm/factors/factors.h"

namespace gssm::internal {

/// Σ_j r_j ∇²r_j of factor f at x with r = r(x) held fixed: the derivative of
/// J(x)ᵀr over the factor's stacked keys, by central differences of its
/// analytic Jacobians (symmetrized).
Eigen::MatrixXd residualCurvature(const Factor& f, const Values& x, const Eigen::VectorXd& r);

}  // namespace gssm::internal
