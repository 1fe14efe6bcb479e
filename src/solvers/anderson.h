#pragma once
// Internal: Anderson acceleration of the batch solver's undamped
// Gauss–Newton iteration x ← x ⊕ f(x), f the Gauss–Newton step (Walker &
// Ni, SIAM J. Numer. Anal. 49(4), 2011, "type II", memory m; docs/DESIGN.md
// §5). Gauss–Newton converges only linearly where it leaves out second-order
// terms that matter: residuals that stay large at the optimum, a robust
// loss's reweighting, a constant seen through a product of rotations (the
// GNSS/INS drive's mounting: each step 0.38 of the last). The last m steps
// and the changes of f they caused show that slow direction; the mix
// extrapolates along it:
//   step = f_k − (ΔX + ΔF)·γ,  γ = argmin ‖f_k − ΔF·γ‖_W,
// ΔX the last m steps taken, ΔF the changes of f over them, W a diagonal
// metric (the information matrix's diagonal: the same in any units). The
// caller keeps a mixed step only if it lowers the cost.
#include <Eigen/Core>
#include <vector>

namespace gssm::internal {

class AndersonMixing {
 public:
  explicit AndersonMixing(int memory = 0) : memory_(memory) {}
  /// Forgets every step (a damped, rejected or singular one breaks the
  /// sequence the differences describe).
  void reset();
  /// The step to take from the current point, given its Gauss–Newton step
  /// `f` and positive weights `w`: f itself until a step was taken since
  /// the last reset, then the mix. f is remembered until accepted().
  /// Returns false (and leaves `step` = f) when no mix was made.
  bool mix(const Eigen::VectorXd& f, const Eigen::VectorXd& w, Eigen::VectorXd& step);
  /// The step `taken` from the point mix() was called at was kept.
  void accepted(const Eigen::VectorXd& taken);

 private:
  int memory_;
  Eigen::VectorXd f_pending_, f_last_, taken_last_;  // f at the current point; at the last point; the step from it
  bool has_pending_ = false, has_last_ = false;
  std::vector<Eigen::VectorXd> dF_, dX_;  // the last `memory_` differences, oldest first
};

}  // namespace gssm::internal
