#pragma once
// Feeds a run step by step into a graph-level smoother (the factors a GSSM
// adds per measurement), so tests can compare after every update.
#include <vector>

#include "gssm/factors/factors.h"
#include "gssm/model/model.h"

namespace gssm::testing {

/// Factors and initial values of step 0 (priors on x_c(0) and x_b).
inline std::pair<std::vector<FactorPtr>, Values> initialStep(const Model& m) {
  std::vector<FactorPtr> f{std::make_shared<PriorFactor>(Key::state(0), m.priorState())};
  Values v;
  v.insert(Key::state(0), m.priorState().mean);
  if (m.dims().nb > 0) {
    f.push_back(std::make_shared<PriorFactor>(Key::constants(), m.priorConstants()));
    v.insert(Key::constants(), m.priorConstants().mean);
  }
  return {f, v};
}

/// Factors of step k (process k-1 → k, measurement y at k) and the predicted
/// initial value of x_c(k) from the current estimates.
template <class Smoother>
std::pair<std::vector<FactorPtr>, Values> nextStep(const Model& m, Smoother& s, std::int64_t k,
                                                   const Eigen::VectorXd& y, double dt) {
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(m.dims().nu);
  std::vector<FactorPtr> f{std::make_shared<ProcessFactor>(m, k - 1, u, dt),
                           std::make_shared<MeasurementFactor>(m, k, y)};
  const Eigen::VectorXd xb =
      m.dims().nb ? s.estimate(Key::constants()) : Eigen::VectorXd(Eigen::VectorXd::Zero(0));
  Values v;
  v.insert(Key::state(k), m.f(s.estimate(Key::state(k - 1)), xb, u, dt));
  return {f, v};
}

}  // namespace gssm::testing
