#pragma once
// Internal: the one loop that scatters a factor's Gauss–Newton blocks JᵀJ
// into the upper triangle of a sparse symmetric matrix (the batch solver's
// information matrix, the Newton system's Hessian).
#include <Eigen/Core>
#include <vector>

namespace gssm::internal {

/// Calls emit(row, col, a, i, b, j) for every upper-triangle entry
/// (row ≤ col) of the blocks of `count` variables, variable a occupying
/// columns offs[a] … offs[a] + cols(a) − 1. Same order on every call for the
/// same shapes, so callers may address entries by their running index: a
/// pattern laid out once from the shapes is refilled from the Jacobians.
template <class Cols, class Emit>
void forEachUpperEntry(const Eigen::Index* offs, std::size_t count, Cols&& cols, Emit&& emit) {
  for (std::size_t a = 0; a < count; ++a)
    for (std::size_t b = 0; b < count; ++b) {
      if (offs[a] > offs[b]) continue;
      for (Eigen::Index j = 0; j < cols(b); ++j)
        for (Eigen::Index i = 0; i < cols(a); ++i) {
          const Eigen::Index gi = offs[a] + i, gj = offs[b] + j;
          if (gi > gj) continue;  // diagonal block: keep its upper half
          emit(gi, gj, a, i, b, j);
        }
    }
}

/// Calls emit(row, col, v, a, i, b, j) for every upper-triangle entry of
/// JᵀJ, where block J[a] occupies columns offs[a]… and
/// v = J[a].col(i)·J[b].col(j) (forEachUpperEntry's order; summed row by
/// row: a residual has a few rows, too few for a vectorized dot to pay).
template <class Emit>
void forEachUpperJtJ(const Eigen::Index* offs, const std::vector<Eigen::MatrixXd>& J, Emit&& emit) {
  if (J.empty()) return;
  const Eigen::Index m = J[0].rows();
  forEachUpperEntry(offs, J.size(), [&](std::size_t a) { return J[a].cols(); },
                    [&](Eigen::Index gi, Eigen::Index gj, std::size_t a, Eigen::Index i, std::size_t b, Eigen::Index j) {
                      const double* ca = J[a].data() + i * m;
                      const double* cb = J[b].data() + j * m;
                      double v = 0;
                      for (Eigen::Index r = 0; r < m; ++r) v += ca[r] * cb[r];
                      emit(gi, gj, v, a, i, b, j);
                    });
}

}  // namespace gssm::internal
