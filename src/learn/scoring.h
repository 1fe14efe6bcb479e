#pragma once
// Maximum likelihood by scoring for noise learning (docs/DESIGN.md §10).
// The prediction-error log-likelihood is a sum of one term per measurement,
// ℓ(θ) = Σ_k ℓ_k(θ), each the density of a prediction error given the past:
// a martingale difference's score, so the outer product of the terms'
// gradients estimates the information (Berndt, Hall, Hall & Hausman, Ann.
// Econ. Soc. Meas. 3(4), 1974). Forward differences of every term give the
// gradient and that matrix from the same p + 1 filter passes; quasi-Newton
// steps from it (then BFGS's secant updates) reach the maximum in a few
// iterations where Nelder–Mead takes hundreds of passes.
#include <Eigen/Core>
#include <functional>
#include <vector>

namespace gssm::internal {

/// One filter pass: the log-likelihood and its terms (total −∞, terms
/// empty, where the pass failed or θ is outside the domain).
struct LikelihoodTerms {
  double total = 0;
  Eigen::VectorXd terms;
};

/// The passes at several θ (independent: they may run in parallel).
using LikelihoodTermsAt = std::function<std::vector<LikelihoodTerms>(const std::vector<Eigen::VectorXd>&)>;

struct ScoringOptions {
  Eigen::VectorXd lo, hi;  ///< the box θ stays in
  int max_evaluations = 4000;
  /// Converged when the next quasi-Newton step's predicted gain ½ gᵀH⁻¹g
  /// (H: the curvature, B then BFGS) is under tolerance·(1 + |ℓ|).
  double tolerance = 1e-7;
  /// Forward-difference step in θ. Their slope vanishes half a step from
  /// the top (−ℓ''·step/2 is their error), so the maximum found lies within
  /// step/2 of the true one: 5e-6 in log σ, far inside any standard error.
  double step = 1e-5;
  double max_step = 2;  ///< largest move of one θ per iteration (a factor e² in σ)
  /// How many passes `at` runs at once: each line-search trial goes with
  /// that many less one of the slope's passes at the trial point, and the
  /// start with its slope's (the same path as one pass at a time, in fewer
  /// rounds where the trial is taken; where it is refused they are extra).
  int parallel_passes = 1;
};

struct ScoringResult {
  Eigen::VectorXd x;
  double value = 0;
  int evaluations = 0;
  int iterations = 0;
  bool converged = false;
};

/// The θs the maximization's first round runs at from x0: x0 (clamped
/// into the box), then its slope's points. A caller may run them before,
/// beside its own first passes, and serve them again from what it keeps.
std::vector<Eigen::VectorXd> firstScoringPoints(const Eigen::VectorXd& x0, const ScoringOptions& o);

/// Maximizes ℓ from x0 (clamped into the box); a θ at a bound whose
/// gradient points outward stays there. `iteration` is called with the
/// best value after each iteration.
ScoringResult maximizeByScoring(const LikelihoodTermsAt& at, const Eigen::VectorXd& x0, const ScoringOptions& o,
                                const std::function<void(double)>& iteration = {});

}  // namespace gssm::internal
