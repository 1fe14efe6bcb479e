#pragma once
// Internal: the one loop that scatters a factor's Gauss–Newton blocks JᵀJ
// into the upper triangle of a sparse symmetric matrix (the batch solver's
// information matrix, the Newton system's Hessian).
#include <Eigen/Core>
#include <vector>

namespace gssm::internal {

/// Calls emit(row, col, v, a, i, b, j) for every upper-triangle entry
/// (row ≤ col) of JᵀJ, where block J[a] occupies columns offs[a]… and
/// v = J[a].col(i)·J[b].col(j). Same order on every call for the same
/// shapes, so callers may address entries by their running index.
template <class Emit>
void forEachUpperJtJ(const std::vector<Eigen::Index>& offs, const std::vector<Eigen::MatrixXd>& J, Emit&& emit) {
  for (std::size_t a = 0; a < J.size(); ++a)
    for (std::size_t b = 0; b < J.size(); ++b) {
      if (offs[a] > offs[b]) continue;
      // entry by entry: no temporary on this hot path
      for (Eigen::Index j = 0; j < J[b].cols(); ++j)
        for (Eigen::Index i = 0; i < J[a].cols(); ++i) {
          const Eigen::Index gi = offs[a] + i, gj = offs[b] + j;
          if (gi > gj) continue;  // diagonal block: keep its upper half
          emit(gi, gj, J[a].col(i).dot(J[b].col(j)), a, i, b, j);
        }
    }
}

}  // namespace gssm::internal
