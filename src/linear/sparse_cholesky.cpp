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

double& SparseCholesky::value(std::size_t e) { return static_cast<double*>(triplet_->x)[e]; }

Eigen::Index SparseCholesky::factorize() {
  if (dense_) {
    // H from its upper-triangle triplets (duplicates summed), then a plain
    // column Cholesky that reports the first column that is not positive.
    Eigen::MatrixXd& L = L_;
    L.setZero(n_, n_);
    const int* Ti = static_cast<const int*>(triplet_->i);
    const int* Tj = static_cast<const int*>(triplet_->j);
    const double* Tx = static_cast<const double*>(triplet_->x);
    for (std::size_t e = 0; e < count_; ++e) L(Tj[e], Ti[e]) += Tx[e];  // lower triangle: L(j, i), i <= j
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
  if (!matrix_ || slot_.size() != count_) {
    // First factorization of this pattern: let CHOLMOD assemble (sort, sum
    // duplicates), then record where each triplet entry landed.
    if (matrix_) cholmod_free_sparse(&matrix_, &common_);
    matrix_ = cholmod_triplet_to_sparse(triplet_, count_, &common_);
    if (!matrix_) throw NumericalError("CHOLMOD could not assemble the system matrix");
    const int* Ap = static_cast<const int*>(matrix_->p);
    const int* Ai = static_cast<const int*>(matrix_->i);
    const int* Ti = static_cast<const int*>(triplet_->i);
    const int* Tj = static_cast<const int*>(triplet_->j);
    slot_.resize(count_);
    for (std::size_t e = 0; e < count_; ++e) {
      const int* b = Ai + Ap[Tj[e]];
      const int* end = Ai + Ap[Tj[e] + 1];
      slot_[e] = static_cast<int>(std::lower_bound(b, end, Ti[e]) - Ai);
    }
  } else {
    // Same pattern: refill the values (a triplet→sparse conversion was 7% of
    // a million-step batch solve).
    double* Ax = static_cast<double*>(matrix_->x);
    const double* Tx = static_cast<const double*>(triplet_->x);
    std::fill(Ax, Ax + static_cast<const int*>(matrix_->p)[n_], 0.0);
    for (std::size_t e = 0; e < count_; ++e) Ax[slot_[e]] += Tx[e];
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
  const auto b = rows.begin() + colptr[static_cast<std::size_t>(j)];
  const auto e = rows.begin() + colptr[static_cast<std::size_t>(j) + 1];
  const auto it = std::lower_bound(b, e, static_cast<int>(i));
  if (it == e || *it != i) return false;
  out = values[static_cast<std::size_t>(it - rows.begin())];
  return true;
}

SparseCholesky::SelectedInverse SparseCholesky::selectedInverse() const {
  if (dense_) {  // the whole inverse: every entry is "on the pattern"
    if (!factored_) throw NumericalError("selectedInverse: nothing factored");
    const Eigen::MatrixXd Linv = L_.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(n_, n_));
    const Eigen::MatrixXd Hinv = Linv.transpose() * Linv;
    SelectedInverse S;
    S.colptr.assign(static_cast<std::size_t>(n_) + 1, 0);
    for (Eigen::Index j = 0; j < n_; ++j) {
      S.colptr[static_cast<std::size_t>(j) + 1] = S.colptr[static_cast<std::size_t>(j)] + static_cast<int>(n_ - j);
      for (Eigen::Index i = j; i < n_; ++i) {
        S.rows.push_back(static_cast<int>(i));
        S.values.push_back(Hinv(i, j));
      }
    }
    return S;
  }
  if (!factor_) throw NumericalError("selectedInverse: nothing factored");
  cholmod_common& c = const_cast<cholmod_common&>(common_);
  // A simplicial LDLᵀ copy (unit L, D) of the factor, with sorted rows.
  cholmod_factor* F = cholmod_copy_factor(factor_, &c);
  if (!F || !cholmod_change_factor(CHOLMOD_REAL, false, false, true, true, F, &c)) {
    if (F) cholmod_free_factor(&F, &c);
    throw NumericalError("selectedInverse: CHOLMOD could not convert the factor");
  }
  const int* perm = static_cast<const int*>(F->Perm);
  for (Eigen::Index k = 0; k < n_; ++k)
    if (perm && perm[k] != k) {
      cholmod_free_factor(&F, &c);
      throw NumericalError("selectedInverse: expected the natural ordering");
    }
  const int* Lp = static_cast<const int*>(F->p);
  const int* Li = static_cast<const int*>(F->i);
  const int* Lnz = static_cast<const int*>(F->nz);
  const double* Lx = static_cast<const double*>(F->x);
  SelectedInverse S;
  S.colptr.assign(static_cast<std::size_t>(n_) + 1, 0);
  for (Eigen::Index j = 0; j < n_; ++j) S.colptr[j + 1] = S.colptr[j] + Lnz[j];
  S.rows.resize(static_cast<std::size_t>(S.colptr.back()));
  S.values.assign(S.rows.size(), 0.0);
  std::vector<double> d(static_cast<std::size_t>(n_));
  std::vector<std::vector<std::pair<int, double>>> below(static_cast<std::size_t>(n_));
  for (Eigen::Index j = 0; j < n_; ++j) {
    auto& col = below[static_cast<std::size_t>(j)];
    for (int p = Lp[j]; p < Lp[j] + Lnz[j]; ++p) {
      if (Li[p] == j) d[static_cast<std::size_t>(j)] = Lx[p];
      else col.emplace_back(Li[p], Lx[p]);
    }
    std::sort(col.begin(), col.end());
    int q = S.colptr[j];
    S.rows[static_cast<std::size_t>(q++)] = static_cast<int>(j);
    for (const auto& e : col) S.rows[static_cast<std::size_t>(q++)] = e.first;
  }
  cholmod_free_factor(&F, &c);
  // Backward sweep: Σ_ij = −Σ_k Σ_ik l_kj (i > j), Σ_jj = 1/d_j − Σ_k l_kj Σ_kj.
  for (Eigen::Index j = n_ - 1; j >= 0; --j) {
    const auto& col = below[static_cast<std::size_t>(j)];
    const int base = S.colptr[j];
    for (std::size_t a = 0; a < col.size(); ++a) {
      double sum = 0;
      for (const auto& [k, lkj] : col) {
        double sik;
        if (!S.lookup(col[a].first, k, sik))
          throw NumericalError("selectedInverse: pattern is not closed (internal error)");
        sum += sik * lkj;
      }
      S.values[static_cast<std::size_t>(base) + 1 + a] = -sum;
    }
    double diag = 1.0 / d[static_cast<std::size_t>(j)];
    for (std::size_t a = 0; a < col.size(); ++a)
      diag -= col[a].second * S.values[static_cast<std::size_t>(base) + 1 + a];
    S.values[static_cast<std::size_t>(base)] = diag;
  }
  return S;
}

}  // namespace gssm::internal
