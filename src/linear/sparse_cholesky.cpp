#include "linear/sparse_cholesky.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

#include "gssm/core/error.h"

namespace gssm::internal {

namespace {
// Mean entries per column of L from which the supernodal factorization is used.
constexpr double kSupernodalColumnCount = 16;
}  // namespace

SparseCholesky::SparseCholesky() {
  cholmod_start(&common_);
  common_.nmethods = 1;
  common_.method[0].ordering = CHOLMOD_NATURAL;
  common_.postorder = 0;
  common_.final_ll = true;  // LLᵀ either way (a non-positive pivot is reported, not factored through)
  common_.print = 0;
  common_.error_handler = nullptr;
}

SparseCholesky::~SparseCholesky() {
  freeAll();
  cholmod_finish(&common_);
}

void SparseCholesky::freeAll() {
  if (solution_) cholmod_free_dense(&solution_, &common_);
  if (work_y_) cholmod_free_dense(&work_y_, &common_);
  if (work_e_) cholmod_free_dense(&work_e_, &common_);
  if (triplet_) cholmod_free_triplet(&triplet_, &common_);
  if (factor_) cholmod_free_factor(&factor_, &common_);
  if (matrix_) cholmod_free_sparse(&matrix_, &common_);
  slot_.clear();
}

void SparseCholesky::reset(Eigen::Index n, std::size_t capacity) {
  freeAll();
  n_ = n;
  count_ = 0;
  dense_ = n <= kDenseMax;
  factored_ = false;
  triplet_ = cholmod_allocate_triplet(n, n, std::max<std::size_t>(capacity, 1), 1, CHOLMOD_REAL,
                                      &common_);
  if (!triplet_) throw NumericalError("CHOLMOD could not allocate the system matrix");
}

void SparseCholesky::add(Eigen::Index i, Eigen::Index j, double v) {
  if (matrix_) throw NumericalError("SparseCholesky::add after assemble(): call reset() for a new pattern");
  if (count_ == triplet_->nzmax) {
    if (!cholmod_reallocate_triplet(2 * triplet_->nzmax, triplet_, &common_))
      throw NumericalError("CHOLMOD could not grow the system matrix");
  }
  static_cast<int*>(triplet_->i)[count_] = static_cast<int>(i);
  static_cast<int*>(triplet_->j)[count_] = static_cast<int>(j);
  static_cast<double*>(triplet_->x)[count_] = v;
  ++count_;
  triplet_->nnz = count_;
}

void SparseCholesky::assemble() {
  if (matrix_) return;
  const int* Ti = static_cast<const int*>(triplet_->i);
  const int* Tj = static_cast<const int*>(triplet_->j);
  const std::size_t count = count_;
  assembleEntries(
      [&](auto&& emit) {
        for (std::size_t e = 0; e < count; ++e) emit(Ti[e], Tj[e]);
      },
      static_cast<const double*>(triplet_->x));
  cholmod_free_triplet(&triplet_, &common_);
}

// Rows sorted within each column (stable: duplicates keep the order they
// were added, in which they are summed), then H in compressed columns and
// each entry's position. Insertion sort for the short columns of the states,
// a counting sort for the constants' long ones.
void SparseCholesky::assembleColumns(const std::vector<std::size_t>& start, std::vector<std::uint32_t>& by_column,
                                     const int* row, const double* value, int* slot) {
  const std::size_t n = static_cast<std::size_t>(n_);
  std::size_t unique = 0;
  std::vector<std::uint32_t> count, sorted;  // the long columns' counting sort
  for (std::size_t j = 0; j < n; ++j) {
    std::uint32_t* b = by_column.data() + start[j];
    std::uint32_t* e = by_column.data() + start[j + 1];
    if (e - b > 32) {
      // Stable counting sort by row (rows ≤ j): linear in the column's
      // length where a merge sort of the constants' columns (3M entries
      // each at a million steps) took 0.3 s.
      if (!std::is_sorted(b, e, [&](std::uint32_t x, std::uint32_t y) { return row[x] < row[y]; })) {
        count.assign(j + 2, 0);
        for (const std::uint32_t* p = b; p < e; ++p) ++count[static_cast<std::size_t>(row[*p]) + 1];
        for (std::size_t r = 0; r <= j; ++r) count[r + 1] += count[r];
        sorted.resize(static_cast<std::size_t>(e - b));
        for (const std::uint32_t* p = b; p < e; ++p) sorted[count[static_cast<std::size_t>(row[*p])]++] = *p;
        std::copy(sorted.begin(), sorted.end(), b);
      }
    } else {
      for (std::uint32_t* p = b + 1; p < e; ++p) {
        const std::uint32_t v = *p;
        std::uint32_t* q = p;
        for (; q > b && row[*(q - 1)] > row[v]; --q) *q = *(q - 1);
        *q = v;
      }
    }
    for (std::uint32_t* p = b; p < e; ++p)
      if (p == b || row[*p] != row[*(p - 1)]) ++unique;
  }
  matrix_ = cholmod_allocate_sparse(n, n, unique, /*sorted=*/true, /*packed=*/true, /*stype=*/1, CHOLMOD_REAL, &common_);
  if (!matrix_) throw NumericalError("CHOLMOD could not allocate the system matrix");
  int* Ap = static_cast<int*>(matrix_->p);
  int* Ai = static_cast<int*>(matrix_->i);
  double* Ax = static_cast<double*>(matrix_->x);
  // `slot` may be `row` itself: an entry's row is read before its slot
  // overwrites it, and the previous entry's row is kept aside.
  int q = -1;
  for (std::size_t j = 0; j < n; ++j) {
    Ap[j] = q + 1;
    int previous_row = -1;
    for (std::size_t p = start[j]; p < start[j + 1]; ++p) {
      const std::uint32_t e = by_column[p];
      const int r = row[e];
      if (p == start[j] || r != previous_row) {
        Ai[++q] = r;
        Ax[q] = 0.0;
      }
      previous_row = r;
      if (value) Ax[q] += value[e];
      slot[e] = q;
    }
  }
  Ap[n] = q + 1;
}

double* SparseCholesky::values() {
  assemble();
  return static_cast<double*>(matrix_->x);
}

std::size_t SparseCholesky::nonzeros() const {
  return matrix_ ? static_cast<std::size_t>(static_cast<const int*>(matrix_->p)[n_]) : 0;
}

Eigen::Index SparseCholesky::factorize() {
  assemble();
  const int* Ap = static_cast<const int*>(matrix_->p);
  const int* Ai = static_cast<const int*>(matrix_->i);
  const double* Ax = static_cast<const double*>(matrix_->x);
  if (dense_) {
    // H from its upper triangle, then a plain column Cholesky that reports
    // the first column that is not positive.
    Eigen::MatrixXd& L = L_;
    L.setZero(n_, n_);
    for (Eigen::Index j = 0; j < n_; ++j)
      for (int p = Ap[j]; p < Ap[j + 1]; ++p) L(j, Ai[p]) = Ax[p];  // lower triangle: L(j, i), i <= j
    factored_ = false;
    for (Eigen::Index j = 0; j < n_; ++j) {
      const double d = L(j, j) - L.row(j).head(j).squaredNorm();
      if (!(d > 0) || !std::isfinite(d)) return j;
      const double ljj = std::sqrt(d);
      L(j, j) = ljj;
      for (Eigen::Index i = j + 1; i < n_; ++i)
        L(i, j) = (L(i, j) - L.row(i).head(j).dot(L.row(j).head(j))) / ljj;
    }
    factored_ = true;
    return -1;
  }
  if (!factor_) {
    // Simplicial (column by column) where the factor is thin — a chain of
    // states with a few constants: 2.6× faster than supernodal on the 20k-
    // step radar, whose thin columns left BLAS-3 nothing to do; supernodal
    // where columns are long enough for dense kernels to pay.
    common_.supernodal = CHOLMOD_SIMPLICIAL;
    factor_ = cholmod_analyze(matrix_, &common_);
    if (factor_ && common_.lnz >= kSupernodalColumnCount * static_cast<double>(n_)) {
      cholmod_free_factor(&factor_, &common_);
      common_.supernodal = CHOLMOD_SUPERNODAL;
      factor_ = cholmod_analyze(matrix_, &common_);
    }
  }
  if (!factor_) throw NumericalError("CHOLMOD symbolic analysis failed");
  common_.status = CHOLMOD_OK;
  cholmod_factorize(matrix_, factor_, &common_);
  if (common_.status == CHOLMOD_NOT_POSDEF) return static_cast<Eigen::Index>(factor_->minor);
  if (common_.status < CHOLMOD_OK) throw NumericalError("CHOLMOD numeric factorization failed");
  return -1;
}

void SparseCholesky::solveInPlace(Eigen::VectorXd& b) {
  if (dense_) {  // small: as solve() does it (matrix kernels, the same rounding)
    b = solve(b);
    return;
  }
  // b's storage as CHOLMOD's right-hand side; the solution and workspace are
  // kept from call to call (at a million unknowns, fresh ones per LM step
  // were tens of MB of page faults).
  cholmod_dense B{};
  B.nrow = B.nzmax = B.d = static_cast<std::size_t>(b.size());
  B.ncol = 1;
  B.x = b.data();
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  if (!cholmod_solve2(CHOLMOD_A, factor_, &B, nullptr, &solution_, nullptr, &work_y_, &work_e_, &common_))
    throw NumericalError("CHOLMOD solve failed");
  std::memcpy(b.data(), solution_->x, sizeof(double) * static_cast<std::size_t>(b.size()));
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& B) {
  if (dense_) {
    if (!factored_) throw NumericalError("solve: nothing factored");
    Eigen::MatrixXd Y = L_.triangularView<Eigen::Lower>().solve(B);
    L_.transpose().triangularView<Eigen::Upper>().solveInPlace(Y);
    return Y;
  }
  cholmod_dense* b = cholmod_allocate_dense(B.rows(), B.cols(), B.rows(), CHOLMOD_REAL, &common_);
  std::memcpy(b->x, B.data(), sizeof(double) * B.size());
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, factor_, b, &common_);
  cholmod_free_dense(&b, &common_);
  if (!x) throw NumericalError("CHOLMOD solve failed");
  Eigen::MatrixXd X = Eigen::Map<Eigen::MatrixXd>(static_cast<double*>(x->x), B.rows(), B.cols());
  cholmod_free_dense(&x, &common_);
  return X;
}

bool SparseCholesky::SelectedInverse::lookup(Eigen::Index i, Eigen::Index j, double& out) const {
  if (i < j) std::swap(i, j);
  const int* b = rows.data() + colptr[static_cast<std::size_t>(j)];
  const int* e = rows.data() + colptr[static_cast<std::size_t>(j) + 1];
  const int row = static_cast<int>(i);
  const int* it = e - b <= 16 ? std::find(b, e, row) : std::lower_bound(b, e, row);  // a state's column is short
  if (it == e || *it != row) return false;
  out = values[static_cast<std::size_t>(it - rows.data())];
  return true;
}

namespace {
using SelectedInverse = SparseCholesky::SelectedInverse;

// The whole inverse of LLᵀ (a dense factor): every entry is "on the pattern".
SelectedInverse denseSelectedInverse(const Eigen::MatrixXd& L) {
  const Eigen::Index n = L.rows();
  const Eigen::MatrixXd Linv = L.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(n, n));
  const Eigen::MatrixXd Hinv = Linv.transpose() * Linv;
  SelectedInverse S;
  S.colptr.assign(static_cast<std::size_t>(n) + 1, 0);
  for (Eigen::Index j = 0; j < n; ++j) {
    S.colptr[static_cast<std::size_t>(j) + 1] = S.colptr[static_cast<std::size_t>(j)] + static_cast<int>(n - j);
    for (Eigen::Index i = j; i < n; ++i) {
      S.rows.push_back(static_cast<int>(i));
      S.values.push_back(Hinv(i, j));
    }
  }
  return S;
}

// S on the simplicial factor F's pattern, each column's rows sorted with the
// diagonal first; l holds L's entries in the same places (l_jj at the
// diagonal's).
void patternOfFactor(const cholmod_factor* F, Eigen::Index n, SelectedInverse& S, std::vector<double>& l) {
  const int* Lp = static_cast<const int*>(F->p);
  const int* Li = static_cast<const int*>(F->i);
  const int* Lnz = static_cast<const int*>(F->nz);
  const double* Lx = static_cast<const double*>(F->x);
  S.colptr.assign(static_cast<std::size_t>(n) + 1, 0);
  for (Eigen::Index j = 0; j < n; ++j) S.colptr[j + 1] = S.colptr[j] + Lnz[j];
  S.rows.resize(static_cast<std::size_t>(S.colptr.back()));
  S.values.assign(S.rows.size(), 0.0);
  l.resize(S.rows.size());
  for (Eigen::Index j = 0; j < n; ++j) {
    const int q0 = S.colptr[j];
    for (int p = Lp[j], q = q0; p < Lp[j] + Lnz[j]; ++p, ++q) {
      S.rows[static_cast<std::size_t>(q)] = Li[p];
      l[static_cast<std::size_t>(q)] = Lx[p];
    }
    // CHOLMOD keeps the diagonal first and the rows increasing; sort anyway
    // (insertion: a column has a few entries) so nothing rests on that.
    auto rank = [&](int q) { return S.rows[q] == j ? -1 : S.rows[q]; };
    for (int q = q0 + 1; q < S.colptr[j + 1]; ++q)
      for (int t = q; t > q0 && rank(t - 1) > rank(t); --t) {
        std::swap(S.rows[t], S.rows[t - 1]);
        std::swap(l[t], l[t - 1]);
      }
    if (S.rows[q0] != j) throw NumericalError("selectedInverse: the factor has no diagonal entry (internal error)");
  }
}

// Backward sweep with L = LLᵀ's factor (Takahashi):
//   Σ_ij = −(1/l_jj) Σ_k Σ_ik l_kj  (i > j),   Σ_jj = (1/l_jj − Σ_k l_kj Σ_kj) / l_jj,
// k over column j's rows below the diagonal.
void takahashiSweep(Eigen::Index n, SelectedInverse& S, const std::vector<double>& l) {
  for (Eigen::Index j = n - 1; j >= 0; --j) {
    const int base = S.colptr[j], end = S.colptr[j + 1];
    const double ljj = l[static_cast<std::size_t>(base)];
    for (int a = base + 1; a < end; ++a) {
      double sum = 0;
      for (int b = base + 1; b < end; ++b) {
        double sik;
        if (!S.lookup(S.rows[a], S.rows[b], sik))
          throw NumericalError("selectedInverse: pattern is not closed (internal error)");
        sum += sik * l[static_cast<std::size_t>(b)];
      }
      S.values[static_cast<std::size_t>(a)] = -sum / ljj;
    }
    double diag = 1.0 / ljj;
    for (int a = base + 1; a < end; ++a) diag -= l[static_cast<std::size_t>(a)] * S.values[static_cast<std::size_t>(a)];
    S.values[static_cast<std::size_t>(base)] = diag / ljj;
  }
}
}  // namespace

SparseCholesky::SelectedInverse SparseCholesky::selectedInverse() const {
  if (dense_) {
    if (!factored_) throw NumericalError("selectedInverse: nothing factored");
    return denseSelectedInverse(L_);
  }
  if (!factor_) throw NumericalError("selectedInverse: nothing factored");
  cholmod_common& c = const_cast<cholmod_common&>(common_);
  // A simplicial LLᵀ factor: the one factorize() made (read in place), or a
  // simplicial LLᵀ copy of a supernodal one.
  cholmod_factor* copy = nullptr;
  const cholmod_factor* F = factor_;
  if (factor_->is_super || !factor_->is_ll) {
    copy = cholmod_copy_factor(factor_, &c);
    if (!copy || !cholmod_change_factor(CHOLMOD_REAL, true, false, true, true, copy, &c)) {
      if (copy) cholmod_free_factor(&copy, &c);
      throw NumericalError("selectedInverse: CHOLMOD could not convert the factor");
    }
    F = copy;
  }
  struct FreeCopy {
    cholmod_factor*& f;
    cholmod_common& c;
    ~FreeCopy() {
      if (f) cholmod_free_factor(&f, &c);
    }
  } free_copy{copy, c};
  const int* perm = static_cast<const int*>(F->Perm);
  for (Eigen::Index k = 0; k < n_; ++k)
    if (perm && perm[k] != k) throw NumericalError("selectedInverse: expected the natural ordering");
  SelectedInverse S;
  std::vector<double> l;
  patternOfFactor(F, n_, S, l);
  takahashiSweep(n_, S, l);
  return S;
}

}  // namespace gssm::internal
