#include "learn/scoring.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

namespace gssm::internal {

namespace {
// The gradient g = Σ_k ∇ℓ_k and the outer-product information B = Σ_k
// ∇ℓ_k ∇ℓ_kᵀ from differences of every term: forward (backward at the
// box's upper end; p passes beside the one at x) or, once those no longer
// resolve the slope near the top, central (2p passes).
struct Slope {
  Eigen::VectorXd g;
  Eigen::MatrixXd B;
  bool ok = true;
  bool central = false;
};

Slope slopeAt(const LikelihoodTermsAt& at, const Eigen::VectorXd& x, const LikelihoodTerms& here,
              const ScoringOptions& o, bool central, int& evaluations) {
  const Eigen::Index p = x.size();
  std::vector<Eigen::VectorXd> points;
  Eigen::VectorXd h(p);
  for (Eigen::Index i = 0; i < p; ++i) {
    h[i] = x[i] + o.step <= o.hi[i] ? o.step : -o.step;
    points.push_back(x), points.back()[i] += h[i];
    if (central) points.push_back(x), points.back()[i] -= h[i];
  }
  const std::vector<LikelihoodTerms> passes = at(points);
  evaluations += static_cast<int>(points.size());
  Slope s;
  s.central = central;
  Eigen::MatrixXd G(here.terms.size(), p);  // one row per term: ∂ℓ_k/∂θ
  const std::size_t per = central ? 2 : 1;
  for (Eigen::Index i = 0; i < p; ++i) {
    const LikelihoodTerms& a = passes[per * static_cast<std::size_t>(i)];
    const LikelihoodTerms& b = central ? passes[per * static_cast<std::size_t>(i) + 1] : here;
    if (!std::isfinite(a.total) || a.terms.size() != here.terms.size() || !std::isfinite(b.total) ||
        b.terms.size() != here.terms.size()) {
      s.ok = false;
      return s;
    }
    G.col(i) = (a.terms - b.terms) / (central ? 2 * h[i] : h[i]);
  }
  s.g = G.colwise().sum().transpose();
  s.B = G.transpose() * G;
  return s;
}

// The quasi-Newton step H⁻¹g over the parameters not held at a bound, at
// most max_step in any θ (H: the curvature of −ℓ).
Eigen::VectorXd newtonStep(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, const std::vector<bool>& held,
                           double max_step) {
  const Eigen::Index p = g.size();
  const double floor = 1e-12 * std::max(1.0, H.diagonal().maxCoeff());
  Eigen::MatrixXd A = H;
  Eigen::VectorXd rhs = g;
  for (Eigen::Index i = 0; i < p; ++i) {
    A(i, i) += floor;
    if (!held[static_cast<std::size_t>(i)]) continue;
    A.row(i).setZero(), A.col(i).setZero(), A(i, i) = 1, rhs[i] = 0;
  }
  Eigen::VectorXd d = A.ldlt().solve(rhs);
  const double largest = d.lpNorm<Eigen::Infinity>();
  if (largest > max_step) d *= max_step / largest;
  return d;
}

// A θ at a bound whose gradient points out of the box is held there.
std::vector<bool> heldAtBounds(const Eigen::VectorXd& x, const Eigen::VectorXd& g, const ScoringOptions& o) {
  std::vector<bool> held(static_cast<std::size_t>(x.size()));
  for (Eigen::Index i = 0; i < x.size(); ++i)
    held[static_cast<std::size_t>(i)] = (x[i] <= o.lo[i] && g[i] < 0) || (x[i] >= o.hi[i] && g[i] > 0);
  return held;
}

// BFGS's update of the curvature H of −ℓ from a step s and the change of
// the gradient of ℓ, Δg; where the pair shows no positive curvature, the
// outer product B at the new point instead.
void updateCurvature(Eigen::MatrixXd& H, const Eigen::VectorXd& s, const Eigen::VectorXd& dg,
                     const Eigen::MatrixXd& B) {
  const Eigen::VectorXd y = -dg;
  const double sy = s.dot(y);
  if (!(sy > 1e-10 * s.norm() * y.norm())) {
    H = B;
    return;
  }
  const Eigen::VectorXd Hs = H * s;
  H += y * y.transpose() / sy - Hs * Hs.transpose() / s.dot(Hs);
}
// Backtracking from x along d (α = 1, ¼, 1/16, …) until ℓ rises by a
// tenth of the step's first-order gain; `parallel_passes` trials at a time,
// the first that passes taken: the serial search's step, in fewer rounds
// where it would have refused α = 1 (the later trials are then wasted).
bool searchAlong(const LikelihoodTermsAt& at, const Eigen::VectorXd& x, const Eigen::VectorXd& d,
                 const Eigen::VectorXd& g, LikelihoodTerms& here, Eigen::VectorXd& next, const ScoringOptions& o,
                 int& evaluations) {
  double alpha = 1;
  while (alpha > 1e-3 && evaluations < o.max_evaluations) {
    std::vector<Eigen::VectorXd> trials;
    for (; alpha > 1e-3 && static_cast<int>(trials.size()) < std::max(o.parallel_passes, 1); alpha *= 0.25)
      trials.push_back((x + alpha * d).cwiseMax(o.lo).cwiseMin(o.hi));
    std::vector<LikelihoodTerms> there = at(trials);
    evaluations += static_cast<int>(trials.size());
    for (std::size_t k = 0; k < trials.size(); ++k)
      if (std::isfinite(there[k].total) && there[k].total > here.total + 0.1 * g.dot(trials[k] - x)) {
        here = std::move(there[k]), next = std::move(trials[k]);
        return true;
      }
  }
  return false;
}
}  // namespace

ScoringResult maximizeByScoring(const LikelihoodTermsAt& at, const Eigen::VectorXd& x0, const ScoringOptions& o,
                                const std::function<void(double)>& iteration) {
  ScoringResult r;
  r.x = x0.cwiseMax(o.lo).cwiseMin(o.hi);
  LikelihoodTerms here = at({r.x}).front();
  r.evaluations = 1;
  r.value = here.total;
  if (!std::isfinite(here.total)) return r;
  Slope s = slopeAt(at, r.x, here, o, false, r.evaluations);
  Eigen::MatrixXd H = s.B;  // the outer product first, then BFGS's secant updates
  while (s.ok && r.evaluations + 2 * r.x.size() + 1 <= o.max_evaluations) {
    const std::vector<bool> held = heldAtBounds(r.x, s.g, o);
    const Eigen::VectorXd d = newtonStep(H, s.g, held, o.max_step);
    ++r.iterations;
    if (0.5 * s.g.dot(d) < o.tolerance * (1.0 + std::abs(here.total))) {
      r.converged = true;
      break;
    }
    Eigen::VectorXd next;
    const bool moved = searchAlong(at, r.x, d, s.g, here, next, o, r.evaluations);
    if (iteration) iteration(here.total);
    if (!moved && s.central) break;  // no step along the slope raises ℓ: as far as differences resolve it
    if (!moved) {  // forward differences' error may be all that is left of the slope
      s = slopeAt(at, r.x, here, o, true, r.evaluations);
      continue;
    }
    Slope at_next = slopeAt(at, next, here, o, s.central, r.evaluations);
    if (at_next.ok) updateCurvature(H, next - r.x, at_next.g - s.g, at_next.B);
    r.x = next, s = std::move(at_next);  // not ok: a pass failed a step away, the search ends here
  }
  r.value = here.total;
  return r;
}

}  // namespace gssm::internal
