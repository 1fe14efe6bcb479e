#pragma once
// Internal: the one Levenberg–Marquardt / Newton policy of every iterative
// solver (the batch solver and the iterated incremental smoother;
// docs/DESIGN.md §5, eq. 6). It owns what used to drift between two copies:
// the damping schedule, which steps are accepted, the switch to undamped
// steps once a convergence test passes, and the Newton polish loop.
#include <algorithm>
#include <cmath>

#include "gssm/core/values.h"
#include "solvers/newton.h"

namespace gssm::internal {

class LevenbergMarquardtPolicy {
 public:
  /// The batch solver's options carry these defaults (BatchSolverOptions:
  /// why λ₀ is small there).
  static constexpr double kInitialLambda = 1e-8;
  static constexpr double kMaxLambda = 1e12;
  static constexpr double kMinLambda = 1e-12;
  /// Near the minimum the cost change (∝ ‖δ‖²) is below rounding, so an
  /// undamped step is kept unless it raises the cost by more than this.
  static constexpr double kUndampedSlack = 1e-10;

  LevenbergMarquardtPolicy(double initial_lambda = kInitialLambda, double max_lambda = kMaxLambda,
                           bool damped = true)
      : lambda_(damped ? initial_lambda : 0.0), max_lambda_(max_lambda), damped_(damped), undamped_(!damped) {}

  /// λ of the next step (0 while finishing undamped).
  double lambda() const { return undamped_ ? 0.0 : lambda_; }
  bool undamped() const { return undamped_; }
  /// Whether a step from `cost` to `new_cost` is kept (plain Gauss–Newton
  /// cannot back off: it keeps every step).
  bool accept(double new_cost, double cost) const {
    if (!damped_) return true;
    return undamped_ ? acceptUndamped(new_cost, cost) : new_cost < cost;
  }
  static bool acceptUndamped(double new_cost, double cost) { return new_cost <= cost * (1 + kUndampedSlack); }
  /// After a kept step: less damping, none below kMinLambda. λ·diag(JᵀJ)
  /// damps a long chain of stiff states (an INS's, 10⁹–10¹¹ on the
  /// diagonal) by ~λ·10¹¹ per state; kept at 1e-12 it held the GNSS/INS
  /// drive's outages 0.19 m from the minimum after 100 iterations, where
  /// undamped steps reach 0.12 m in 10.
  void accepted() {
    if (!undamped_) lambda_ = lambda_ / 10 < kMinLambda ? 0.0 : lambda_ / 10;
  }
  /// After a step that raised the cost (or could not be formed): more
  /// damping; false when λ passed its maximum (no progress possible).
  bool rejected() {
    lambda_ = lambda_ > 0 ? lambda_ * 10 : kMinLambda;
    return lambda_ <= max_lambda_;
  }
  /// The damped system could not be factored: more damping, damped again.
  void singular() {
    undamped_ = !damped_;
    lambda_ = std::max(lambda_ * 10, 1e-6);
  }
  /// Whether more damping could still help a system that does not factor.
  bool canDampMore() const { return damped_ && lambda_ < max_lambda_; }
  /// A convergence test passed. LM leaves a damping bias of order λ in its
  /// last steps, so the first time (while damped) the policy switches to
  /// undamped Gauss–Newton and returns false (keep going); then true (stop):
  /// on a linear problem the result is the exact least-squares solution.
  bool converged() {
    if (undamped_) return true;
    undamped_ = true;
    lambda_ = 0.0;  // a later singular() restarts damping small
    return false;
  }

 private:
  double lambda_, max_lambda_;
  bool damped_, undamped_;
};

/// What a Newton polish did.
struct NewtonPolishResult {
  int steps = 0;        ///< full Newton steps kept
  double cost = 0;      ///< cost at the end
  bool indefinite = false;  ///< stopped because the Hessian was not positive definite
};

/// Up to `max_steps` full Newton steps from the estimate `x` with cost
/// `cost`, after the Gauss–Newton/LM iteration converged (the Hessian with
/// its second-order terms: see newton.h). The solver provides
///   assemble(NewtonSystem&, const Values& x)  the system at x;
///   trial(Values& candidate) -> double       moves there tentatively and
///                                            returns its cost (+∞ if it
///                                            cannot be evaluated); may set
///                                            `candidate` to where it landed
///                                            (a re-elimination moves on);
///   keep(bool)                               commits or undoes the trial;
///   converged(const Values& from, const Values& to, const Eigen::VectorXd& d)
///                                            after a kept step.
/// A step is kept only if LevenbergMarquardtPolicy would keep an undamped one.
template <class Assemble, class Trial, class Keep, class Converged>
NewtonPolishResult newtonPolish(Values x, double cost, int max_steps, Assemble assemble, Trial trial, Keep keep,
                                Converged converged) {
  NewtonPolishResult out;
  out.cost = cost;
  for (int it = 0; it < max_steps; ++it) {
    NewtonSystem sys(x);
    assemble(sys, x);
    Eigen::VectorXd d;
    if (!sys.solve(d)) {  // not near a minimum: keep the Gauss–Newton answer
      out.indefinite = true;
      break;
    }
    Values next = addStep(x, d);
    const double c = trial(next);
    if (!LevenbergMarquardtPolicy::acceptUndamped(c, out.cost)) {
      keep(false);
      break;
    }
    keep(true);
    ++out.steps;
    out.cost = c;
    const bool done = converged(x, next, d);
    x = std::move(next);
    if (done) break;
  }
  return out;
}

}  // namespace gssm::internal
