// EnvelopeCholesky's factor from J's rows: a Givens QR whose R is U
// (envelope_cholesky.h, beginRows). R(k, j) is stored where U(k, j) is, at
// base_[j] + k; while rows come in, R(k, k) holds itself, and finishRows()
// turns it into 1/U(k, k) as factorize() leaves it.
#include <algorithm>
#include <cmath>
#include <functional>

#include "gssm/core/error.h"
#include "linear/envelope_cholesky.h"

namespace gssm::internal {

void EnvelopeCholesky::beginRows() {
  const auto n = static_cast<std::ptrdiff_t>(first_.size());
  u_.assign(h_.size(), 0.0);
  factored_ = inverse_ = false;
  // Row k's columns: every j ≥ k with first[j] ≤ k (k = j: the diagonal).
  row_begin_.assign(static_cast<std::size_t>(n) + 1, 0);
  for (std::ptrdiff_t j = 0; j < n; ++j)
    for (std::ptrdiff_t k = first_[static_cast<std::size_t>(j)]; k <= j; ++k) ++row_begin_[static_cast<std::size_t>(k) + 1];
  for (std::ptrdiff_t k = 0; k < n; ++k) row_begin_[static_cast<std::size_t>(k) + 1] += row_begin_[static_cast<std::size_t>(k)];
  row_columns_.resize(static_cast<std::size_t>(row_begin_.back()));
  std::vector<std::ptrdiff_t> next(row_begin_.begin(), row_begin_.end() - 1);
  for (std::ptrdiff_t j = 0; j < n; ++j)  // ascending j: each row's columns come out sorted
    for (std::ptrdiff_t k = first_[static_cast<std::size_t>(j)]; k <= j; ++k)
      row_columns_[static_cast<std::size_t>(next[static_cast<std::size_t>(k)]++)] = static_cast<int>(j);
  row_started_.assign(static_cast<std::size_t>(n), 0);
  queued_.assign(static_cast<std::size_t>(n), 0);
  work_.assign(static_cast<std::size_t>(n), 0.0);
  pending_.clear();
}

// The row in work_ meets pivot row k: stored there if the row is the
// first to reach it, else rotated against it (zeroing work_[k]), its new
// nonzero columns queued.
void EnvelopeCholesky::rotateInto(std::ptrdiff_t k) {
  const auto kk = static_cast<std::size_t>(k);
  const int* col = row_columns_.data() + row_begin_[kk];
  const int* end = row_columns_.data() + row_begin_[kk + 1];
  double* w = work_.data();
  if (!row_started_[kk]) {
    row_started_[kk] = 1;
    const double sign = w[k] < 0 ? -1.0 : 1.0;  // a positive diagonal, as U's
    for (; col != end; ++col) {
      u_[static_cast<std::size_t>(base_[static_cast<std::size_t>(*col)] + k)] = sign * w[*col];
      w[*col] = 0.0;
      queued_[static_cast<std::size_t>(*col)] = 0;
    }
    for (int j : pending_) {  // every nonzero left lay on row k's columns: stored
      if (w[j] != 0.0) throw NumericalError("EnvelopeCholesky: a row left the envelope (internal error)");
      queued_[static_cast<std::size_t>(j)] = 0;
    }
    pending_.clear();
    return;
  }
  double& rkk = u_[static_cast<std::size_t>(base_[kk] + k)];
  const double r = std::hypot(rkk, w[k]), c = rkk / r, s = w[k] / r;
  rkk = r;
  w[k] = 0.0;
  for (++col; col != end; ++col) {
    double& rkj = u_[static_cast<std::size_t>(base_[static_cast<std::size_t>(*col)] + k)];
    const double a = rkj, b = w[*col];
    rkj = c * a + s * b;
    w[*col] = c * b - s * a;
    if (w[*col] != 0.0 && !queued_[static_cast<std::size_t>(*col)]) {
      queued_[static_cast<std::size_t>(*col)] = 1;
      pending_.push_back(*col);
      std::push_heap(pending_.begin(), pending_.end(), std::greater<int>());
    }
  }
}

void EnvelopeCholesky::addRow(const int* columns, const double* values, int count) {
  if (row_started_.size() != first_.size()) throw NumericalError("EnvelopeCholesky: addRow() before beginRows()");
  for (int a = 0; a < count; ++a) {  // checked before any is placed: a refused row leaves R as it was
    const int j = columns[a];
    if (j < 0 || j >= static_cast<int>(first_.size()) || first_[static_cast<std::size_t>(j)] > columns[0] ||
        (a > 0 && j <= columns[a - 1]))
      throw NumericalError("EnvelopeCholesky: a row's columns must ascend inside the envelope (internal error)");
  }
  for (int a = 0; a < count; ++a) {
    const int j = columns[a];
    if (values[a] == 0.0) continue;
    work_[static_cast<std::size_t>(j)] = values[a];
    queued_[static_cast<std::size_t>(j)] = 1;
    pending_.push_back(j);
  }
  std::make_heap(pending_.begin(), pending_.end(), std::greater<int>());
  while (!pending_.empty()) {  // the lowest nonzero column next: its pivot row
    std::pop_heap(pending_.begin(), pending_.end(), std::greater<int>());
    const int k = pending_.back();
    pending_.pop_back();
    queued_[static_cast<std::size_t>(k)] = 0;
    if (work_[static_cast<std::size_t>(k)] != 0.0) rotateInto(k);
  }
}

Eigen::Index EnvelopeCholesky::finishRows() {
  const auto n = static_cast<std::ptrdiff_t>(first_.size());
  for (std::ptrdiff_t k = 0; k < n; ++k) {
    double& d = u_[static_cast<std::size_t>(base_[static_cast<std::size_t>(k)] + k)];
    if (!row_started_[static_cast<std::size_t>(k)] || !(d > 0) || !std::isfinite(d)) return k;
    d = 1.0 / d;
  }
  factored_ = true;
  return -1;
}

}  // namespace gssm::internal
