#pragma once
// BatchSolver: the MAP estimate of a whole GSSM graph by sparse
// Levenberg–Marquardt (or Gauss–Newton) on the normal equations
// JᵀJ δ = −Jᵀr with the states in time order and the constants last (no
// fill beyond the constants' border), factored by its envelope when the
// graph is such a chain and by CHOLMOD otherwise. The correctness
// reference for every other estimator.
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gssm/factors/factors.h"

namespace gssm {

struct BatchSolverOptions {
  enum class Method { LevenbergMarquardt, GaussNewton };
  /// "levenberg-marquardt" or "gauss-newton": the algorithm's name in INI files and in Python.
  static const char* methodName(Method m);
  /// The algorithm called `name`, if any.
  static std::optional<Method> methodNamed(const std::string& name);
  /// LM is the default: the radar start-up (x ≈ 0, range insensitive to x)
  /// makes undamped Gauss–Newton overshoot from the paper's prior.
  Method method = Method::LevenbergMarquardt;
  int max_iterations = 100;
  /// Stop when an accepted step lowers the cost by less than this fraction.
  double relative_cost_tolerance = 1e-12;
  /// Stop when ‖δ‖ ≤ tol·(‖x‖ + tol).
  double step_tolerance = 1e-10;
  /// Stop when max |Jᵀr| ≤ tol.
  double gradient_tolerance = 1e-9;
  /// Stop when an undamped step's predicted decrease −½gᵀδ (= ½δᵀHδ: half
  /// its squared length in the posterior's metric) is at most this, in cost
  /// units (0: no such test). The relative tests above cannot pass where
  /// the cost's rounding exceeds 1e-12 of it: an INS's 10⁵ stiff process
  /// factors sum residuals of 10⁻⁵ m over positions of 10³ m. 1e-4 stops
  /// where no estimate would move by more than 0.014 σ.
  double decrease_tolerance = 0;
  /// LM damping λ₀, relative to diag(JᵀJ). Small: the GSSM's constants are
  /// weakly determined next to their diagonal (h trades off against every
  /// x_c(k)), so λ·diag damps their step far more than the others'; 1e-4
  /// took 6 iterations on 20k radar steps from the EKF guess, 1e-8 takes 3.
  /// A start that needs damping pays one rejected step per factor of 10.
  double initial_lambda = 1e-8;
  double max_lambda = 1e12;
  /// After convergence, up to this many full Newton steps: the Hessian with
  /// its second-order terms Σ r_i ∇²r_i (central differences of the
  /// analytic Jacobians). Where residuals stay large at the optimum
  /// (the radar start-up from the paper's 143σ-wrong prior) LM converges
  /// only linearly with a rate near 1; Newton finishes quadratically. Costs
  /// 2·(variables per factor) extra Jacobian evaluations per factor per step.
  int newton_polish_steps = 0;
  /// No polish with false. false: an undamped step (Gauss–Newton's, or
  /// Levenberg–Marquardt's finishing one) whose predicted decrease −½gᵀδ is
  /// below relative_cost_tolerance·cost is the last one — taken, not
  /// followed by a linearization — and the covariances come from the
  /// factorization that computed it, at the point before it (for a step
  /// that small the difference is of its own order); the summary's
  /// final_cost is then the predicted one and gradient_norm the last
  /// linearization's. A converged solve costs one linearization and one
  /// factorization fewer (the paper window: 4 → 3 of each per solve; an
  /// E-step of EM on the UWB log: 6 → 5).
  bool relinearize_at_solution = true;
  /// Threads that may linearize a long chain (16384 factors or more, on the
  /// envelope): its two halves side by side. The same bits with any count
  /// (the halves' sums are combined in one fixed order).
  int threads = 1;
  /// Covariances from a QR of the whitened Jacobian at the solution
  /// (Givens rotations, row by row) instead of the normal equations' factor:
  /// JᵀJ squares J's condition number, and a stiff chain beside a constant
  /// it nearly hides (an INS's IMU factors and its lever arm) loses digits
  /// of that constant's variance in it: on the GNSS/INS drive the lever
  /// arm's vertical sd moved by 3 % between two problems one ulp apart. The
  /// same factor's pattern, so the same selected inverse; one more pass
  /// over the factors. Where the envelope serves the graph (a chain in time
  /// order, constants last; otherwise the normal equations).
  bool covariance_by_qr = false;
  /// Anderson acceleration of the undamped steps (0: off): each
  /// Gauss–Newton step mixed with the last `anderson_memory` steps and the
  /// changes of the Gauss–Newton step over them (Walker & Ni 2011; docs/
  /// DESIGN.md §5). Where Gauss–Newton converges only linearly (second-order
  /// terms it leaves out: large residuals at the optimum, a robust loss, a
  /// constant seen through products of rotations) the mix extrapolates along
  /// the slow direction: on the GNSS/INS drive 10 iterations → 6 at 2,
  /// nearer the minimum. A mixed step is kept only if it lowers the cost
  /// (otherwise Gauss–Newton's own step follows); the convergence tests
  /// judge Gauss–Newton's step, so the stopping point's meaning is the same.
  /// Holds 2·memory + 2 vectors of the problem's size.
  int anderson_memory = 0;
  /// Empty when valid; otherwise says which field is wrong and why.
  bool validate(std::string* why = nullptr) const;
};

struct BatchSolverSummary {
  enum class Termination {
    CostConverged,
    StepConverged,
    GradientConverged,
    MaxIterations,
    NoProgress,  ///< LM damping hit max_lambda without lowering the cost
  };
  Termination termination = Termination::MaxIterations;
  bool converged = false;     ///< true for the three *Converged reasons
  int iterations = 0;         ///< linearizations after the initial one
  int rejected_steps = 0;     ///< LM steps that raised the cost
  int factorizations = 0;
  int newton_steps = 0;       ///< full Newton steps taken by the polish
  int anderson_steps = 0;     ///< Anderson-mixed steps kept (anderson_memory > 0)
  int anderson_rejected = 0;  ///< mixed steps that did not lower the cost (Gauss–Newton's taken instead)
  /// How the information matrix was factored: "envelope" (a chain in time
  /// order with the constants last: its profile, no fill outside it), or
  /// for any other graph "dense" (at most 64 unknowns) or "sparse" (CHOLMOD).
  std::string linear_solver;
  double initial_cost = 0;    ///< ½Σ‖r‖² at the initial values
  double final_cost = 0;
  double gradient_norm = 0;   ///< max |Jᵀr| at the solution
  double seconds = 0;
  std::size_t num_factors = 0;
  std::size_t num_variables = 0;
  Eigen::Index dimension = 0;
  std::string message;        ///< one line: why it stopped
  std::string toString() const;
};

const char* toString(BatchSolverSummary::Termination t);

/// A change of the last solved graph confined to a few variables (the
/// paper window's drop of its oldest state: docs/DESIGN.md §4).
struct GraphChange {
  FactorGraph removed;       ///< factors of the last solve's graph that leave
  FactorGraph added;         ///< new factors, on variables of the last solve that stay
  std::vector<Key> dropped;  ///< variables that leave; only `removed` factors may touch them
};

/// What BatchSolver::stepAfterChange() computed.
struct ChangeStep {
  double cost_before = 0;         ///< ½Σ‖r‖² of the changed graph at the factored point
  double predicted_decrease = 0;  ///< −½g'ᵀδ: the Gauss–Newton model's decrease
  Eigen::Index rank = 0;          ///< columns of the low-rank correction (the touched variables')
};

class BatchSolver {
 public:
  explicit BatchSolver(BatchSolverOptions options = {});  ///< throws if invalid
  ~BatchSolver();
  BatchSolver(BatchSolver&&) noexcept;
  BatchSolver& operator=(BatchSolver&&) noexcept;

  /// Minimizes ½Σ‖r_i‖² from `values` (in: initial guess; out: the solution).
  /// Throws NumericalError naming the variable when the information matrix
  /// is singular even with damping; `values` is then unchanged.
  BatchSolverSummary solve(const FactorGraph& graph, Values& values);

  /// Linearizes and factors the information matrix at `values` without
  /// moving them (e.g. at the true states, for a Cramér–Rao bound); the
  /// marginal covariances then refer to that point. Throws NumericalError
  /// naming the variable if the information matrix is singular there.
  void evaluateAt(const FactorGraph& graph, const Values& values);

  /// The point the covariances refer to: the solution, or with
  /// relinearize_at_solution false the point before the last step (`like`'s
  /// keys and sizes, which must be the last solve's). Restoring a solver
  /// exactly: evaluateAt(graph, factoredAt(values)).
  Values factoredAt(const Values& like) const;

  /// One Gauss–Newton step of the last solved graph after `change`, from
  /// the point x_f where that solve last factored H, without relinearizing
  /// or refactoring the factors that stay. With O the dropped variables, R
  /// the rest and H_d, H_a the removed and added factors' JᵀJ at x_f, the
  /// changed graph's information on R is S + E: S, the Schur complement of
  /// O in the factored H, and E = H_d,RO·H_d,OO⁻¹·H_d,OR − H_d,RR + H_a,RR,
  /// nonzero only among the k columns of the variables the change touches.
  /// So δ = −(S + E)⁻¹g' (g' the changed gradient at x_f) takes two solves
  /// with H's factor, H⁻¹ among the k columns and k × k algebra
  /// (Woodbury), the same step
  /// a fresh linearization and factorization at x_f would give, to
  /// rounding. `values` (the last solve's keys and sizes) becomes x_f ⊕ δ
  /// without the dropped variables. The factorization belongs to the old
  /// graph afterwards: solve() the changed graph before asking for
  /// covariances. Throws InvalidArgument for a key the last solve did not
  /// have or an added factor on a dropped variable, NumericalError (naming
  /// the variables) when the removed factors do not determine the dropped
  /// variables or the changed information matrix is singular; `values` is
  /// then unchanged.
  ChangeStep stepAfterChange(const GraphChange& change, Values& values);

  /// Marginal covariance of one variable at the last solution.
  Eigen::MatrixXd marginalCovariance(const Key& key) const;
  /// Joint marginal covariance of several variables (blocks in the given order).
  Eigen::MatrixXd jointMarginalCovariance(const std::vector<Key>& keys) const;

  const BatchSolverOptions& options() const { return options_; }

 private:
  struct Impl;
  BatchSolverOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gssm
