#pragma once
// Internal: full Newton steps for ½Σ‖r_i(x)‖² (docs/DESIGN.md §5, eq. 5).
// Gauss–Newton drops the second-order terms Σ_j r_ij ∇²r_ij of the Hessian;
// where residuals stay large at the optimum (the radar start-up, whose prior
// is 143σ off) it converges only linearly, with a rate near 1. A few Newton
// steps with those terms restored finish the job quadratically. The terms
// come from central differences of the factors' analytic Jacobians, so the
// gradient, and hence the fixed point, stays exact.
#include <Eigen/Core>
#include <vector>

#include "gssm/factors/factors.h"
#include "linear/sparse_cholesky.h"
#include "solvers/curvature.h"

namespace gssm::internal {

/// H = Σ J_iᵀJ_i + Σ curvature_i and g = Σ J_iᵀ r_i over the variables of a
/// Values (columns in its order, so states by step and constants last:
/// banded plus a border, no fill), solved by sparse Cholesky.
class NewtonSystem {
 public:
  explicit NewtonSystem(const Values& layout);
  /// One factor's blocks; `curvature` (stacked over `keys`) may be null.
  void add(const std::vector<Key>& keys, const Eigen::VectorXd& r, const std::vector<Eigen::MatrixXd>& J,
           const Eigen::MatrixXd* curvature);
  /// δ = −H⁻¹g in the layout's order; false when H is not positive definite
  /// (not near a minimum: keep the Gauss–Newton answer).
  bool solve(Eigen::VectorXd& delta);
  /// max |g|.
  double gradientNorm() const { return g_.size() ? g_.lpNorm<Eigen::Infinity>() : 0.0; }

 private:
  const Values& layout_;
  std::vector<Eigen::Index> offset_;  // by Values position
  Eigen::VectorXd g_;
  SparseCholesky chol_;
};

/// Where x ⊕ δ is not x + δ (docs/DESIGN.md §12): each variable's rotation
/// blocks, by its position in a Values, as its factors declare them.
struct Retraction {
  std::vector<Factor::Rotations> by_position;  ///< empty: x + δ everywhere
  bool trivial() const { return by_position.empty(); }
  static Retraction of(const FactorGraph& graph, const Values& x);
};

/// x ⊕ δ for δ stacked in x's order (+ without a retraction).
Values addStep(const Values& x, const Eigen::VectorXd& delta, const Retraction* retraction = nullptr);
/// out = x ⊕ δ in place; out holds x's keys and sizes (no allocation) and may be x itself.
void addStep(const Values& x, const Eigen::VectorXd& delta, Values& out, const Retraction* retraction = nullptr);
/// x's vectors stacked in its order into `flat` (resized to x.dim()).
void flatten(const Values& x, Eigen::VectorXd& flat);
/// The inverse: x's vectors overwritten from `flat` (same sizes: no allocation).
void unflatten(const Eigen::VectorXd& flat, Values& x);
/// ‖x‖ over every stacked component (the LM step test's scale).
double norm(const Values& x);

}  // namespace gssm::internal
