#include <gtest/gtest.h>

#include <iostream>

#include <functional>
#include <map>
#include <random>

#include "gssm/solvers/batch_solver.h"
#include "gssm/estimator/estimator.h"
#include "gssm/core/error.h"
#include "gssm/models/linear.h"
#include "gssm/models/radar2d.h"
#include "gssm/factors/problem.h"
#include "gssm/model/simulation.h"
#include "gssm/solvers/smoothers.h"
#include "reference_kalman.h"
#include "smoother_driver.h"

using namespace gssm;
using gssm::testing::relativeError;

namespace {
using gssm::testing::normalSampler;
using gssm::testing::radarPaperRun;

models::LinearModel randomLinear(unsigned seed) {
  std::mt19937 rng(seed);
  return models::LinearModel(gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1));
}

// A smoother iterated to convergence, finished by Newton steps, and a batch
// solver as strict: stopping on the step size only (the cost change is below
// rounding long before the radar's slow start-up steps have converged).
// Steps 1-9 of the radar: the MAP has a 50σ range residual (the prior forces
// h > 1150 while the range is ~1000) and x is determined only to ±5 m along
// a valley where the cost changes by 3e-7 over 4e-3 m: Gauss–Newton and LM
// converge linearly with a rate near 1 there, and stop up to 4e-6 apart;
// both finish with full Newton steps (second-order terms restored).
SmootherOptions iteratedToConvergence() {
  SmootherOptions o;
  o.iterate_to_convergence = true;
  o.convergence_tolerance = 1e-12;
  o.newton_polish_steps = 10;
  return o;
}
BatchSolverOptions strictBatch() {
  BatchSolverOptions bo;
  bo.max_iterations = 5000;
  bo.relative_cost_tolerance = 0;
  bo.gradient_tolerance = 0;
  bo.step_tolerance = 1e-13;
  bo.newton_polish_steps = 10;
  return bo;
}

Eigen::VectorXd stacked(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb) {
  Eigen::VectorXd z(xc.size() + xb.size());
  z << xc, xb;
  return z;
}
}  // namespace

TEST(IncrementalSmoother, LinearModelEqualsBatchAfterEveryStep) {
  for (auto ordering : {EliminationOrdering::ConstrainedColamd, EliminationOrdering::TimeOrdered}) {
    const auto model = randomLinear(31);
    SimulationSpec spec;
    spec.steps = 40;
    const SimulatedRun run = simulate(model, spec, normalSampler(6));
    IncrementalSmoother smoother(SmootherOptions{}, ordering);
    auto [f0, v0] = gssm::testing::initialStep(model);
    smoother.update(f0, v0);
    for (int k = 1; k <= spec.steps; ++k) {
      auto [f, v] = gssm::testing::nextStep(model, smoother, k, run.measurements[k - 1].y, 0.1);
      smoother.update(f, v);
      const std::vector<Measurement> upto(run.measurements.begin(), run.measurements.begin() + k);
      Problem p = buildProblem(model, upto);
      Values x = p.initial;
      BatchSolver batch;
      ASSERT_TRUE(batch.solve(p.graph, x).converged);
      const Values inc = smoother.calculateEstimate();
      for (const auto& kv : x)
        EXPECT_LT(relativeError(inc.at(kv.first), kv.second), 1e-9) << kv.first.toString() << " at step " << k;
      const std::vector<Key> top{Key::state(k), Key::constants()};
      EXPECT_LT(relativeError(smoother.jointMarginalCovariance(top), batch.jointMarginalCovariance(top)), 1e-9)
          << "step " << k;
      const std::vector<Key> old{Key::state(k / 2), Key::constants()};
      EXPECT_LT(relativeError(smoother.jointMarginalCovariance(old), batch.jointMarginalCovariance(old)), 1e-9)
          << "step " << k;
    }
  }
}

class FixedLagVsKalman : public ::testing::TestWithParam<int> {};

TEST_P(FixedLagVsKalman, NewestStateEqualsKalmanFilterAndWindowEqualsRts) {
  const int w = GetParam();
  const auto model = randomLinear(32);
  SimulationSpec spec;
  spec.steps = 30;
  const SimulatedRun run = simulate(model, spec, normalSampler(7));
  FixedLagSmootherOptions o;
  o.window = w;
  FixedLagSmoother smoother(o);
  auto [f0, v0] = gssm::testing::initialStep(model);
  smoother.update(f0, v0);
  const auto stackedModel = gssm::testing::stack(model, 0.1);
  for (int k = 1; k <= spec.steps; ++k) {
    auto [f, v] = gssm::testing::nextStep(model, smoother, k, run.measurements[k - 1].y, 0.1);
    const UpdateReport rep = smoother.update(f, v);
    const std::vector<Measurement> upto(run.measurements.begin(), run.measurements.begin() + k);
    const auto ref = gssm::testing::kalmanAndRts(stackedModel, upto);
    const Eigen::VectorXd z = stacked(smoother.estimate(Key::state(k)), smoother.estimate(Key::constants()));
    EXPECT_LT(relativeError(z, ref.zf[k]), 1e-9) << "w " << w << " step " << k;
    EXPECT_LT(relativeError(smoother.jointMarginalCovariance({Key::state(k), Key::constants()}), ref.Pf[k]), 1e-9)
        << "w " << w << " step " << k;
    // States inside the window equal the RTS smoother over data 1..k.
    const Values all = smoother.calculateEstimate();
    for (std::int64_t j = smoother.oldestStep(); j <= k; ++j) {
      EXPECT_LT(relativeError(stacked(all.at(Key::state(j)), all.at(Key::constants())), ref.zs[j]), 1e-9)
          << "w " << w << " step " << k << " state " << j;
      EXPECT_LT(relativeError(smoother.jointMarginalCovariance({Key::state(j), Key::constants()}), ref.Ps[j]), 1e-9)
          << "w " << w << " step " << k << " state " << j;
    }
    // Bounded: window states + constants, and factors stay bounded too.
    EXPECT_EQ(smoother.numVariables(), static_cast<std::size_t>(std::min(k + 1, w) + 1));
    EXPECT_EQ(rep.num_variables, smoother.numVariables());
  }
}

INSTANTIATE_TEST_SUITE_P(Windows, FixedLagVsKalman, ::testing::Values(1, 3, 10));

TEST(IncrementalSmoother, RadarPaperEqualsBatchAfterEveryUpdateWhenIterated) {
  const models::Radar2D radar;
  const int steps = 300;
  const SimulatedRun run = radarPaperRun(radar, steps, 1);
  IncrementalSmoother smoother(iteratedToConvergence());
  auto [f0, v0] = gssm::testing::initialStep(radar);
  smoother.update(f0, v0);
  Values warm;  // the batch starts from its previous solution (as the smoother does)
  double worst = 0;
  for (int k = 1; k <= steps; ++k) {
    auto [f, v] = gssm::testing::nextStep(radar, smoother, k, run.measurements[k - 1].y,
                                          run.times[k] - run.times[k - 1]);
    const UpdateReport rep = smoother.update(f, v);
    const std::vector<Measurement> upto(run.measurements.begin(), run.measurements.begin() + k);
    Problem p = buildProblem(radar, upto);
    Values x = p.initial;
    for (const auto& kv : warm) x.at(kv.first) = kv.second;
    BatchSolver batch(strictBatch());  // equally strict
    const auto sum = batch.solve(p.graph, x);
    ASSERT_TRUE(sum.converged) << sum.toString();
    warm = x;
    const double tol = 1e-6;
    worst = std::max({worst, relativeError(smoother.estimate(Key::state(k)), x.at(Key::state(k))),
                      relativeError(smoother.estimate(Key::constants()), x.at(Key::constants()))});
    EXPECT_LT(relativeError(smoother.estimate(Key::state(k)), x.at(Key::state(k))), tol)
        << "step " << k << ": " << rep.toString();
    EXPECT_LT(relativeError(smoother.estimate(Key::constants()), x.at(Key::constants())), tol)
        << "step " << k << ": " << rep.toString();
  }
  std::cout << "incremental (iterated, Newton-polished) vs batch over 300 radar steps: worst relative difference "
            << worst << "\n";
}

// An iteration that stops while damped (here: one LM step per update) must
// not leave its Marquardt rows in the tree: the covariances it reports are
// those of the undamped information matrix, which the batch solver gives at
// the estimate by evaluateAt() (a damped tree's were 6–22% too small here
// with λ₀ = 1e-8, ~100× with the former λ₀ = 1e-4).
TEST(IncrementalSmoother, IterationStoppedWhileDampedReportsUndampedCovariances) {
  // A prior at the truth: each update's single LM step is kept, so the tree
  // is linearized at the estimate (a rejected step would leave the new
  // factors at their initial points, which the batch here does not model).
  models::Radar2D::Params prm;
  prm.prior_x = 0;
  prm.prior_xdot = 100;
  prm.prior_h = 1000;
  const models::Radar2D radar(prm);
  const int steps = 40;
  const SimulatedRun run = radarPaperRun(radar, steps, 4);
  SmootherOptions o;
  o.iterate_to_convergence = true;
  o.max_iterations = 1;  // one damped LM step per update, never converged
  IncrementalSmoother smoother(o);
  auto [f0, v0] = gssm::testing::initialStep(radar);
  smoother.update(f0, v0);
  for (int k = 1; k <= steps; ++k) {
    auto [f, v] = gssm::testing::nextStep(radar, smoother, k, run.measurements[k - 1].y,
                                          run.times[k] - run.times[k - 1]);
    smoother.update(f, v);
    if (k % 5) continue;
    const std::vector<Measurement> upto(run.measurements.begin(), run.measurements.begin() + k);
    Problem p = buildProblem(radar, upto);
    const Values x = smoother.calculateEstimate();
    BatchSolver batch;
    batch.evaluateAt(p.graph, x);
    const std::vector<Key> keys{Key::state(k), Key::constants()};
    const Eigen::MatrixXd expected = batch.jointMarginalCovariance(keys);
    const Eigen::MatrixXd got = smoother.jointMarginalCovariance(keys);
    // The tree is linearized one Gauss–Newton step behind its solution, so
    // the two agree to first order (≤ 5e-4 here); a damped tree's are off
    // by 0.06–0.2.
    EXPECT_LT((got - expected).norm() / expected.norm(), 1e-2) << "step " << k << "\n" << got << "\nvs\n" << expected;
  }
}

namespace {
// Streams `steps` radar paper-scenario measurements through a smoother and
// returns the reports at the requested steps.
template <class Smoother>
std::map<int, UpdateReport> radarReports(Smoother& smoother, int steps, const std::vector<int>& at) {
  const models::Radar2D radar;
  static std::map<int, SimulatedRun> cache;
  if (!cache.count(steps)) cache[steps] = radarPaperRun(radar, steps, 3);
  const SimulatedRun& run = cache[steps];
  auto [f0, v0] = gssm::testing::initialStep(radar);
  smoother.update(f0, v0);
  std::map<int, UpdateReport> out;
  for (int k = 1; k <= steps; ++k) {
    auto [f, v] = gssm::testing::nextStep(radar, smoother, k, run.measurements[k - 1].y, 0.05);
    const UpdateReport rep = smoother.update(f, v);
    if (std::find(at.begin(), at.end(), k) != at.end()) out[k] = rep;
  }
  return out;
}
}  // namespace

TEST(IncrementalSmoother, CliquesReeliminatedPerUpdateDoNotGrowWithHistory) {
  SmootherOptions o;
  o.relinearize = false;
  IncrementalSmoother smoother(o);
  const auto reps = radarReports(smoother, 100000, {1000, 100000});
  EXPECT_EQ(reps.at(1000).cliques_reeliminated, reps.at(100000).cliques_reeliminated);
  EXPECT_EQ(reps.at(100000).cliques_reeliminated, 3);  // x_c(k−1), x_c(k), x_b
  EXPECT_EQ(reps.at(1000).orphans, reps.at(100000).orphans);
  EXPECT_EQ(reps.at(100000).num_variables, 100002u);
}

TEST(FixedLagSmoother, HundredThousandStepsKeepVariablesAndFactorsBounded) {
  FixedLagSmootherOptions o;
  o.window = 10;
  FixedLagSmoother smoother(o);
  const auto reps = radarReports(smoother, 100000, {1000, 100000});
  for (const auto& [k, rep] : reps) {
    EXPECT_EQ(rep.num_variables, 11u) << "step " << k;  // window + constants
    EXPECT_EQ(rep.variables_marginalized, 1) << "step " << k;
    EXPECT_EQ(rep.cliques_reeliminated, reps.at(1000).cliques_reeliminated) << "step " << k;
  }
  // window process+measurement factors, the x_b prior, one marginal prior
  EXPECT_EQ(reps.at(100000).num_factors, reps.at(1000).num_factors);
  EXPECT_LE(reps.at(100000).num_factors, 2u * 10 + 2);
}

TEST(MultiRate, RangesEveryFifthStepBatchEqualsIncrementalAfterEveryUpdate) {
  // Inputs every step define the steps; measurements arrive every 5th step.
  std::mt19937 rng(12);
  models::LinearSystem sys = gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1);
  sys.B = Eigen::MatrixXd::Random(3, 1);
  const models::LinearModel model(sys);
  SimulationSpec spec;
  spec.steps = 40;
  const SimulatedRun run = simulate(model, spec, normalSampler(13));
  std::vector<Input> inputs;
  std::vector<Measurement> ms;
  for (int k = 0; k < spec.steps; ++k) {
    inputs.push_back({run.times[k], Eigen::VectorXd::Constant(1, std::cos(0.3 * k))});
    if ((k + 1) % 5 == 0) ms.push_back(run.measurements[static_cast<std::size_t>(k)]);
  }
  for (const Method method : {Method::Incremental, Method::FixedLag, Method::Ekf, Method::PaperWindow}) {
    EstimatorOptions o;
    o.method = method;
    o.fixed_lag.window = o.paper_window.window = 30;  // longer than the run: fixed-lag then equals incremental
    auto est = makeEstimator(model, o);
    std::size_t next_m = 0;
    for (int k = 0; k < spec.steps; ++k) {
      est->addInput(inputs[static_cast<std::size_t>(k)].t, inputs[static_cast<std::size_t>(k)].u);
      if (next_m < ms.size() && std::abs(ms[next_m].t - run.times[k + 1]) < 1e-12) {
        est->addMeasurement(ms[next_m].t, ms[next_m].y);
        ++next_m;
        if (method == Method::PaperWindow) continue;  // runs, but is not exact
        const std::vector<Measurement> upto(ms.begin(), ms.begin() + static_cast<long>(next_m));
        const std::vector<Input> in_upto(inputs.begin(), inputs.begin() + k + 1);
        Problem p = buildProblem(model, upto, in_upto);
        Values x = p.initial;
        BatchSolver batch;
        ASSERT_TRUE(batch.solve(p.graph, x).converged);
        const auto kk = static_cast<std::int64_t>(p.times.size()) - 1;
        ASSERT_EQ(est->step(), kk) << method;
        Eigen::VectorXd z(5);
        z << x.at(Key::state(kk)), x.at(Key::constants());
        EXPECT_LT(relativeError(est->current().mean, z), 1e-8) << method << " step " << kk;
        EXPECT_LT(relativeError(est->current().covariance,
                                batch.jointMarginalCovariance({Key::state(kk), Key::constants()})),
                  1e-8)
            << method << " step " << kk;
      }
    }
    EXPECT_EQ(next_m, ms.size());
  }
}

#include "gssm/models/nav2d.h"

namespace {
// A Nav2D run: a curving trajectory from measured accelerations (bias
// included), ranges to 4 beacons every `every` steps.
SimulatedRun navRun(const models::Nav2D& nav, int steps, int every, unsigned seed) {
  SimulationSpec spec;
  spec.steps = steps;
  spec.measure_every = every;
  spec.xb = Eigen::Vector3d(0.05, -0.03, 2.0);
  spec.input = [](double t, const Eigen::VectorXd&) { return Eigen::VectorXd(Eigen::Vector2d(0.5 * std::cos(0.2 * t), 0.5 * std::sin(0.2 * t))); };
  return simulate(nav, spec, normalSampler(seed));
}

// Streams a run (inputs at every step, measurements as they come).
void stream(Estimator& est, const SimulatedRun& run, const std::function<void(int)>& after_measurement) {
  std::size_t m = 0;
  for (std::size_t k = 0; k < run.inputs.size(); ++k) {
    est.addInput(run.inputs[k].t, run.inputs[k].u);
    for (; m < run.measurements.size() && run.measurements[m].t <= run.times[k + 1] + 1e-12; ++m) {
      est.addMeasurement(run.measurements[m].t, run.measurements[m].y);
      after_measurement(static_cast<int>(m) + 1);
    }
  }
}
}  // namespace

TEST(Nav2D, BatchEqualsIncrementalAfterEveryUpdateAndFixedLagEqualsIncremental) {
  const models::Nav2D nav;
  for (int every : {1, 5}) {
    const SimulatedRun run = navRun(nav, 150, every, 21);
    EstimatorOptions inc_o, fl_o;
    inc_o.method = Method::Incremental;
    inc_o.smoother.iterate_to_convergence = true;
    fl_o.method = Method::FixedLag;
    fl_o.fixed_lag.window = fl_o.paper_window.window = 1000;  // longer than the run
    fl_o.smoother.iterate_to_convergence = true;
    auto inc = makeEstimator(nav, inc_o), fl = makeEstimator(nav, fl_o);
    Values warm;
    stream(*inc, run, [&](int nm) {
      const std::vector<Measurement> ms(run.measurements.begin(), run.measurements.begin() + nm);
      const auto k = inc->step();
      const std::vector<Input> in(run.inputs.begin(), run.inputs.begin() + k);
      Problem p = buildProblem(nav, ms, in);
      Values x = p.initial;
      for (const auto& kv : warm)
        if (x.contains(kv.first)) x.at(kv.first) = kv.second;
      BatchSolverOptions bo;
      bo.relative_cost_tolerance = 0;
      bo.gradient_tolerance = 0;
      bo.step_tolerance = 1e-13;
      BatchSolver batch(bo);
      ASSERT_TRUE(batch.solve(p.graph, x).converged);
      warm = x;
      ASSERT_EQ(static_cast<std::int64_t>(p.times.size()) - 1, k);
      Eigen::VectorXd z(7);
      z << x.at(Key::state(k)), x.at(Key::constants());
      EXPECT_LT(relativeError(inc->current().mean, z), 1e-6) << "every " << every << " step " << k;
    });
    stream(*fl, run, [](int) {});
    EXPECT_LT(relativeError(fl->current().mean, inc->current().mean), 1e-6) << "every " << every;
    EXPECT_LT(relativeError(fl->current().covariance, inc->current().covariance), 1e-6) << "every " << every;
  }
}

// A user's graph need not number its states consecutively: states far apart
// (and before the first) live in the engine's table apart from the dense
// run of steps. The estimates and marginals must still be the batch
// solution's, after every update.
TEST(IncrementalSmoother, StatesFarApartInStepEqualTheBatchSolve) {
  const std::vector<std::int64_t> steps{0, 1, 2, 5000, 5001, -7000, 3, 40000, -6999, 4};
  std::mt19937 rng(8);
  std::normal_distribution<double> g;
  IncrementalSmoother smoother(SmootherOptions{}, EliminationOrdering::ConstrainedColamd);
  FactorGraph graph;
  Values all;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const Key k = Key::state(steps[i]);
    std::vector<FactorPtr> added;
    Values initial;
    const Eigen::Vector2d mean(g(rng), 10 + g(rng));
    initial.insert(k, mean);
    all.insert(k, mean);
    added.push_back(std::make_shared<PriorFactor>(k, Gaussian{mean, Eigen::Matrix2d::Identity() * (4.0 + i)}));
    if (i > 0) {  // a linear link to the previous state: x_k − x_prev = [1, 0] ± 0.5
      const Key prev = Key::state(steps[i - 1]);
      Values at;
      at.insert(prev, Eigen::Vector2d::Zero());
      at.insert(k, Eigen::Vector2d::Zero());
      added.push_back(std::make_shared<LinearGaussianFactor>(
          std::vector<Key>{prev, k}, std::vector<Eigen::MatrixXd>{-2.0 * Eigen::Matrix2d::Identity(), 2.0 * Eigen::Matrix2d::Identity()},
          Eigen::Vector2d(2.0, 0.0), at));
    }
    smoother.update(added, initial);
    for (const auto& f : added) graph.add(f);
    Values x = all;
    BatchSolver batch;
    ASSERT_TRUE(batch.solve(graph, x).converged);
    const Values inc = smoother.calculateEstimate();
    ASSERT_EQ(inc.size(), x.size());
    for (const auto& kv : x) {
      EXPECT_LT(relativeError(inc.at(kv.first), kv.second), 1e-9) << kv.first.toString() << " after " << i + 1;
      EXPECT_LT(relativeError(smoother.jointMarginalCovariance({kv.first}), batch.jointMarginalCovariance({kv.first})),
                1e-9)
          << kv.first.toString() << " after " << i + 1;
    }
  }
}

// The engine holds one model's process and measurement factors as their
// numbers and any other model's as objects (docs/DESIGN.md §6). A smoother
// fed every other step's factors from a second, identical radar model takes
// both paths — evaluation, relinearization, cost, covariances — and must
// agree bit for bit with one fed a single model's (fails if a slot were
// evaluated with the wrong model or its factor rebuilt on it).
TEST(IncrementalSmoother, FactorsOfASecondModelAreHeldAsObjectsAndChangeNoBit) {
  const models::Radar2D radar, twin;
  const int steps = 200;
  const SimulatedRun run = radarPaperRun(radar, steps, 3);
  IncrementalSmoother one, mixed;
  {
    auto [f, v] = gssm::testing::initialStep(radar);
    one.update(f, v);
    auto [g, w] = gssm::testing::initialStep(twin);
    mixed.update(g, w);
  }
  for (int k = 1; k <= steps; ++k) {
    const Eigen::VectorXd& y = run.measurements[k - 1].y;
    const double dt = run.times[k] - run.times[k - 1];
    auto [f, v] = gssm::testing::nextStep(radar, one, k, y, dt);
    const UpdateReport a = one.update(f, v);
    auto [g, w] = gssm::testing::nextStep(k % 2 ? twin : radar, mixed, k, y, dt);
    const UpdateReport b = mixed.update(g, w);
    ASSERT_EQ(a.factors_relinearized, b.factors_relinearized) << "step " << k;
    for (const Key& key : {Key::state(k), Key::state(k / 2)}) {
      ASSERT_TRUE(one.estimate(key) == mixed.estimate(key)) << key.toString() << " at step " << k;
      ASSERT_TRUE(one.jointMarginalCovariance({key, Key::constants()}) ==
                  mixed.jointMarginalCovariance({key, Key::constants()}))
          << key.toString() << " at step " << k;
    }
    ASSERT_TRUE(one.estimate(Key::constants()) == mixed.estimate(Key::constants())) << "step " << k;
  }
  EXPECT_GT(one.numFactors(), 2u * steps);
}

// The same with a second model whose measurement function differs (a linear
// model of the same dimensions): every third step adds its measurement of
// the state and constants. The smoother must solve the graph of both models'
// factors, which the batch solver evaluates as the objects themselves (fails
// if the engine evaluated the second model's factors with the first's h).
TEST(IncrementalSmoother, FactorsOfTwoDifferentModelsEqualTheBatchSolve) {
  const models::Radar2D radar;
  std::mt19937 rng(21);
  const models::LinearModel other(gssm::testing::randomLinearSystem(rng, 1, 2, 1, 0.05));
  const int steps = 90;
  const SimulatedRun run = radarPaperRun(radar, steps, 4);
  IncrementalSmoother smoother(iteratedToConvergence());
  FactorGraph graph;
  auto [f0, v0] = gssm::testing::initialStep(radar);
  smoother.update(f0, v0);
  for (const auto& f : f0) graph.add(f);
  for (int k = 1; k <= steps; ++k) {
    auto [f, v] = gssm::testing::nextStep(radar, smoother, k, run.measurements[k - 1].y, run.times[k] - run.times[k - 1]);
    if (k % 3 == 0) {  // the linear model's reading of the predicted state, 0.1 off
      const Eigen::VectorXd y = other.h(v.at(Key::state(k)), smoother.estimate(Key::constants())).array() + 0.1;
      f.push_back(std::make_shared<MeasurementFactor>(other, k, y));
    }
    smoother.update(f, v);
    for (const auto& g : f) graph.add(g);
    if (k % 30 != 0) continue;
    Values x = smoother.calculateEstimate();  // a start at the answer: the test is where it ends
    BatchSolver batch(strictBatch());
    ASSERT_TRUE(batch.solve(graph, x).converged);
    for (const Key& key : {Key::state(k), Key::state(k / 2), Key::constants()})
      EXPECT_LT(relativeError(smoother.estimate(key), x.at(key)), 1e-6) << key.toString() << " at step " << k;
  }
}
