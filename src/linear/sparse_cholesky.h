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
#include <cstdint>
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
  std::size_t entries() const { return count_; }

  /// Sums the entries added so far (in the order added) into H's upper
  /// triangle in compressed columns, rows sorted. From then on H's values
  /// live in values(), which a caller that refills H at every iteration
  /// overwrites in place through slot(): no entries to sort or sum again.
  /// factorize() assembles when needed; reset() starts a new pattern.
  void assemble();
  /// reset(n) + add(i, j, 0) for every entry + assemble(), without holding
  /// the entries: each(emit) calls emit(i, j) (i <= j) for every entry, in
  /// the same order both times it is called.
  template <class ForEachEntry>
  void assemblePattern(Eigen::Index n, ForEachEntry&& each);
  /// Where entry e (in the order added) landed in values(), after assemble().
  int slot(std::size_t e) const { return slot_[e]; }
  const int* slots() const { return slot_.data(); }
  double* values();
  std::size_t nonzeros() const;

  /// Factors H as it stands in values() (assembling and analyzing the
  /// pattern the first time, natural ordering: callers order variables so
  /// that fill stays small).
  /// Returns -1 on success, else the column at which H is not positive definite.
  Eigen::Index factorize();
  /// Solves H x = b in place (no allocation after the first call).
  void solveInPlace(Eigen::VectorXd& b);
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
  template <class ForEachEntry>
  void assembleEntries(ForEachEntry&& each, const double* value);
  void assembleColumns(const std::vector<std::size_t>& start, std::vector<std::uint32_t>& by_column, const int* row,
                       const double* value, int* slot);
  cholmod_common common_;
  cholmod_triplet* triplet_ = nullptr;
  cholmod_factor* factor_ = nullptr;
  // H in compressed columns, assembled from the triplets once per pattern;
  // slot_: entry → position in its values.
  cholmod_sparse* matrix_ = nullptr;
  std::vector<int> slot_;
  cholmod_dense* solution_ = nullptr;  // solveInPlace's result and workspace, reused
  cholmod_dense* work_y_ = nullptr;
  cholmod_dense* work_e_ = nullptr;
  Eigen::Index n_ = 0;
  std::size_t count_ = 0;
  bool dense_ = false;
  Eigen::MatrixXd L_;  // dense path: the lower Cholesky factor
  bool factored_ = false;
};

template <class ForEachEntry>
void SparseCholesky::assemblePattern(Eigen::Index n, ForEachEntry&& each) {
  reset(n, 0);
  assembleEntries(each, nullptr);
  if (triplet_) cholmod_free_triplet(&triplet_, &common_);
}

// Counts the entries per column, lists them column by column with their
// rows, and hands them to assembleColumns, whose slots overwrite the rows.
template <class ForEachEntry>
void SparseCholesky::assembleEntries(ForEachEntry&& each, const double* value) {
  std::vector<std::size_t> start(static_cast<std::size_t>(n_) + 1, 0);
  each([&](Eigen::Index, Eigen::Index j) { ++start[static_cast<std::size_t>(j) + 1]; });
  for (std::size_t j = 0; j < static_cast<std::size_t>(n_); ++j) start[j + 1] += start[j];
  count_ = start.back();
  std::vector<int> row(count_);
  std::vector<std::uint32_t> by_column(count_);
  std::vector<std::size_t> next(start.begin(), start.end() - 1);
  std::uint32_t e = 0;
  each([&](Eigen::Index i, Eigen::Index j) {
    row[e] = static_cast<int>(i);
    by_column[next[static_cast<std::size_t>(j)]++] = e++;
  });
  assembleColumns(start, by_column, row.data(), value, row.data());  // each entry's row becomes its slot
  slot_ = std::move(row);
}

}  // namespace gssm::internal
