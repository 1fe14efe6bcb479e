#include "linear/sparse_cholesky.h"

#include <cstring>

#include "gssm/error.h"

namespace gssm::internal {

SparseCholesky::SparseCholesky() {
  cholmod_start(&common_);
  common_.nmethods = 1;
  common_.method[0].ordering = CHOLMOD_NATURAL;
  common_.postorder = 0;
  common_.supernodal = CHOLMOD_SUPERNODAL;
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
}

void SparseCholesky::reset(Eigen::Index n, std::size_t capacity) {
  freeAll();
  n_ = n;
  count_ = 0;
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
  cholmod_sparse* A = cholmod_triplet_to_sparse(triplet_, count_, &common_);
  if (!A) throw NumericalError("CHOLMOD could not assemble the system matrix");
  if (!factor_) factor_ = cholmod_analyze(A, &common_);
  if (!factor_) {
    cholmod_free_sparse(&A, &common_);
    throw NumericalError("CHOLMOD symbolic analysis failed");
  }
  common_.status = CHOLMOD_OK;
  cholmod_factorize(A, factor_, &common_);
  cholmod_free_sparse(&A, &common_);
  if (common_.status == CHOLMOD_NOT_POSDEF) return static_cast<Eigen::Index>(factor_->minor);
  if (common_.status < CHOLMOD_OK) throw NumericalError("CHOLMOD numeric factorization failed");
  return -1;
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& B) {
  cholmod_dense* b = cholmod_allocate_dense(B.rows(), B.cols(), B.rows(), CHOLMOD_REAL, &common_);
  std::memcpy(b->x, B.data(), sizeof(double) * B.size());
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, factor_, b, &common_);
  cholmod_free_dense(&b, &common_);
  if (!x) throw NumericalError("CHOLMOD solve failed");
  Eigen::MatrixXd X = Eigen::Map<Eigen::MatrixXd>(static_cast<double*>(x->x), B.rows(), B.cols());
  cholmod_free_dense(&x, &common_);
  return X;
}

}  // namespace gssm::internal
