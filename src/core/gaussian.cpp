#include "gssm/core/gaussian.h"

#include <Eigen/Cholesky>
#include <memory>
#include <sstream>

#include "gssm/core/error.h"

namespace gssm {

void requireVector(const Eigen::VectorXd& v, Eigen::Index n, const std::string& what) {
  if (v.size() != n) {
    std::ostringstream os;
    os << what << ": expected " << n << " entries, got " << v.size();
    throw InvalidArgument(os.str());
  }
  for (Eigen::Index i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) {
      std::ostringstream os;
      os << what << ": entry " << i << " is " << v[i] << " (must be finite)";
      throw InvalidArgument(os.str());
    }
}

namespace {
// requireCovariance's checks; returns the Cholesky factor L they computed
// (a diagonal covariance, a window's re-prior, needs no factorization: L is
// the square roots, what the factorization would give bit for bit).
Eigen::MatrixXd checkedCholeskyFactor(const Eigen::MatrixXd& m, Eigen::Index n, const std::string& what) {
  if (m.rows() != n || m.cols() != n) {
    std::ostringstream os;
    os << what << ": expected a " << n << "x" << n << " covariance, got " << m.rows() << "x"
       << m.cols();
    throw InvalidArgument(os.str());
  }
  if (!m.allFinite()) throw InvalidArgument(what + ": covariance has a NaN or infinite entry");
  const double scale = std::max(1.0, m.cwiseAbs().maxCoeff());
  if ((m - m.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale)
    throw InvalidArgument(what + ": covariance is not symmetric");
  const Eigen::MatrixXd off_diagonal = m - Eigen::MatrixXd(m.diagonal().asDiagonal());
  bool ok = true;
  Eigen::MatrixXd L;
  if ((off_diagonal.array() == 0.0).all()) {
    ok = (m.diagonal().array() > 0).all();
    L = m.diagonal().cwiseSqrt().asDiagonal();
  } else {
    Eigen::LLT<Eigen::MatrixXd> llt(m);
    ok = llt.info() == Eigen::Success;
    L = llt.matrixL();
  }
  if (!ok) {
    std::ostringstream os;
    os << what << ": covariance is not positive definite (diagonal: "
       << m.diagonal().transpose()
       << "); every variance must be > 0 and the matrix full rank";
    throw NumericalError(os.str());
  }
  return L;
}
}  // namespace

void requireCovariance(const Eigen::MatrixXd& m, Eigen::Index n, const std::string& what) {
  checkedCholeskyFactor(m, n, what);
}

GaussianNoise::GaussianNoise() {
  static const Data* const empty = new Data();  // never released: its count never reaches 0
  empty->refs.fetch_add(1, std::memory_order_relaxed);
  data_ = empty;
}

GaussianNoise::GaussianNoise(const Eigen::MatrixXd& covariance, const std::string& what) {
  auto d = std::make_unique<Data>();
  d->L = checkedCholeskyFactor(covariance, covariance.rows(), what);  // one factorization for the checks and L
  d->covariance = covariance;
  const Eigen::Index n = d->L.rows();
  d->diagonal = n <= 1 || (d->L - Eigen::MatrixXd(d->L.diagonal().asDiagonal())).cwiseAbs().maxCoeff() == 0.0;
  d->inverse_diagonal = d->L.diagonal().cwiseInverse();
  data_ = d.release();
}

// A diagonal L (independent noise, the common case) scales row by row by
// 1/L(i, i): without a general-size triangular solve's overhead (6% of a
// million-step batch solve on 1×1 blocks), and a multiply where a divide
// was (a range's 30 Jacobian entries: a quarter of its linearization). A
// full L solves, skipping a block of exact zeros (a motion model's block on
// constants it does not use), which it would leave zero.
void GaussianNoise::whitenInPlace(Eigen::VectorXd& v) const {
  if (data_->diagonal) v.array() *= data_->inverse_diagonal.array();
  else data_->L.triangularView<Eigen::Lower>().solveInPlace(v);
}

void GaussianNoise::whitenInPlace(Eigen::MatrixXd& m) const {
  if (data_->diagonal) {
    // A scalar measurement's Jacobian (1 × n): one contiguous multiply (a
    // row of a dynamic matrix is strided to Eigen, so not vectorized)
    if (m.rows() == 1) m *= data_->inverse_diagonal[0];
    else m.array().colwise() *= data_->inverse_diagonal.array();
  } else if (!(m.array() == 0.0).all()) {
    data_->L.triangularView<Eigen::Lower>().solveInPlace(m);
  }
}

Eigen::VectorXd GaussianNoise::whiten(const Eigen::VectorXd& v) const {
  Eigen::VectorXd out = v;
  whitenInPlace(out);
  return out;
}

}  // namespace gssm
