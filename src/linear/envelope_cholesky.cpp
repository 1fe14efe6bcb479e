#include "linear/envelope_cholesky.h"

#include <algorithm>
#include <cmath>

#include "gssm/core/error.h"

namespace gssm::internal {

namespace {
// Σ a[k] b[k] over [0, n), in order (a column segment: a few entries).
inline double dot(const double* a, const double* b, std::ptrdiff_t n) {
  double s = 0;
  for (std::ptrdiff_t k = 0; k < n; ++k) s += a[k] * b[k];
  return s;
}
}  // namespace

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
  // steps down a constants' column (2× faster there).
  const int* first = first_.data();
  const std::ptrdiff_t* base = base_.data();
  double* u = u_.data();
  const double* h = h_.data();
  for (std::ptrdiff_t j = 0; j < n; ++j) {
    const std::ptrdiff_t fj = first[j];
    double* uj = u + base[j];  // uj[i] = U(i, j)
    const double* hj = h + base[j];
    for (std::ptrdiff_t i = fj; i < j; ++i) {
      const std::ptrdiff_t fi = first[i];
      const double* ui = u + base[i];
      const std::ptrdiff_t lo = fi > fj ? fi : fj;
      uj[i] = (hj[i] - dot(ui + lo, uj + lo, i - lo)) * ui[i];
    }
    const double d = hj[j] - dot(uj + fj, uj + fj, j - fj);
    if (!(d > 0) || !std::isfinite(d)) return j;
    uj[j] = 1.0 / std::sqrt(d);
  }
  factored_ = true;
  return -1;
}

void EnvelopeCholesky::solveInPlace(double* x) const {
  if (!factored_) throw NumericalError("EnvelopeCholesky: solve before a successful factorize()");
  const auto n = static_cast<std::ptrdiff_t>(first_.size());
  for (std::ptrdiff_t j = 0; j < n; ++j) {  // Uᵀ y = b
    const std::ptrdiff_t fj = first_[static_cast<std::size_t>(j)];
    const double* uj = u_.data() + base_[static_cast<std::size_t>(j)];
    x[j] = (x[j] - dot(uj + fj, x + fj, j - fj)) * uj[j];  // uj[j] = 1/U(j, j)
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

void EnvelopeCholesky::selectedInverse() {
  if (!factored_) throw NumericalError("EnvelopeCholesky: selected inverse before a successful factorize()");
  const std::size_t n = first_.size();
  // H⁻¹ takes H's storage (the batch solver refills H before it factors
  // again): no fresh memory for it.
  std::vector<double>& z = h_;
  auto zAt = [&](Eigen::Index a, Eigen::Index b) -> double {  // Z(a, b) = Z(b, a), in the envelope
    return a <= b ? z[position(a, b)] : z[position(b, a)];
  };
  // From the last row up (H⁻¹ = U⁻¹U⁻ᵀ, so U Z = U⁻ᵀ, lower triangular):
  //   Z(i, j) = −(1/U_ii) Σ_k U(i, k) Z(k, j)   for j in row i's columns,
  //   Z(i, i) = (1/U_ii)(1/U_ii − Σ_k U(i, k) Z(k, i)),
  // k over row i's columns — the columns k > i whose envelope reaches row i,
  // kept in increasing order as the sweep moves up (k = i + 1 joins, a
  // column leaves above its first row); every Z(k, j) needed lies in the
  // envelope (both reach row i) and below row i: computed already.
  std::vector<int> row;  // row i's columns
  for (std::size_t ii = n; ii-- > 0;) {
    const auto i = static_cast<Eigen::Index>(ii);
    row.erase(std::remove_if(row.begin(), row.end(), [&](int k) { return first_[static_cast<std::size_t>(k)] > i; }),
              row.end());
    if (ii + 1 < n && first_[ii + 1] <= i) row.insert(row.begin(), static_cast<int>(ii + 1));
    const double inv = u_[diagonal(i)];  // 1/U(i, i)
    const std::size_t m = row.size();
    for (std::size_t b = m; b-- > 0;) {  // Z(i, j) reads Z(k, j), k > i only
      const Eigen::Index j = row[b];
      double s = 0;
      for (std::size_t a = 0; a < m; ++a) s += u_[position(i, row[a])] * zAt(row[a], j);
      z[position(i, j)] = -s * inv;
    }
    double s = 0;
    for (std::size_t a = 0; a < m; ++a) s += u_[position(i, row[a])] * z[position(i, row[a])];
    z[diagonal(i)] = (inv - s) * inv;
  }
  inverse_ = true;
}

bool EnvelopeCholesky::inverseEntry(Eigen::Index i, Eigen::Index j, double& out) const {
  if (i > j) std::swap(i, j);
  if (!inverse_ || i < 0 || j >= size() || i < first_[static_cast<std::size_t>(j)]) return false;
  out = h_[position(i, j)];
  return true;
}

}  // namespace gssm::internal
