#pragma once
// Internal: the small dense algebra of BatchSolver::stepAfterChange(): the
// removed and added factors' normal equations at the factored point on the
// few variables they reach, and from them the low-rank correction E that
// turns the Schur complement S of the dropped variables into the changed
// graph's information matrix (S + E; batch_solver.h).
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <vector>

#include "gssm/solvers/batch_solver.h"

namespace gssm::internal {

/// The change's factors linearized at x_f on the local columns of the
/// variables they reach: the dropped ones (O) first, then the others (T).
struct LocalChange {
  std::vector<Key> keys;             ///< O's keys, then T's
  std::vector<Eigen::Index> offset;  ///< each key's first local column; then m
  std::size_t dropped = 0;           ///< how many of `keys` are O's
  Eigen::MatrixXd H_removed, H_added;  ///< JᵀJ, m × m
  Eigen::VectorXd g_removed, g_added;  ///< Jᵀr
  double cost_removed = 0, cost_added = 0;
  Eigen::VectorXd r;                   ///< a factor's residual (reused)
  std::vector<Eigen::MatrixXd> J;      ///< and Jacobian blocks
  Eigen::Index droppedColumns() const { return offset[dropped]; }
  Eigen::Index columns() const { return offset.back(); }
};

/// A Cholesky factorization of A that succeeded with every pivot clear of
/// rounding (relative to A's largest diagonal entry).
bool clearlyPositiveDefinite(const Eigen::LLT<Eigen::MatrixXd>& llt, const Eigen::MatrixXd& A);

/// Linearizes the change's factors at x_f (robust losses reweighted there)
/// into `c` (its buffers reused from call to call). InvalidArgument for an
/// added factor on a dropped variable or a key x_f lacks.
void linearizeChange(const GraphChange& change, const Values& x_f, LocalChange& c);

/// On T's columns: E = H_r,TO·H_r,OO⁻¹·H_r,OT − H_r,TT + H_a,TT and the
/// gradient change g_a,T − g_r,T. NumericalError naming the dropped
/// variables when the removed factors do not determine them (H_r,OO not
/// positive definite).
struct LowRankCorrection {
  Eigen::MatrixXd E;
  Eigen::VectorXd gradient_change;
};
void lowRankCorrection(const LocalChange& c, LowRankCorrection& out);

}  // namespace gssm::internal
