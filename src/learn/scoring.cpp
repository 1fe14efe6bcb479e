#include "learn/scoring.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <iterator>
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

// The slope's points at x: each θ a step up (down at the box's upper
// end), and with `central` a step down too.
struct SlopePoints {
  std::vector<Eigen::VectorXd> points;
  Eigen::VectorXd h;
  bool central = false;
};

SlopePoints slopePoints(const Eigen::VectorXd& x, const ScoringOptions& o, bool central) {
  const Eigen::Index p = x.size();
  SlopePoints sp;
  sp.h.resize(p);
  sp.central = central;
  for (Eigen::Index i = 0; i < p; ++i) {
    sp.h[i] = x[i] + o.step <= o.hi[i] ? o.step : -o.step;
    sp.points.push_back(x), sp.points.back()[i] += sp.h[i];
    if (central) sp.points.push_back(x), sp.points.back()[i] -= sp.h[i];
  }
  return sp;
}

// The slope from the passes at its points and the one at x, `here`.
Slope slopeFrom(const SlopePoints& sp, const std::vector<LikelihoodTerms>& passes, const LikelihoodTerms& here) {
  const Eigen::Index p = sp.h.size();
  Slope s;
  s.central = sp.central;
  Eigen::MatrixXd G(here.terms.size(), p);  // one row per term: ∂ℓ_k/∂θ
  const std::size_t per = sp.central ? 2 : 1;
  for (Eigen::Index i = 0; i < p; ++i) {
    const LikelihoodTerms& a = passes[per * static_cast<std::size_t>(i)];
    const LikelihoodTerms& b = sp.central ? passes[per * static_cast<std::size_t>(i) + 1] : here;
    if (!std::isfinite(a.total) || a.terms.size() != here.terms.size() || !std::isfinite(b.total) ||
        b.terms.size() != here.terms.size()) {
      s.ok = false;
      return s;
    }
    G.col(i) = (a.terms - b.terms) / (sp.central ? 2 * sp.h[i] : sp.h[i]);
  }
  s.g = G.colwise().sum().transpose();
  s.B = G.transpose() * G;
  return s;
}

// The passes at `points`, counted.
std::vector<LikelihoodTerms> passesAt(const LikelihoodTermsAt& at, const std::vector<Eigen::VectorXd>& points,
                                      int& evaluations) {
  if (points.empty()) return {};
  evaluations += static_cast<int>(points.size());
  return at(points);
}

Slope slopeAt(const LikelihoodTermsAt& at, const Eigen::VectorXd& x, const LikelihoodTerms& here,
              const ScoringOptions& o, bool central, int& evaluations) {
  const SlopePoints sp = slopePoints(x, o, central);
  return slopeFrom(sp, passesAt(at, sp.points, evaluations), here);
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
// tenth of the step's first-order gain: the serial search's step, in
// rounds of `parallel_passes`. The s slope passes at the step taken then
// fill whole rounds but for s mod P of them: that many run beside each
// round's first trial, at its point (the next iteration's, a round fewer
// where it is taken, wasted where it is refused), and the round's other
// places go to the trials after it (a round fewer where the first is
// refused). Returns the slope at the point taken in `slope`.
bool searchAlong(const LikelihoodTermsAt& at, const Eigen::VectorXd& x, const Eigen::VectorXd& d,
                 const Eigen::VectorXd& g, LikelihoodTerms& here, Eigen::VectorXd& next, Slope& slope,
                 bool central, const ScoringOptions& o, int& evaluations) {
  const auto P = static_cast<std::size_t>(std::max(o.parallel_passes, 1));
  const std::size_t s = static_cast<std::size_t>(x.size()) * (central ? 2 : 1);
  const auto early = static_cast<std::ptrdiff_t>(s % P);
  double alpha = 1;
  while (alpha > 1e-3 && evaluations < o.max_evaluations) {
    std::vector<Eigen::VectorXd> trials;
    for (; alpha > 1e-3 && trials.size() + static_cast<std::size_t>(early) < P; alpha *= 0.25)
      trials.push_back((x + alpha * d).cwiseMax(o.lo).cwiseMin(o.hi));
    const SlopePoints first = slopePoints(trials.front(), o, central);
    std::vector<Eigen::VectorXd> round = trials;
    round.insert(round.end(), first.points.begin(), first.points.begin() + early);
    std::vector<LikelihoodTerms> there = passesAt(at, round, evaluations);
    for (std::size_t k = 0; k < trials.size(); ++k) {
      if (!(std::isfinite(there[k].total) && there[k].total > here.total + 0.1 * g.dot(trials[k] - x))) continue;
      here = std::move(there[k]), next = std::move(trials[k]);
      const SlopePoints sp = k == 0 ? first : slopePoints(next, o, central);
      const std::ptrdiff_t done = k == 0 ? early : 0;
      std::vector<LikelihoodTerms> passes(std::make_move_iterator(there.end() - done),
                                          std::make_move_iterator(there.end()));
      std::vector<LikelihoodTerms> rest =
          passesAt(at, std::vector<Eigen::VectorXd>(sp.points.begin() + done, sp.points.end()), evaluations);
      std::move(rest.begin(), rest.end(), std::back_inserter(passes));
      slope = slopeFrom(sp, passes, here);
      return true;
    }
  }
  return false;
}
}  // namespace

namespace {
// x, then its slope's points: the first round's θs.
std::vector<Eigen::VectorXd> startAndSlope(const Eigen::VectorXd& x, const SlopePoints& sp) {
  std::vector<Eigen::VectorXd> first{x};
  first.insert(first.end(), sp.points.begin(), sp.points.end());
  return first;
}
}  // namespace

std::vector<Eigen::VectorXd> firstScoringPoints(const Eigen::VectorXd& x0, const ScoringOptions& o) {
  const Eigen::VectorXd x = x0.cwiseMax(o.lo).cwiseMin(o.hi);
  return startAndSlope(x, slopePoints(x, o, false));
}

ScoringResult maximizeByScoring(const LikelihoodTermsAt& at, const Eigen::VectorXd& x0, const ScoringOptions& o,
                                const std::function<void(double)>& iteration) {
  ScoringResult r;
  r.x = x0.cwiseMax(o.lo).cwiseMin(o.hi);
  // The start and its slope's passes in one batch (forward differences
  // need the start only to difference against).
  const SlopePoints sp = slopePoints(r.x, o, false);
  std::vector<LikelihoodTerms> passes = passesAt(at, startAndSlope(r.x, sp), r.evaluations);
  LikelihoodTerms here = std::move(passes.front());
  r.value = here.total;
  if (!std::isfinite(here.total)) return r;
  passes.erase(passes.begin());
  Slope s = slopeFrom(sp, passes, here);
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
    Slope at_next;
    const bool moved = searchAlong(at, r.x, d, s.g, here, next, at_next, s.central, o, r.evaluations);
    if (iteration) iteration(here.total);
    if (!moved && s.central) break;  // no step along the slope raises ℓ: as far as differences resolve it
    if (!moved) {  // forward differences' error may be all that is left of the slope
      s = slopeAt(at, r.x, here, o, true, r.evaluations);
      continue;
    }
    if (at_next.ok) updateCurvature(H, next - r.x, at_next.g - s.g, at_next.B);
    r.x = next, s = std::move(at_next);  // not ok: a pass failed a step away, the search ends here
  }
  r.value = here.total;
  return r;
}

}  // namespace gssm::internal
