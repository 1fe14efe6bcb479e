#pragma once
// Internal: the Cholesky factorization H = UᵀU of a symmetric positive-definite
// matrix held by its envelope (profile): column j of the upper triangle from
// its first nonzero row first[j] down to the diagonal, contiguous. In the
// natural order U fills only within the envelope, so a GSSM chain — states
// in time order, each coupled to the next, and the constants last — needs
// no symbolic analysis, no sorting and no index per entry: a banded block
// plus the constants' dense border, about 4 words a step for the radar
// against CHOLMOD's ~23 (entry lists, compressed columns, a separate factor).
// Factorization, solves and the selected inverse (H⁻¹ on the envelope) are
// linear in the envelope's size times its row width.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace gssm::internal {

class EnvelopeCholesky {
 public:
  /// An n × n pattern whose column j starts at row first[j] (≤ j); H's
  /// values are zeroed.
  void setPattern(std::vector<int> first);
  Eigen::Index size() const { return static_cast<Eigen::Index>(first_.size()); }
  /// Entries of the envelope (upper triangle, diagonal included).
  std::size_t entries() const { return h_.size(); }
  /// Where H(i, j) lives in values() (i ≤ j, first[j] ≤ i): one load, the
  /// batch solver asks it for every entry of every factor's JᵀJ.
  std::size_t position(Eigen::Index i, Eigen::Index j) const {
    return static_cast<std::size_t>(base_[static_cast<std::size_t>(j)] + i);
  }
  std::size_t diagonal(Eigen::Index j) const { return position(j, j); }
  /// H's upper envelope by columns; the caller fills it before factorize()
  /// (and again after selectedInverse(), which takes its storage).
  double* values() {
    inverse_ = false;
    return h_.data();
  }

  /// Factors H as it stands in values() (left untouched). Returns -1 on
  /// success, else the first column whose pivot is not positive and finite.
  Eigen::Index factorize();
  /// Factors H = JᵀJ from J's rows instead, without forming H: a QR of J
  /// by Givens rotations, row by row, whose R is U (R's pattern is the
  /// envelope's; rows best given in the order of their first column, a
  /// chain's time order: each then rotates only through the band above
  /// it). Forming H squares J's condition number: a stiff chain beside a
  /// constant it nearly hides (an INS's IMU factors and its lever arm) loses
  /// digits of that constant's variance in H, which no factorization of H
  /// gets back (docs/DESIGN.md §5). beginRows(); addRow() for each row;
  /// finishRows() returns -1, or the first column J leaves without a pivot.
  /// values() is left as it was.
  void beginRows();
  /// One row of J: `count` entries at ascending columns, each column's
  /// envelope reaching the row's first column.
  void addRow(const int* columns, const double* values, int count);
  Eigen::Index finishRows();
  /// Solves H x = b in place.
  void solveInPlace(Eigen::VectorXd& b) const { solveInPlace(b.data()); }
  /// Solves H X = B (n × m).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B) const;

  /// Computes H⁻¹ on the envelope (Takahashi's recurrences with U's rows:
  /// every entry the envelope holds, which includes U's pattern) for the
  /// rows from `down_to` on, in H's storage: values() must be refilled
  /// before the next factorize(). The sweep runs from the last row up; a
  /// later call with a smaller `down_to` resumes it.
  void selectedInverse(Eigen::Index down_to = 0);
  /// H⁻¹(i, j) if (i, j) lies in the envelope and the sweep reached
  /// min(i, j) (after selectedInverse()).
  bool inverseEntry(Eigen::Index i, Eigen::Index j, double& out) const;
  /// The block of H⁻¹ on columns [first, first + size) as WᵀW with
  /// W = U⁻ᵀE (E: those unit columns; H⁻¹ = U⁻¹U⁻ᵀ): one forward
  /// substitution per column from row `first` down, no sweep — for a small
  /// block near the top, which the sweep reaches only at its end.
  Eigen::MatrixXd inverseBlock(Eigen::Index first, Eigen::Index size) const;
  /// The same for any columns (H⁻¹ among them, in the order given): one
  /// forward substitution per column from its own row down.
  Eigen::MatrixXd inverseColumns(const std::vector<Eigen::Index>& columns) const;
  /// Work of inverseBlock(first, size) and of the sweep from where it stands
  /// up to row `first`, in multiply-adds (estimates, to choose between them).
  double inverseBlockWork(Eigen::Index first, Eigen::Index size) const;
  double sweepWork(Eigen::Index first) const;
  /// The first row the selected inverse holds (size() before any sweep).
  Eigen::Index inverseFrom() const { return inverse_ ? inverse_from_ : size(); }

 private:
  std::vector<int> first_;
  std::vector<std::ptrdiff_t> base_;  // column j's entry for row i at base_[j] + i (i from first_[j] to j)
  std::vector<double> h_, u_;  // H (or H⁻¹ on the envelope after selectedInverse()); U, 1/U(j, j) on its diagonal
  void solveInPlace(double* x) const;  // x: n entries
  // U(i, j), i < j; 1/U(j, j) (false if not positive definite there): the
  // dots from row `from` on, `known` the part of the sum before it.
  void offDiagonal(std::ptrdiff_t i, std::ptrdiff_t j, std::ptrdiff_t from = 0, double known = 0.0);
  bool pivot(std::ptrdiff_t j, std::ptrdiff_t from = 0, double known = 0.0);
  void inverseRow(Eigen::Index i, const std::vector<int>& row, std::vector<double>& u_row);
  Eigen::Index panel(std::ptrdiff_t j, std::ptrdiff_t end);
  // A panel this wide over this many rows above it takes their Gram matrix.
  static constexpr std::ptrdiff_t kGramColumns = 8, kGramRows = 32;
  static constexpr std::ptrdiff_t kPanelGroup = 4;  // a panel's columns taken together down the rows above it
  // The row QR's state: each row's columns (CSR: the columns j ≥ k whose
  // envelope reaches row k), which pivot rows hold a row yet, the row
  // being merged (dense) and its nonzero columns still to visit (a heap).
  std::vector<std::ptrdiff_t> row_begin_;
  std::vector<int> row_columns_;
  std::vector<char> row_started_, queued_;
  std::vector<double> work_;
  std::vector<int> pending_;
  void rotateInto(std::ptrdiff_t k);
  // inverse_: h_ holds H⁻¹ on the envelope, not H (values() must refill it).
  bool factored_ = false, inverse_ = false;
  // The selected inverse's sweep: rows from inverse_from_ on are done; the
  // columns of the next row up and a buffer for its U entries.
  Eigen::Index inverse_from_ = 0;
  std::vector<int> sweep_columns_;
  std::vector<double> sweep_u_;
};

}  // namespace gssm::internal
