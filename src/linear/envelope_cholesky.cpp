#include "linear/envelope_cholesky.h"

#include <algorithm>
#include <cmath>

#include "gssm/core/error.h"
#include "linear/dot.h"

namespace gssm::internal {

// Dots in four interleaved partial sums (linear/dot.h): a constants'
// column is dotted with every column before it (~70 entries in a paper
// window), and one running sum is a chain of dependent additions, 4× slower.
// Below four entries (a band) the sum is in order, as before.

void EnvelopeCholesky::setPattern(std::vector<int> first) {
  first_ = std::move(first);
  const std::size_t n = first_.size();
  base_.resize(n);
  std::ptrdiff_t size = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const int f = first_[j];
    if (f < 0 || f > static_cast<int>(j)) throw NumericalError("EnvelopeCholesky: column's first row out of range");
    base_[j] = size - f;
    size += static_cast<std::ptrdiff_t>(j) - f + 1;
  }
  h_.assign(static_cast<std::size_t>(size), 0.0);
  u_.clear();
  factored_ = inverse_ = false;
}

Eigen::Index EnvelopeCholesky::factorize() {
  if (inverse_) throw NumericalError("EnvelopeCholesky: H was replaced by its inverse; refill values() first");
  factored_ = false;
  u_.resize(h_.size());
  const auto n = static_cast<std::ptrdiff_t>(first_.size());
  // Column by column (H = UᵀU, U upper): U(i, j) for i < j from the columns
  // before, dotted over the rows both hold; then the pivot. The diagonal is
  // held as 1/U(j, j): a multiply, not a divide, in the chain of dependent
  // steps down a column. Columns that start at the same row (a panel: the
  // constants, a state's components) take the rows above the panel row by
  // row across the panel: U(i, j) waits for U(i − 1, j), so one column at
  // a time is a chain of dependent dots, while the panel's columns at one
  // row are independent (the same arithmetic, entry by entry).
  for (std::ptrdiff_t j = 0; j < n;) {
    std::ptrdiff_t end = j + 1;
    while (end < n && first_[static_cast<std::size_t>(end)] == first_[static_cast<std::size_t>(j)]) ++end;
    // Four columns at a time: enough independent dots, and few enough
    // streams down long columns for the prefetcher (all 25 constants at
    // once stalled on memory over a 10⁵-state batch).
    const std::ptrdiff_t f = first_[static_cast<std::size_t>(j)];
    for (std::ptrdiff_t c0 = j; c0 < end; c0 += kPanelGroup)
      for (std::ptrdiff_t i = f; i < j; ++i)
        for (std::ptrdiff_t c = c0; c < std::min(c0 + kPanelGroup, end); ++c) offDiagonal(i, c);
    const Eigen::Index bad = panel(j, end);
    if (bad >= 0) return bad;
    j = end;
  }
  factored_ = true;
  return -1;
}

// The panel [j, end)'s own rows, column by column; the first column whose
// pivot fails, or -1. A wide panel over many rows takes the part of every
// dot that runs over the rows above it (U's rows f … j − 1 of its columns,
// A) from their Gram matrix AᵀA, one blocked product: a GSSM's constants
// are ~25 columns over every state's rows, and their ~300 dots, each a pass
// over columns of 10⁵ entries, were a factorization's main cost (memory
// bound). A narrow one dots from its first row.
Eigen::Index EnvelopeCholesky::panel(std::ptrdiff_t j, std::ptrdiff_t end) {
  const std::ptrdiff_t f = first_[static_cast<std::size_t>(j)], w = end - j;
  const bool by_gram = j - f >= kGramRows && w >= kGramColumns;
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(by_gram ? w : 0, by_gram ? w : 0);
  if (by_gram) {
    Eigen::MatrixXd above(j - f, w);
    for (std::ptrdiff_t a = 0; a < w; ++a)
      above.col(a) = Eigen::Map<const Eigen::VectorXd>(u_.data() + base_[static_cast<std::size_t>(j + a)] + f, j - f);
    gram.selfadjointView<Eigen::Lower>().rankUpdate(above.transpose());
  }
  const std::ptrdiff_t from = by_gram ? j : f;  // where each dot starts
  for (std::ptrdiff_t a = 0; a < w; ++a) {
    for (std::ptrdiff_t b = 0; b < a; ++b) offDiagonal(j + b, j + a, from, by_gram ? gram(a, b) : 0.0);
    if (!pivot(j + a, from, by_gram ? gram(a, a) : 0.0)) return j + a;
  }
  return -1;
}

// U(i, j), i < j: (H(i, j) − known − Σ_k U(k, i) U(k, j)) / U(i, i), the
// sum over the rows both columns hold from `from` on (known: the part
// before it, already summed).
inline void EnvelopeCholesky::offDiagonal(std::ptrdiff_t i, std::ptrdiff_t j, std::ptrdiff_t from, double known) {
  const std::ptrdiff_t fi = first_[static_cast<std::size_t>(i)], fj = first_[static_cast<std::size_t>(j)];
  const double* ui = u_.data() + base_[static_cast<std::size_t>(i)];
  double* uj = u_.data() + base_[static_cast<std::size_t>(j)];
  const std::ptrdiff_t lo = std::max({fi, fj, from});
  uj[i] = (h_[static_cast<std::size_t>(base_[static_cast<std::size_t>(j)] + i)] - known - dot4(ui + lo, uj + lo, i - lo)) * ui[i];
}

// 1/U(j, j) from column j's entries above it (from `from` on, `known` the
// part before); false if H(j, j) − Σ U(k, j)² is not positive and finite.
inline bool EnvelopeCholesky::pivot(std::ptrdiff_t j, std::ptrdiff_t from, double known) {
  const std::ptrdiff_t lo = std::max<std::ptrdiff_t>(first_[static_cast<std::size_t>(j)], from);
  double* uj = u_.data() + base_[static_cast<std::size_t>(j)];
  const double d = h_[static_cast<std::size_t>(base_[static_cast<std::size_t>(j)] + j)] - known - dot4(uj + lo, uj + lo, j - lo);
  if (!(d > 0) || !std::isfinite(d)) return false;
  uj[j] = 1.0 / std::sqrt(d);
  return true;
}

void EnvelopeCholesky::solveInPlace(double* x) const {
  if (!factored_) throw NumericalError("EnvelopeCholesky: solve before a successful factorize()");
  const auto n = static_cast<std::ptrdiff_t>(first_.size());
  for (std::ptrdiff_t j = 0; j < n; ++j) {  // Uᵀ y = b
    const std::ptrdiff_t fj = first_[static_cast<std::size_t>(j)];
    const double* uj = u_.data() + base_[static_cast<std::size_t>(j)];
    x[j] = (x[j] - dot4(uj + fj, x + fj, j - fj)) * uj[j];  // uj[j] = 1/U(j, j)
  }
  for (std::ptrdiff_t j = n - 1; j >= 0; --j) {  // U x = y
    const std::ptrdiff_t fj = first_[static_cast<std::size_t>(j)];
    const double* uj = u_.data() + base_[static_cast<std::size_t>(j)];
    x[j] *= uj[j];
    const double xj = x[j];
    for (std::ptrdiff_t i = fj; i < j; ++i) x[i] -= uj[i] * xj;
  }
}

Eigen::MatrixXd EnvelopeCholesky::solve(const Eigen::MatrixXd& B) const {
  Eigen::MatrixXd X = B;  // column-major: each column solved where it lies
  for (Eigen::Index c = 0; c < X.cols(); ++c) solveInPlace(X.col(c).data());
  return X;
}

void EnvelopeCholesky::selectedInverse(Eigen::Index down_to) {
  if (!factored_) throw NumericalError("EnvelopeCholesky: selected inverse before a successful factorize()");
  const auto n = static_cast<Eigen::Index>(first_.size());
  if (!inverse_) {  // a fresh sweep from the last row
    inverse_ = true;
    inverse_from_ = n;
    sweep_columns_.clear();
  }
  // H⁻¹ takes H's storage (the batch solver refills H before it factors
  // again): no fresh memory for it. From the last row up (H⁻¹ = U⁻¹U⁻ᵀ, so
  // U Z = U⁻ᵀ, lower triangular):
  //   Z(i, j) = −(1/U_ii) Σ_k U(i, k) Z(k, j)   for j in row i's columns,
  //   Z(i, i) = (1/U_ii)(1/U_ii − Σ_k U(i, k) Z(k, i)),
  // k over row i's columns — the columns k > i whose envelope reaches row i,
  // kept in increasing order as the sweep moves up (k = i + 1 joins, a
  // column leaves above its first row); every Z(k, j) needed lies in the
  // envelope (both reach row i) and below row i: computed already. The sweep
  // stops at `down_to` and resumes there: the last variables' block (a
  // window's newest state and the constants) costs only its own rows.
  std::vector<int>& row = sweep_columns_;
  std::vector<double>& u_row = sweep_u_;
  for (Eigen::Index i = inverse_from_ - 1; i >= down_to && i >= 0; --i) {
    const auto ii = static_cast<std::size_t>(i);
    row.erase(std::remove_if(row.begin(), row.end(), [&](int k) { return first_[static_cast<std::size_t>(k)] > i; }),
              row.end());
    if (i + 1 < n && first_[ii + 1] <= i) row.insert(row.begin(), static_cast<int>(i + 1));
    inverseRow(i, row, u_row);
    inverse_from_ = i;
  }
}

// Row i of Z = H⁻¹ on the envelope from the rows below it (row: row i's
// columns, ascending). Z(k, j) for k ≤ j is held in column j, for k > j in
// column k: the sum splits there, in the same order.
void EnvelopeCholesky::inverseRow(Eigen::Index i, const std::vector<int>& row, std::vector<double>& u_row) {
  double* z = h_.data();
  const std::ptrdiff_t* base = base_.data();
  const std::size_t m = row.size();
  u_row.resize(m);
  for (std::size_t a = 0; a < m; ++a) u_row[a] = u_[static_cast<std::size_t>(base[row[a]] + i)];  // U(i, k)
  const double inv = u_[diagonal(i)];  // 1/U(i, i)
  for (std::size_t b = m; b-- > 0;) {  // Z(i, j) reads Z(k, j), k > i only
    const int j = row[b];
    const double* zj = z + base[j];
    double s = 0;
    for (std::size_t a = 0; a <= b; ++a) s += u_row[a] * zj[row[a]];
    for (std::size_t a = b + 1; a < m; ++a) s += u_row[a] * z[base[row[a]] + j];
    z[base[j] + i] = -s * inv;
  }
  double s = 0;
  for (std::size_t a = 0; a < m; ++a) s += u_row[a] * z[base[row[a]] + i];
  z[diagonal(i)] = (inv - s) * inv;
}

Eigen::MatrixXd EnvelopeCholesky::inverseBlock(Eigen::Index first, Eigen::Index size) const {
  std::vector<Eigen::Index> columns(static_cast<std::size_t>(size));
  for (Eigen::Index c = 0; c < size; ++c) columns[static_cast<std::size_t>(c)] = first + c;
  return inverseColumns(columns);
}

Eigen::MatrixXd EnvelopeCholesky::inverseColumns(const std::vector<Eigen::Index>& columns) const {
  if (!factored_) throw NumericalError("EnvelopeCholesky: inverse block before a successful factorize()");
  const auto n = static_cast<std::ptrdiff_t>(first_.size());
  const auto size = static_cast<Eigen::Index>(columns.size());
  const std::ptrdiff_t first = size ? *std::min_element(columns.begin(), columns.end()) : 0;
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(n - first, size);  // rows first … n − 1 of U⁻ᵀE
  for (Eigen::Index c = 0; c < size; ++c) {
    const std::ptrdiff_t from = columns[static_cast<std::size_t>(c)];
    double* w = W.col(c).data() - first;  // w[j]: row j
    w[from] = 1.0;
    for (std::ptrdiff_t j = from; j < n; ++j) {  // Uᵀw = e: rows above `from` are 0
      const std::ptrdiff_t lo = std::max<std::ptrdiff_t>(first_[static_cast<std::size_t>(j)], from);
      const double* uj = u_.data() + base_[static_cast<std::size_t>(j)];
      w[j] = (w[j] - dot4(uj + lo, w + lo, j - lo)) * uj[j];
    }
  }
  const Eigen::MatrixXd block = W.transpose() * W;
  return 0.5 * (block + block.transpose());
}

double EnvelopeCholesky::inverseBlockWork(Eigen::Index first, Eigen::Index size) const {
  const auto f = static_cast<std::size_t>(first);
  const double below = static_cast<double>(h_.size()) - static_cast<double>(base_[f] + first_[f]);
  return static_cast<double>(size) * below;
}

double EnvelopeCholesky::sweepWork(Eigen::Index first) const {
  const double width = static_cast<double>(h_.size()) / static_cast<double>(std::max<Eigen::Index>(size(), 1));
  return static_cast<double>(std::max<Eigen::Index>(inverseFrom() - first, 0)) * width * width;
}

bool EnvelopeCholesky::inverseEntry(Eigen::Index i, Eigen::Index j, double& out) const {
  if (i > j) std::swap(i, j);
  if (!inverse_ || i < inverse_from_ || i < 0 || j >= size() || i < first_[static_cast<std::size_t>(j)]) return false;
  out = h_[position(i, j)];
  return true;
}

}  // namespace gssm::internal
