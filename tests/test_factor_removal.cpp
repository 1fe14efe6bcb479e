// Removing factors from the incremental smoother (the engine's part of
// inserting a state into the chain): the result equals the smoother that
// never had them, and a bad removal changes nothing.
#include <gtest/gtest.h>

#include "gssm/core/error.h"
#include "gssm/models/linear.h"
#include "gssm/solvers/smoothers.h"
#include "reference_kalman.h"
#include "smoother_driver.h"
#include "track_with_bias.h"

namespace gssm {
namespace {

// A relative constraint x_c(a) − x_c(b) ≈ d (a loop closure), linear.
FactorPtr loop(std::int64_t a, std::int64_t b, double d) {
  std::vector<Eigen::MatrixXd> A{Eigen::MatrixXd::Identity(2, 2), -Eigen::MatrixXd::Identity(2, 2)};
  Values x0;
  x0.insert(Key::state(a), Eigen::Vector2d::Zero());
  x0.insert(Key::state(b), Eigen::Vector2d::Zero());
  return std::make_shared<LinearGaussianFactor>(std::vector<Key>{Key::state(a), Key::state(b)}, A,
                                                Eigen::Vector2d(d, 0.0), x0);
}

// The run fed step by step, with the loop factors added after step `at`.
std::unique_ptr<IncrementalSmoother> feed(const Model& m, const SimulatedRun& run,
                                          const std::vector<FactorPtr>& loops, std::size_t at) {
  SmootherOptions o;
  o.relinearize = false;  // linear: every factor keeps its linearization
  auto s = std::make_unique<IncrementalSmoother>(o);
  auto [f0, v0] = testing::initialStep(m);
  s->update(f0, v0);
  for (std::size_t k = 1; k <= run.measurements.size(); ++k) {
    auto [f, v] = testing::nextStep(m, *s, static_cast<std::int64_t>(k), run.measurements[k - 1].y, m.nominalStep());
    s->update(f, v);
    if (k == at) s->update(loops, Values{});
  }
  return s;
}

TEST(FactorRemoval, RemovingFactorsEqualsNeverHavingThem) {
  const models::LinearModel m(testing::trackWithBias(0.01, 0.04, 0.25, 0.5));
  SimulationSpec spec;
  spec.steps = 40;
  const SimulatedRun run = simulate(m, spec, testing::normalSampler(3));
  auto with = feed(m, run, {loop(5, 20, 1.0), loop(8, 30, -2.0)}, 30);
  auto without = feed(m, run, {loop(8, 30, -2.0)}, 30);
  const Values before = with->calculateEstimate();
  // No factor on x_c(5) and x_c(25): refused, nothing changed.
  EXPECT_THROW(with->replace({{Key::state(5), Key::state(25)}}, {}, Values{}), InvalidArgument);
  EXPECT_EQ(with->calculateEstimate().at(Key::state(12)), before.at(Key::state(12)));
  const std::size_t factors = with->numFactors();
  const UpdateReport r = with->replace({{Key::state(5), Key::state(20)}}, {}, Values{});
  EXPECT_EQ(with->numFactors(), factors - 1);
  EXPECT_EQ(r.num_factors, factors - 1);
  const Values a = with->calculateEstimate(), b = without->calculateEstimate();
  for (std::int64_t k = 0; k <= 40; ++k)
    EXPECT_LE((a.at(Key::state(k)) - b.at(Key::state(k))).cwiseAbs().maxCoeff(), 1e-9) << k;
  EXPECT_LE((a.at(Key::constants()) - b.at(Key::constants())).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LE((with->marginalCovariance(Key::state(12)) - without->marginalCovariance(Key::state(12))).norm(), 1e-9);
  // A process factor replaced by itself: the same solution.
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(0);
  with->replace({{Key::state(10), Key::state(11)}}, {std::make_shared<ProcessFactor>(m, 10, u, m.nominalStep())},
                Values{});
  EXPECT_EQ(with->numFactors(), factors - 1);
  const Values c = with->calculateEstimate();
  for (std::int64_t k = 0; k <= 40; ++k)
    EXPECT_LE((c.at(Key::state(k)) - b.at(Key::state(k))).cwiseAbs().maxCoeff(), 1e-9) << k;
}

}  // namespace
}  // namespace gssm
