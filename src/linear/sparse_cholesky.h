#pragma once
// Internal: a symmetric positive-definite sparse system H x = b factored by
// CHOLMOD (LLᵀ — simplicial where the factor is thin, supernodal where its
// columns are long — so an indefinite or singular H is detected and the
// failing column reported). H is given by its upper triangle as
// triplets whose pattern is fixed after the first analyze(). Systems of at
// most kDenseMax unknowns (a paper window, a start-up batch) are factored
// densely instead: CHOLMOD's symbolic analysis and supernodal machinery cost
// far more than a 34 × 34 Cholesky.
#include <Eigen/Core>
#include <cholmod.h>
#include <vector>

namespace gssm::internal {

class SparseCholesky {
 public:
  static constexpr Eigen::Index kDenseMax = 64;
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  /// Starts a new pattern of size n with room for `capacity` upper-triangle
  /// entries; drops any earlier factorization.
  void reset(Eigen::Index n, std::size_t capacity);
  /// Appends H(i, j) += v (i <= j required). Duplicates are summed.
  void add(Eigen::Index i, Eigen::Index j, double v);
  /// Overwrites the values of entry e (in the order they were added).
  double& value(std::size_t e);
  std::size_t entries() const { return count_; }

  /// Factors the current values (analyzing the pattern the first time,
  /// natural ordering: callers order variables so that fill stays small).
  /// Returns -1 on success, else the column at which H is not positive definite.
  Eigen::Index factorize();
  /// Solves H X = B for a dense right-hand side (n × m).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B);

  /// Entries of H⁻¹ on the sparsity pattern of the factor L (Takahashi's
  /// selected inversion): every diagonal entry and every (i, j) that L
  /// couples. Costs O(Σ_j |col_j(L)|²), linear in n for a banded-plus-border
  /// pattern such as the GSSM's.
  struct SelectedInverse {
    std::vector<int> colptr, rows;  // lower triangle, rows sorted, diagonal first
    std::vector<double> values;
    /// H⁻¹(i, j) if (i, j) is on the pattern.
    bool lookup(Eigen::Index i, Eigen::Index j, double& out) const;
  };
  SelectedInverse selectedInverse() const;
  Eigen::Index size() const { return n_; }

 private:
  void freeAll();
  cholmod_common common_;
  cholmod_triplet* triplet_ = nullptr;
  cholmod_factor* factor_ = nullptr;
  // H in compressed columns, assembled from the triplets once per pattern;
  // later factorizations refill its values through slot_ (entry → position).
  cholmod_sparse* matrix_ = nullptr;
  std::vector<int> slot_;
  Eigen::Index n_ = 0;
  std::size_t count_ = 0;
  bool dense_ = false;
  Eigen::MatrixXd L_;  // dense path: the lower Cholesky factor
  bool factored_ = false;
};

}  // namespace gssm::internal
