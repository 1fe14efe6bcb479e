#pragma once
// Internal: the one loop that scatters a factor's Gauss–Newton blocks JᵀJ
// into the upper triangle of a sparse symmetric matrix (the batch solver's
// information matrix, the Newton system's Hessian).
#include <Eigen/Core>
#include <algorithm>
#include <utility>
#include <vector>

namespace gssm::internal {

/// A factor's Jacobian columns flattened in key order (variable a's
/// component i after all of variable a−1's): each one's column of H and,
/// once gathered from the Jacobian blocks, its entries, side by side. Kept
/// by the caller from factor to factor, so it allocates only for the widest.
struct FactorColumns {
  std::vector<Eigen::Index> global;  ///< column of H
  std::vector<double> entries;       ///< the Jacobian, rows × size() column-major
  /// After gather: the columns with a nonzero entry, ascending (a range's
  /// Jacobian reaches 4 of its 30 columns: the pose's three and one bias).
  std::vector<std::size_t> nonzero;
  /// After gather, with more than one row: the rows [first, last) outside
  /// which column p is zero (a prior's identity Jacobian: one row each).
  std::vector<std::pair<Eigen::Index, Eigen::Index>> span;
  Eigen::Index rows = 0;
  bool ascending = true;  ///< global columns strictly increase (a factor's keys in Key order)
  std::size_t size() const { return size_; }

  /// The columns of `count` variables, variable a at columns offs[a] …
  /// offs[a] + dim(a) − 1 (no entries: a pattern's layout).
  template <class Dim>
  void place(const Eigen::Index* offs, std::size_t count, Dim&& dim) {
    start();
    for (std::size_t a = 0; a < count; ++a)
      for (Eigen::Index i = 0, d = dim(a); i < d; ++i) push(offs[a] + i);
  }
  /// The columns of J's blocks, block a at offs[a], with their entries, and
  /// which of them hold a nonzero (branch-free: which columns of a range's
  /// 30 are nonzero changes from link to link). With `used` (one entry per
  /// block, nullptr: all its columns), only the listed columns of a block
  /// are taken: the factor says the others are zero everywhere (a range's
  /// own bias and the scale of 25 constants).
  void gather(const Eigen::Index* offs, const std::vector<Eigen::MatrixXd>& J,
              const std::vector<int>* const* used = nullptr) {
    rows = J.empty() ? 0 : J[0].rows();
    std::size_t total = 0;
    for (std::size_t a = 0; a < J.size(); ++a)
      total += used && used[a] ? used[a]->size() : static_cast<std::size_t>(J[a].cols());
    if (global.size() < total) global.resize(total);
    if (entries.size() < static_cast<std::size_t>(rows) * total) entries.resize(static_cast<std::size_t>(rows) * total);
    nonzero.resize(total);
    if (rows > 1) span.resize(total);
    size_ = total;
    ascending = true;
    double* out = entries.data();
    std::size_t p = 0, count = 0;
    Eigen::Index last = -1;
    auto take = [&](Eigen::Index column, const double* in) {  // the next gathered column
      if (column <= last) ascending = false;  // a repeated column takes the general loop
      last = column;
      global[p] = column;
      bool any = false;
      for (Eigen::Index r = 0; r < rows; ++r) {
        any |= in[r] != 0.0;
        *out++ = in[r];
      }
      if (rows > 1) {
        Eigen::Index lo = 0, hi = rows;
        while (lo < hi && in[lo] == 0.0) ++lo;
        while (hi > lo && in[hi - 1] == 0.0) --hi;
        span[p] = {lo, hi};
      }
      nonzero[count] = p++;
      count += any;
    };
    for (std::size_t a = 0; a < J.size(); ++a) {
      const std::vector<int>* list = used ? used[a] : nullptr;
      const Eigen::Index cols = list ? static_cast<Eigen::Index>(list->size()) : J[a].cols();
      for (Eigen::Index i = 0; i < cols; ++i) {
        const Eigen::Index c = list ? (*list)[static_cast<std::size_t>(i)] : i;
        take(offs[a] + c, J[a].data() + c * rows);
      }
    }
    nonzero.resize(count);
  }
  /// Column p's entries.
  const double* column(std::size_t p) const { return entries.data() + static_cast<Eigen::Index>(p) * rows; }
  /// Column p dotted with a `rows`-vector, over rows [lo, hi) (all by default).
  double dot(std::size_t p, const double* other, Eigen::Index lo = 0, Eigen::Index hi = -1) const {
    const double* a = column(p);
    if (rows == 1) return a[0] * other[0];  // a scalar residual: most factors of a 1-D sensor
    double v = 0;
    for (Eigen::Index r = lo, end = hi < 0 ? rows : hi; r < end; ++r) v += a[r] * other[r];
    return v;
  }

 private:
  void start() {
    size_ = 0;
    ascending = true;
  }
  void push(Eigen::Index column) {
    if (size_ > 0 && column <= global[size_ - 1]) ascending = false;  // a repeated column takes the general loop
    if (size_ == global.size()) global.push_back(column);
    else global[size_] = column;
    ++size_;
  }
  std::size_t size_ = 0;
};

/// Calls emit(p, q) for every pair of the factor's columns whose entry
/// (global[p], global[q]) lies in the upper triangle: JᵀJ's entries. Same
/// order on every call for the same columns, so callers may address entries
/// by their running index: a pattern laid out once from the shapes is
/// refilled from the Jacobians.
template <class Emit>
void forEachUpperPair(const FactorColumns& c, Emit&& emit) {
  const std::size_t n = c.size();
  if (c.ascending) {  // the common case, without a comparison per pair
    for (std::size_t q = 0; q < n; ++q)
      for (std::size_t p = 0; p <= q; ++p) emit(p, q);
    return;
  }
  const Eigen::Index* g = c.global.data();
  for (std::size_t q = 0; q < n; ++q)
    for (std::size_t p = 0; p < n; ++p)
      if (g[p] <= g[q]) emit(p, q);
}

/// Calls emit(row, col, v, p, q) for every upper-triangle entry of JᵀJ,
/// v = column p · column q (forEachUpperPair's order; summed row by row: a
/// residual has a few rows, too few for a vectorized dot to pay).
template <class Emit>
void forEachUpperJtJ(const FactorColumns& c, Emit&& emit) {
  forEachUpperPair(c, [&](std::size_t p, std::size_t q) {
    emit(c.global[p], c.global[q], c.dot(p, c.column(q)), p, q);
  });
}

/// A factor's whole contribution to Jᵀr and JᵀJ over its gathered nonzero
/// columns, in one pass: with the residual r (rows entries; nullptr: none)
/// first grad(column of H, column p · r) for every nonzero column, then
/// emit(row, col, v, p, q) for forEachUpperJtJ's entries among them. The
/// entries left out are exact zeros, and so are those of two columns whose
/// nonzero rows do not meet (the same sums where it emits: only zero terms
/// are left out; for callers that address entries by position, not by
/// running index).
template <class Grad, class Emit>
void forEachNonzeroGradientAndUpperJtJ(const FactorColumns& c, const double* r, Grad&& grad, Emit&& emit) {
  const std::size_t* nz = c.nonzero.data();
  const std::size_t n = c.nonzero.size();
  constexpr std::size_t kLocal = 16;
  if (c.rows == 1 && c.ascending && n <= kLocal) {
    // A scalar residual (most factors): its values in locals, which the
    // caller's stores into g and H cannot alias, so none is read twice.
    double v[kLocal];
    Eigen::Index g[kLocal];
    for (std::size_t a = 0; a < n; ++a) v[a] = c.entries[nz[a]], g[a] = c.global[nz[a]];
    if (r)
      for (std::size_t a = 0; a < n; ++a) grad(g[a], v[a] * r[0]);
    for (std::size_t b = 0; b < n; ++b)
      for (std::size_t a = 0; a <= b; ++a) emit(g[a], g[b], v[a] * v[b], nz[a], nz[b]);
    return;
  }
  if (r)
    for (std::size_t a = 0; a < n; ++a) grad(c.global[nz[a]], c.dot(nz[a], r));
  for (std::size_t b = 0; b < n; ++b)
    for (std::size_t a = 0; a < (c.ascending ? b + 1 : n); ++a) {  // ascending: p ≤ q exactly when a ≤ b
      const std::size_t p = nz[a], q = nz[b];
      if (!c.ascending && c.global[p] > c.global[q]) continue;
      if (c.rows == 1) {
        emit(c.global[p], c.global[q], c.entries[p] * c.entries[q], p, q);
        continue;
      }
      const Eigen::Index lo = std::max(c.span[p].first, c.span[q].first), hi = std::min(c.span[p].second, c.span[q].second);
      if (lo >= hi) continue;  // no row holds both
      emit(c.global[p], c.global[q], c.dot(p, c.column(q), lo, hi), p, q);
    }
}

/// forEachNonzeroGradientAndUpperJtJ's JᵀJ entries alone.
template <class Emit>
void forEachNonzeroUpperJtJ(const FactorColumns& c, Emit&& emit) {
  forEachNonzeroGradientAndUpperJtJ(c, nullptr, [](Eigen::Index, double) {}, emit);
}

}  // namespace gssm::internal
