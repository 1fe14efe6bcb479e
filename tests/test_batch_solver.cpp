#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <functional>
#include <iostream>
#include <random>

#include "gssm/solvers/batch_solver.h"
#include "gssm/solvers/ekf.h"
#include "gssm/core/error.h"
#include "gssm/core/time.h"
#include "gssm/estimator/estimator.h"
#include "gssm/models/linear.h"
#include "gssm/models/radar2d.h"
#include "gssm/factors/problem.h"
#include "gssm/model/simulation.h"
#include "reference_kalman.h"
#include "solvers/anderson.h"
#include "solvers/curvature.h"

using namespace gssm;
using gssm::testing::relativeError;

namespace {

using gssm::testing::normalSampler;
using gssm::testing::radarPaperRun;

// The dense Jacobian J and residual r assembled independently of the
// solver, from each factor's Jacobian blocks.
void denseJacobian(const FactorGraph& graph, const Values& x, Eigen::MatrixXd& J, Eigen::VectorXd& r_all) {
  std::map<Key, Eigen::Index> off;
  Eigen::Index n = 0;
  for (const auto& kv : x) {
    off[kv.first] = n;
    n += kv.second.size();
  }
  J = Eigen::MatrixXd::Zero(0, n);
  r_all.resize(0);
  for (const auto& f : graph) {
    Eigen::VectorXd r;
    std::vector<Eigen::MatrixXd> Jb;
    f->linearize(x, r, &Jb);
    Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(r.size(), n);
    for (std::size_t i = 0; i < Jb.size(); ++i)
      rows.middleCols(off[f->keys()[i]], Jb[i].cols()) = Jb[i];
    J.conservativeResize(J.rows() + r.size(), Eigen::NoChange);
    J.bottomRows(r.size()) = rows;
    r_all.conservativeResize(r_all.size() + r.size());
    r_all.tail(r.size()) = r;
  }
}

// Dense information matrix JᵀJ and gradient Jᵀr, the same way.
void denseNormalEquations(const FactorGraph& graph, const Values& x, Eigen::MatrixXd& H,
                          Eigen::VectorXd& g) {
  Eigen::MatrixXd J;
  Eigen::VectorXd r;
  denseJacobian(graph, x, J, r);
  H = J.transpose() * J;
  g = J.transpose() * r;
}

// A scalar factor a·x_i + c·x_j − y (σ = 1 after scaling), on one or two
// variables: a stiff link between states, or a state and a constant seen
// together.
class ScalarFactor final : public Factor {
 public:
  ScalarFactor(std::vector<Key> keys, Eigen::VectorXd coefficients, double y)
      : Factor(std::move(keys), 1), a_(std::move(coefficients)), y_(y) {}
  void linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                   std::vector<Eigen::MatrixXd>* J) const override {
    double v = -y_;
    for (Eigen::Index i = 0; i < a_.size(); ++i) v += a_[i] * (*x[i])[0];
    r = Eigen::VectorXd::Constant(1, v);
    if (J) {
      J->resize(static_cast<std::size_t>(a_.size()));
      for (Eigen::Index i = 0; i < a_.size(); ++i) (*J)[static_cast<std::size_t>(i)] = Eigen::MatrixXd::Constant(1, 1, a_[i]);
    }
  }
  std::string describe() const override { return "scalar"; }

 private:
  Eigen::VectorXd a_;
  double y_;
};

// Priors at the truth (the paper's, 143σ off, leave residuals so large that
// the Gauss–Newton model overstates every step's decrease) and a process
// noise that keeps κ(H) small enough for a tight dense comparison.
models::Radar2D radarWithPriorsAtTheTruth() {
  models::Radar2D::Params params;
  params.q = 0.5;
  params.prior_x = 0, params.prior_xdot = 100, params.prior_h = 1000;
  return models::Radar2D(params);
}

// A linear model whose constant b2 enters neither f nor h (with its prior
// left out, nothing determines it).
models::LinearModel modelBlindToB2() {
  std::mt19937 rng(11);
  models::LinearSystem sys = gssm::testing::randomLinearSystem(rng, 2, 2, 1, 0.1);
  sys.A_b.col(1).setZero();
  sys.C_b.col(1).setZero();
  return models::LinearModel(sys);
}

}  // namespace

// r(x) = x³ − x on one variable: zero (a minimum of ½r²) at −1, 0 and 1.
// From x = 0.55 the Gauss–Newton step lands at −3.6 (cost 900 against
// 0.07), in −1's basin; LM must reject it, go back exactly where it was,
// and descend to 0.
class CubicMinusX final : public Factor {
 public:
  CubicMinusX() : Factor({Key::state(0)}, 1) {}
  void linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                   std::vector<Eigen::MatrixXd>* J) const override {
    const double v = (*x[0])[0];
    r = Eigen::VectorXd::Constant(1, v * v * v - v);
    if (J) {
      J->resize(1);
      (*J)[0] = Eigen::MatrixXd::Constant(1, 1, 3 * v * v - 1);
    }
  }
  std::string describe() const override { return "x³ − x"; }
};

TEST(BatchSolver, RejectedStepsGoBackToWhereTheyLeft) {
  FactorGraph graph;
  graph.add(std::make_shared<CubicMinusX>());
  Values x;
  x.insert(Key::state(0), Eigen::VectorXd::Constant(1, 0.55));
  BatchSolver solver;
  const BatchSolverSummary sum = solver.solve(graph, x);
  ASSERT_TRUE(sum.converged) << sum.toString();
  EXPECT_GT(sum.rejected_steps, 0) << sum.toString();
  // Continuing from a rejected candidate instead would end at −1.
  EXPECT_NEAR(x.at(Key::state(0))[0], 0.0, 1e-9) << sum.toString();
  EXPECT_NEAR(solver.marginalCovariance(Key::state(0))(0, 0), 1.0, 1e-9);  // (J(0)ᵀJ(0))⁻¹ = 1
}

// The GSSM MAP over all steps is the RTS smoother of the stacked Kalman model.
TEST(BatchSolver, LinearModelEqualsRtsSmootherAtEveryStep) {
  std::mt19937 rng(42);
  const models::LinearModel model(gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1));
  SimulationSpec spec;
  spec.steps = 60;
  const SimulatedRun run = simulate(model, spec, normalSampler(3));
  Problem p = buildProblem(model, run.measurements);
  BatchSolver solver;
  Values x = p.initial;
  const BatchSolverSummary sum = solver.solve(p.graph, x);
  ASSERT_TRUE(sum.converged) << sum.toString();

  const auto ref = gssm::testing::kalmanAndRts(gssm::testing::stack(model, 0.1), run.measurements);
  const auto& xb = x.at(Key::constants());
  for (int k = 0; k <= spec.steps; ++k) {
    Eigen::VectorXd z(5);
    z << x.at(Key::state(k)), xb;
    EXPECT_LT(relativeError(z, ref.zs[k]), 1e-8) << "mean at step " << k;
    const Eigen::MatrixXd P = solver.jointMarginalCovariance({Key::state(k), Key::constants()});
    EXPECT_LT(relativeError(P, ref.Ps[k]), 1e-8) << "covariance at step " << k;
  }
  // The newest state of the smoother is the Kalman filter's estimate.
  Eigen::VectorXd zN(5);
  zN << x.at(Key::state(spec.steps)), xb;
  EXPECT_LT(relativeError(zN, ref.zf.back()), 1e-8);
  EXPECT_LT(relativeError(solver.jointMarginalCovariance({Key::state(spec.steps), Key::constants()}),
                          ref.Pf.back()), 1e-8);
}

// A chain of 16384 factors or more is linearized in two halves (on two
// threads where allowed): the same bits with one thread or two, the RTS
// smoother's answer, and a non-finite residual in the second half named
// as in one pass, the values left as they were.
TEST(BatchSolver, ALongChainInTwoHalvesEqualsTheRtsSmootherWithAnyThreadCount) {
  std::mt19937 rng(17);
  models::LinearSystem sys = gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1);
  sys.A_c = -0.5 * Eigen::MatrixXd::Identity(3, 3);  // stable: 830 s of a random A_c may grow by 10^100
  const models::LinearModel model(sys);
  SimulationSpec spec;
  spec.steps = 8300;  // 2 priors + 8300 process + 8300 measurement factors
  const SimulatedRun run = simulate(model, spec, normalSampler(8));
  const Problem p = buildProblem(model, run.measurements);
  ASSERT_GE(p.graph.size(), 16384u);
  Values one = p.initial, two = p.initial;
  BatchSolverOptions o;
  BatchSolver a(o);
  o.threads = 2;
  BatchSolver b(o);
  ASSERT_TRUE(a.solve(p.graph, one).converged);
  ASSERT_TRUE(b.solve(p.graph, two).converged);
  const auto ref = gssm::testing::kalmanAndRts(gssm::testing::stack(model, 0.1), run.measurements);
  for (int k : {0, 1, 4000, 4150, 4151, 4152, 8299, 8300}) {
    const std::vector<Key> keys{Key::state(k), Key::constants()};
    EXPECT_EQ(one.at(Key::state(k)), two.at(Key::state(k))) << "step " << k;
    EXPECT_EQ(a.jointMarginalCovariance(keys), b.jointMarginalCovariance(keys)) << "step " << k;
    Eigen::VectorXd z(5);
    z << one.at(Key::state(k)), one.at(Key::constants());
    EXPECT_LT(relativeError(z, ref.zs[static_cast<std::size_t>(k)]), 1e-8) << "mean at step " << k;
    EXPECT_LT(relativeError(a.jointMarginalCovariance(keys), ref.Ps[static_cast<std::size_t>(k)]), 1e-8)
        << "covariance at step " << k;
  }
  Values bad = p.initial;
  bad.at(Key::state(6000))[1] = std::numeric_limits<double>::quiet_NaN();
  const Values before = bad;
  try {
    b.solve(p.graph, bad);
    FAIL() << "a NaN state must be refused";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("x_c(6000)"), std::string::npos) << e.what();
  }
  for (int k : {0, 5999, 6000, 8300})
    EXPECT_TRUE(bad.at(Key::state(k)).isApprox(before.at(Key::state(k))) || k == 6000) << "step " << k;
  EXPECT_TRUE(std::isnan(bad.at(Key::state(6000))[1]));
}

TEST(BatchSolver, GaussNewtonAndLevenbergMarquardtAgreeOnLinearModel) {
  std::mt19937 rng(5);
  const models::LinearModel model(gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1));
  SimulationSpec spec;
  spec.steps = 30;
  const SimulatedRun run = simulate(model, spec, normalSampler(9));
  Problem p = buildProblem(model, run.measurements);
  Values lm = p.initial, gn = p.initial;
  const auto sum_lm = BatchSolver(BatchSolverOptions{}).solve(p.graph, lm);
  EXPECT_TRUE(sum_lm.converged) << sum_lm.toString();
  std::cout << sum_lm.toString() << "\n";
  BatchSolverOptions o;
  o.method = BatchSolverOptions::Method::GaussNewton;
  const auto sum = BatchSolver(o).solve(p.graph, gn);
  EXPECT_TRUE(sum.converged) << sum.toString();
  EXPECT_LE(sum.iterations, 2);  // linear: one Gauss–Newton step solves it
  for (const auto& kv : lm) EXPECT_LT(relativeError(kv.second, gn.at(kv.first)), 1e-9);
}

TEST(BatchSolver, RadarPaperScenarioConvergesToZeroGradient) {
  const models::Radar2D radar;
  const SimulatedRun run = radarPaperRun(radar, 400, 1);
  Problem p = buildProblem(radar, run.measurements);
  Values x = p.initial;
  BatchSolver solver;
  const BatchSolverSummary sum = solver.solve(p.graph, x);
  ASSERT_TRUE(sum.converged) << sum.toString();
  EXPECT_LT(sum.final_cost, sum.initial_cost);
  // Independent check: central differences of the total cost vanish at the
  // solution (relative to the curvature scale of each variable).
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  denseNormalEquations(p.graph, x, H, g);
  for (auto& kv : x) {
    for (Eigen::Index i = 0; i < kv.second.size(); ++i) {
      const double h = 1e-4 * std::max(1.0, std::abs(kv.second[i]));
      Values xp = x, xm = x;
      xp.at(kv.first)[i] += h;
      xm.at(kv.first)[i] -= h;
      const double dcost = (p.graph.cost(xp) - p.graph.cost(xm)) / (2 * h);
      EXPECT_LT(std::abs(dcost), 1e-4) << kv.first.toString() << " component " << i;
    }
  }
  EXPECT_LT(g.lpNorm<Eigen::Infinity>(), 1e-6);
  // A minimum, not a saddle: the information matrix at the solution is
  // positive definite (the solver factored it for the covariances).
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff(), 0.0);
  // No assertion that the estimate is near the truth: the paper's prior is
  // 14σ (xdot) and 143σ (h) away from it, and the MAP is biased by it.
}

TEST(BatchSolver, MarginalCovariancesEqualDenseInverse) {
  // A larger process noise than the paper's keeps κ(H) small enough for a
  // tight comparison with a dense inverse (the paper's Q gives κ ≈ 1e8).
  models::Radar2D::Params params;
  params.q = 0.5;
  const models::Radar2D radar(params);
  const SimulatedRun run = radarPaperRun(radar, 25, 2);
  Problem p = buildProblem(radar, run.measurements);
  Values x = p.initial;
  BatchSolver solver;
  ASSERT_TRUE(solver.solve(p.graph, x).converged);
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  denseNormalEquations(p.graph, x, H, g);
  const Eigen::MatrixXd Sigma = H.inverse();
  // Both sides carry rounding errors of order ε·κ(H): compare to that.
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues();
  const double tol = 100 * 2.2e-16 * ev.maxCoeff() / ev.minCoeff();
  ASSERT_LT(tol, 1e-8) << "test problem too ill-conditioned to be meaningful";
  // columns: x_c(0..25) then x_b (2)
  const Eigen::Index nb0 = 26;
  EXPECT_LT(relativeError(solver.marginalCovariance(Key::constants()),
                          Sigma.block(nb0, nb0, 2, 2)), tol);
  for (int k : {0, 1, 12, 25}) {
    EXPECT_NEAR(solver.marginalCovariance(Key::state(k))(0, 0), Sigma(k, k),
                tol * Sigma(k, k));
    const Eigen::MatrixXd joint =
        solver.jointMarginalCovariance({Key::state(k), Key::constants()});
    EXPECT_NEAR(joint(0, 1), Sigma(k, nb0), tol * std::sqrt(Sigma(k, k) * Sigma(nb0, nb0)));
    EXPECT_NEAR(joint(0, 2), Sigma(k, nb0 + 1), tol * std::sqrt(Sigma(k, k) * Sigma(nb0 + 1, nb0 + 1)));
  }
  // A pair the factor does not couple (x_c(0), x_c(25)) takes the solve path.
  const Eigen::MatrixXd far = solver.jointMarginalCovariance({Key::state(0), Key::state(25)});
  EXPECT_NEAR(far(0, 1), Sigma(0, 25), tol * std::sqrt(Sigma(0, 0) * Sigma(25, 25)));
  EXPECT_NEAR(far(1, 1), Sigma(25, 25), tol * Sigma(25, 25));
  // A key the solve never had is named.
  try {
    solver.marginalCovariance(Key::state(26));
    FAIL() << "unknown variable accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find(Key::state(26).toString()), std::string::npos) << e.what();
  }
}

// Gauss–Newton's last step, or Levenberg–Marquardt's undamped finishing one.
TEST(BatchSolver, ALastUndampedStepWithoutRelinearizationKeepsTheFactorizationItCameFrom) {
  const models::Radar2D radar = radarWithPriorsAtTheTruth();
  const SimulatedRun run = radarPaperRun(radar, 25, 3);
  const Problem p = buildProblem(radar, run.measurements);
  for (const auto method : {BatchSolverOptions::Method::GaussNewton, BatchSolverOptions::Method::LevenbergMarquardt}) {
    SCOPED_TRACE(BatchSolverOptions::methodName(method));
    BatchSolverOptions o;
    o.method = method;
    o.relative_cost_tolerance = 1e-9;
    Values x_ref = p.initial, x = p.initial;
    BatchSolver reference(o);
    const BatchSolverSummary ref = reference.solve(p.graph, x_ref);
    o.relinearize_at_solution = false;
    BatchSolver solver(o);
    const BatchSolverSummary sum = solver.solve(p.graph, x);
    ASSERT_TRUE(ref.converged && sum.converged) << ref.toString() << "\n" << sum.toString();
    EXPECT_LT(sum.factorizations, ref.factorizations) << "one linearization and factorization fewer";
    // The same iterate: the last step was taken either way.
    for (const auto& kv : x)
      EXPECT_LT((kv.second - x_ref.at(kv.first)).norm(), 1e-6 * (1 + kv.second.norm())) << kv.first.toString();
    // The covariances are the dense inverse of JᵀJ at the point before the
    // last step, which is within that step of the solution.
    const Values at = solver.factoredAt(x);
    Eigen::MatrixXd H;
    Eigen::VectorXd g;
    denseNormalEquations(p.graph, at, H, g);
    const Eigen::MatrixXd Sigma = H.inverse();
    const Eigen::Index nb0 = 26;
    EXPECT_LT(relativeError(solver.marginalCovariance(Key::constants()), Sigma.block(nb0, nb0, 2, 2)), 1e-8);
    EXPECT_NEAR(solver.marginalCovariance(Key::state(7))(0, 0), Sigma(7, 7), 1e-8 * Sigma(7, 7));
    EXPECT_LT(relativeError(solver.marginalCovariance(Key::constants()), reference.marginalCovariance(Key::constants())),
              1e-4);
    double moved = 0;
    for (const auto& kv : x) moved = std::max(moved, (kv.second - at.at(kv.first)).norm());
    EXPECT_GT(moved, 0.0) << "the last step was taken after the factorization";
    // Restoring from that point reproduces the factorization exactly.
    BatchSolver restored(o);
    restored.evaluateAt(p.graph, at);
    EXPECT_EQ(restored.marginalCovariance(Key::constants()), solver.marginalCovariance(Key::constants()));
    // Not with a Newton polish, which relinearizes at the solution.
    o.newton_polish_steps = 1;
    std::string why;
    EXPECT_FALSE(o.validate(&why));
    EXPECT_NE(why.find("relinearize_at_solution"), std::string::npos) << why;
  }
}

// A variable that does not factor beside a far stiffer one eliminated
// before it: the message names both, for rounding may be what lost it.
// Here x2 and x3 are held only in their difference (truly singular at x3,
// its JᵀJ diagonal 1), and x0 has 1e10.
TEST(BatchSolver, SingularBesideAStiffVariableNamesTheStiffOne) {
  Values x;
  for (int k = 0; k < 4; ++k) x.insert(Key::state(k), Eigen::VectorXd::Zero(1));
  const auto linear = [&x](std::vector<Key> keys, std::vector<Eigen::MatrixXd> J) {
    return std::make_shared<LinearGaussianFactor>(keys, J, Eigen::VectorXd::Zero(1), x);
  };
  const Eigen::MatrixXd one = Eigen::MatrixXd::Ones(1, 1);
  FactorGraph g;
  g.add(linear({Key::state(0)}, {1e5 * one}));
  g.add(linear({Key::state(0), Key::state(1)}, {one, -one}));
  g.add(linear({Key::state(2), Key::state(3)}, {one, -one}));
  BatchSolverOptions o;
  o.method = BatchSolverOptions::Method::GaussNewton;
  const auto messageOf = [&](const FactorGraph& graph) {  // x2 + x3 is free: it must not factor
    Values y = x;
    try {
      BatchSolver(o).solve(graph, y);
    } catch (const NumericalError& e) {
      return std::string(e.what());
    }
    return std::string("factored");
  };
  const std::string stiff = messageOf(g);
  EXPECT_NE(stiff.find("x_c(3) component 0"), std::string::npos) << stiff;
  EXPECT_NE(stiff.find("x_c(0) component 0, eliminated before it, has 1e+10"), std::string::npos) << stiff;
  EXPECT_NE(stiff.find("rounding"), std::string::npos) << stiff;
  // Without the stiff one, the plain explanation.
  FactorGraph soft;
  soft.add(linear({Key::state(0)}, {one}));
  soft.add(g[1]);
  soft.add(g[2]);
  const std::string plain = messageOf(soft);
  EXPECT_NE(plain.find("x_c(3) component 0"), std::string::npos) << plain;
  EXPECT_EQ(plain.find("rounding"), std::string::npos) << plain;
  EXPECT_NE(plain.find("do not determine it"), std::string::npos) << plain;
}

TEST(BatchSolver, SingularSystemNamesTheVariableAndLeavesValuesUnchanged) {
  // A linear model where constant b2 enters nothing and has no prior
  // information beyond... we remove its prior by building the graph by hand.
  const models::LinearModel model = modelBlindToB2();
  FactorGraph g;
  g.add(std::make_shared<PriorFactor>(Key::state(0), model.priorState()));
  g.add(std::make_shared<ProcessFactor>(model, 0, Eigen::VectorXd(0), 0.1));
  g.add(std::make_shared<MeasurementFactor>(model, 1, Eigen::VectorXd::Constant(1, 0.3)));
  // prior on b1 only, through a 1-row linear factor
  Values x0;
  x0.insert(Key::state(0), Eigen::VectorXd::Zero(2));
  x0.insert(Key::state(1), Eigen::VectorXd::Zero(2));
  x0.insert(Key::constants(), Eigen::VectorXd::Zero(2));
  Values lin;
  lin.insert(Key::constants(), Eigen::VectorXd::Zero(2));
  g.add(std::make_shared<LinearGaussianFactor>(
      std::vector<Key>{Key::constants()}, std::vector<Eigen::MatrixXd>{Eigen::RowVector2d(1, 0)},
      Eigen::VectorXd::Zero(1), lin));
  Values x = x0;
  BatchSolverOptions o;
  o.method = BatchSolverOptions::Method::GaussNewton;
  try {
    BatchSolver(o).solve(g, x);
    FAIL() << "singular system accepted";
  } catch (const NumericalError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("x_b"), std::string::npos) << msg;
    EXPECT_NE(msg.find("constant"), std::string::npos) << msg;
    EXPECT_NE(msg.find("component 1"), std::string::npos) << msg;  // b2, the one nothing determines
    EXPECT_NE(msg.find("nothing measures it"), std::string::npos) << msg;  // its column of J is zero
  }
  for (const auto& kv : x0) EXPECT_EQ(x.at(kv.first), kv.second);
  // Levenberg–Marquardt: damping lets it iterate (the iterate lives in the
  // caller's values) before the undamped system at the end is found
  // singular; the values are put back as they came.
  Values start = x0;
  start.at(Key::state(1)) << 0.7, -0.2;  // away from the solution, so steps are taken
  x = start;
  EXPECT_THROW(BatchSolver().solve(g, x), NumericalError);
  for (const auto& kv : start) EXPECT_EQ(x.at(kv.first), kv.second) << kv.first.toString();
}

TEST(BatchSolverOptions, ValidateExplainsWhatIsWrong) {
  BatchSolverOptions o;
  std::string why;
  EXPECT_TRUE(o.validate(&why));
  o.max_iterations = 0;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("max_iterations"), std::string::npos);
  EXPECT_THROW(BatchSolver{o}, InvalidArgument);
}

TEST(Problem, RejectsTimesGoingBackwardsAndGroupsEqualTimesIntoOneStep) {
  const models::Radar2D radar;
  std::vector<Measurement> ms{{0.05, Eigen::VectorXd::Constant(1, 1000)},
                              {0.04, Eigen::VectorXd::Constant(1, 1000)}};
  try {
    buildProblem(radar, ms);
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("measurement 1"), std::string::npos) << e.what();
  }
  ms[1].t = 0.05;  // two measurements at one time: one step, two measurement factors
  const Problem p = buildProblem(radar, ms);
  EXPECT_EQ(p.times.size(), 2u);
  EXPECT_EQ(p.graph.size(), 5u);  // 2 priors, 1 process, 2 measurements
}

// GPS-second time bases (1.4e9 s: one ulp is 2.4e-7 s): a measurement one
// ulp after another is at its instant — one step in the batch and in a
// streaming run, the same numbers as at exactly that time — and instants a
// second apart are not the same (the old 1e-9 relative rule merged 1.4 s).
TEST(Problem, InstantsAtGpsSecondsWithinRoundingShareAStep) {
  const double t0 = 1436038461.854, t1 = t0 + 0.05;
  EXPECT_TRUE(sameTime(t1, std::nextafter(t1, 2 * t1)));
  EXPECT_FALSE(sameTime(t1, t1 + 1.0));
  EXPECT_FALSE(sameTime(t1, t1 + 1e-3));
  EXPECT_TRUE(sameTime(0.5, 0.5 + 5e-7));
  EXPECT_FALSE(sameTime(0.5, 0.5 + 2e-6));
  const models::Radar2D radar;
  std::vector<Measurement> exact{{t1, Eigen::VectorXd::Constant(1, 1000)}, {t1, Eigen::VectorXd::Constant(1, 1001)},
                                 {t1 + 0.05, Eigen::VectorXd::Constant(1, 1002)}};
  std::vector<Measurement> ulp = exact;
  ulp[1].t = std::nextafter(t1, 2 * t1);
  EXPECT_EQ(buildProblem(radar, ulp, {}, t0).times, buildProblem(radar, exact, {}, t0).times);
  EXPECT_EQ(buildProblem(radar, ulp, {}, t0).times.size(), 3u);
  for (Method method : {Method::Ekf, Method::Incremental, Method::FixedLag}) {
    EstimatorOptions o(method);
    o.t0 = t0;
    auto a = makeEstimator(radar, o), b = makeEstimator(radar, o);
    for (std::size_t i = 0; i < exact.size(); ++i) a->addMeasurement(exact[i]), b->addMeasurement(ulp[i]);
    EXPECT_EQ(b->step(), 2) << methodName(method);
    EXPECT_EQ(a->current().mean, b->current().mean) << methodName(method);
    EXPECT_EQ(a->current().covariance, b->current().covariance) << methodName(method);
  }
}

TEST(NewtonPolish, CurvaturePlusGaussNewtonEqualsTheNumericalHessianOfEachFactor) {
  // Independent check of the second-order terms: JᵀJ + Σ r∇²r must equal
  // the Hessian of ½‖r‖² by central second differences of the cost alone.
  const models::Radar2D radar;
  std::mt19937 rng(4);
  std::normal_distribution<double> n01;
  for (int trial = 0; trial < 5; ++trial) {
    Values x;
    x.insert(Key::state(3), Eigen::VectorXd::Constant(1, 50 * n01(rng)));
    x.insert(Key::state(4), Eigen::VectorXd::Constant(1, 50 * n01(rng)));
    x.insert(Key::constants(), Eigen::Vector2d(100 + 30 * n01(rng), 1000 + 100 * n01(rng)));
    const std::vector<FactorPtr> factors{
        std::make_shared<MeasurementFactor>(radar, 4, Eigen::VectorXd::Constant(1, 900.0)),
        std::make_shared<ProcessFactor>(radar, 3, Eigen::VectorXd(0), 0.05)};
    for (const auto& f : factors) {
      Eigen::VectorXd r;
      std::vector<Eigen::MatrixXd> J;
      f->linearize(x, r, &J);
      const Eigen::MatrixXd C = internal::residualCurvature(*f, x, r);
      Eigen::MatrixXd Jall(r.size(), C.rows());
      for (std::size_t a = 0, c = 0; a < J.size(); c += static_cast<std::size_t>(J[a].cols()), ++a)
        Jall.middleCols(static_cast<Eigen::Index>(c), J[a].cols()) = J[a];
      const Eigen::MatrixXd H = Jall.transpose() * Jall + C;
      // Numerical Hessian of the factor's cost over its stacked keys.
      std::vector<std::pair<Key, Eigen::Index>> coords;
      for (const auto& k : f->keys())
        for (Eigen::Index i = 0; i < x.at(k).size(); ++i) coords.push_back({k, i});
      Eigen::MatrixXd Hn(C.rows(), C.cols());
      for (std::size_t a = 0; a < coords.size(); ++a)
        for (std::size_t b = 0; b < coords.size(); ++b) {
          const double ha = 1e-3 * std::max(1.0, std::abs(x.at(coords[a].first)[coords[a].second]));
          const double hb = 1e-3 * std::max(1.0, std::abs(x.at(coords[b].first)[coords[b].second]));
          auto at = [&](double sa, double sb) {
            Values y = x;
            y.at(coords[a].first)[coords[a].second] += sa * ha;
            y.at(coords[b].first)[coords[b].second] += sb * hb;
            return f->cost(y);
          };
          Hn(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) =
              (at(1, 1) - at(1, -1) - at(-1, 1) + at(-1, -1)) / (4 * ha * hb);
        }
      EXPECT_LT((H - Hn).norm(), 1e-5 * std::max(1.0, Hn.norm())) << f->describe() << " trial " << trial
                                                                  << "\nH =\n" << H << "\nnumeric =\n" << Hn;
    }
  }
}

namespace {
// Seven steps of the paper scenario from its 143σ-wrong prior: the MAP keeps
// a 50σ range residual, and Levenberg–Marquardt crawls toward it.
Problem radarStartup(const models::Radar2D& radar) { return buildProblem(radar, radarPaperRun(radar, 7, 1).measurements); }
}  // namespace

TEST(NewtonPolish, BatchReachesTheSameRadarStartupMapFromDifferentStarts) {
  // Polished, two different starts end at the same point with a vanishing
  // gradient.
  const models::Radar2D radar;
  Problem p = radarStartup(radar);
  BatchSolverOptions o;
  o.max_iterations = 5000;
  o.newton_polish_steps = 10;
  Values a = p.initial, b = p.initial;
  for (auto& kv : b) kv.second.array() += 5.0;
  BatchSolver sa(o), sb(o);
  const auto ra = sa.solve(p.graph, a), rb = sb.solve(p.graph, b);
  ASSERT_TRUE(ra.converged && rb.converged) << ra.toString() << "\n" << rb.toString();
  EXPECT_GT(ra.newton_steps, 0) << ra.toString();
  EXPECT_LT(ra.gradient_norm, 1e-9) << ra.toString();
  EXPECT_LT(rb.gradient_norm, 1e-9) << rb.toString();
  for (const auto& kv : a) EXPECT_LT(relativeError(kv.second, b.at(kv.first)), 1e-10) << kv.first.toString();
  o.newton_polish_steps = -1;
  EXPECT_THROW(BatchSolver{o}, InvalidArgument);
}

namespace {
// The radar graph of `steps` steps; with `star`, weak links from x_c(0) to
// every x_c(k) as well (a graph that is no chain: its envelope is quadratic,
// so CHOLMOD factors it).
Problem radarGraph(const models::Radar2D& radar, int steps, bool star) {
  Problem p = buildProblem(radar, radarPaperRun(radar, steps, 2).measurements);
  if (star)
    for (int k = 2; k <= steps; ++k) {
      const Key a = Key::state(0), b = Key::state(k);
      Values at;
      at.insert(a, Eigen::VectorXd::Zero(1));
      at.insert(b, Eigen::VectorXd::Zero(1));
      p.graph.add(std::make_shared<LinearGaussianFactor>(
          std::vector<Key>{a, b},
          std::vector<Eigen::MatrixXd>{Eigen::MatrixXd::Constant(1, 1, 0.01), Eigen::MatrixXd::Constant(1, 1, -0.01)},
          Eigen::VectorXd::Zero(1), at));
    }
  return p;
}
}  // namespace

// Both ways of factoring a large information matrix — its envelope (a
// chain), CHOLMOD (anything else) — give the solution where the dense
// gradient vanishes and the covariances of the dense inverse, on and off the
// factor's pattern (a small chain is factored by its envelope too).
TEST(BatchSolver, EveryFactorizationGivesTheDenseSolutionAndInverse) {
  models::Radar2D::Params params;
  params.q = 0.5;  // κ(H) small enough for a tight comparison (see above)
  const models::Radar2D radar(params);
  for (const auto& [steps, star, expected] :
       {std::tuple{25, false, "envelope"}, {150, false, "envelope"}, {150, true, "sparse"}}) {
    SCOPED_TRACE(expected);
    Problem p = radarGraph(radar, steps, star);
    Values x = p.initial;
    BatchSolver solver;
    const BatchSolverSummary sum = solver.solve(p.graph, x);
    ASSERT_TRUE(sum.converged) << sum.toString();
    EXPECT_EQ(sum.linear_solver, expected);
    EXPECT_NE(sum.toString().find(std::string(expected) + " Cholesky"), std::string::npos) << sum.toString();
    Eigen::MatrixXd H;
    Eigen::VectorXd g;
    denseNormalEquations(p.graph, x, H, g);
    EXPECT_LT(g.lpNorm<Eigen::Infinity>(), 1e-5);
    const Eigen::MatrixXd Sigma = H.inverse();
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues();
    const double tol = 100 * 2.2e-16 * ev.maxCoeff() / ev.minCoeff();
    ASSERT_LT(tol, 1e-7);
    const Eigen::Index b0 = steps + 1;  // x_c(0..steps), then x_b
    EXPECT_LT(relativeError(solver.marginalCovariance(Key::constants()), Sigma.block(b0, b0, 2, 2)), tol);
    for (int k : {0, 1, steps / 3, steps}) {
      const Eigen::MatrixXd joint = solver.jointMarginalCovariance({Key::state(k), Key::constants()});
      Eigen::MatrixXd ref(3, 3);
      const std::vector<Eigen::Index> idx{k, b0, b0 + 1};
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) ref(i, j) = Sigma(idx[static_cast<std::size_t>(i)], idx[static_cast<std::size_t>(j)]);
      EXPECT_LT(relativeError(joint, ref), tol) << "x_c(" << k << ")";
    }
    for (auto [a, b] : {std::pair{0, steps}, {3, steps / 2}}) {  // off the pattern (on it for x_c(0) with the star)
      const Eigen::MatrixXd pair = solver.jointMarginalCovariance({Key::state(a), Key::state(b)});
      EXPECT_NEAR(pair(0, 1), Sigma(a, b), tol * std::sqrt(Sigma(a, a) * Sigma(b, b))) << a << ", " << b;
    }
  }
}

// A constant nothing determines is named on every factorization path.
TEST(BatchSolver, SingularSystemNamesTheVariableOnEveryFactorization) {
  const models::LinearModel model = modelBlindToB2();
  for (const auto& [steps, star, expected] : {std::tuple{10, false, "envelope"}, {60, true, "sparse"}}) {
    std::vector<Measurement> ms;
    for (int k = 1; k <= steps; ++k) ms.push_back({0.1 * k, Eigen::VectorXd::Constant(1, 0.3)});
    Problem p = buildProblem(model, ms);
    // The constants' prior replaced by one on b1 alone: b2 enters nothing.
    FactorGraph graph;
    for (const auto& f : p.graph)
      if (!(f->keys().size() == 1 && f->keys()[0] == Key::constants())) graph.add(f);
    Values lin;
    lin.insert(Key::constants(), Eigen::VectorXd::Zero(2));
    graph.add(std::make_shared<LinearGaussianFactor>(
        std::vector<Key>{Key::constants()}, std::vector<Eigen::MatrixXd>{Eigen::RowVector2d(1, 0)},
        Eigen::VectorXd::Zero(1), lin));
    if (star)  // weak links from x_c(0) to every state: no chain
      for (int k = 2; k <= steps; ++k) {
        Values at;
        at.insert(Key::state(0), Eigen::VectorXd::Zero(2));
        at.insert(Key::state(k), Eigen::VectorXd::Zero(2));
        graph.add(std::make_shared<LinearGaussianFactor>(
            std::vector<Key>{Key::state(0), Key::state(k)},
            std::vector<Eigen::MatrixXd>{0.01 * Eigen::Matrix2d::Identity(), -0.01 * Eigen::Matrix2d::Identity()},
            Eigen::VectorXd::Zero(2), at));
      }
    p.graph = graph;
    Values x = p.initial;
    BatchSolverOptions o;
    o.method = BatchSolverOptions::Method::GaussNewton;
    try {
      BatchSolver(o).solve(p.graph, x);
      FAIL() << expected << ": singular system accepted";
    } catch (const NumericalError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("x_b"), std::string::npos) << expected << ": " << msg;
      EXPECT_NE(msg.find("component 1"), std::string::npos) << expected << ": " << msg;
    }
    for (const auto& kv : p.initial) EXPECT_EQ(x.at(kv.first), kv.second) << expected;
  }
}

// A small graph that is no chain (x_c(k) linked to x_c(29 − k)) is factored
// densely: the solution and covariances of the dense inverse; a state no
// factor reaches is named.
TEST(BatchSolver, ASmallGraphThatIsNoChainIsFactoredDensely) {
  auto graphOf = [](bool leave_out_3) {
    FactorGraph g;
    for (int k = 0; k < 30; ++k) {
      if (leave_out_3 && k == 3) continue;
      g.add(std::make_shared<PriorFactor>(
          Key::state(k), Gaussian{Eigen::VectorXd::Constant(1, 0.1 * k), Eigen::MatrixXd::Constant(1, 1, 1.0 + k)}));
    }
    for (int k = 0; k < 15; ++k) {
      if (leave_out_3 && (k == 3 || 29 - k == 3)) continue;
      Values at;
      at.insert(Key::state(k), Eigen::VectorXd::Zero(1));
      at.insert(Key::state(29 - k), Eigen::VectorXd::Zero(1));
      g.add(std::make_shared<LinearGaussianFactor>(
          std::vector<Key>{Key::state(k), Key::state(29 - k)},
          std::vector<Eigen::MatrixXd>{Eigen::MatrixXd::Constant(1, 1, 2.0), Eigen::MatrixXd::Constant(1, 1, -1.0)},
          Eigen::VectorXd::Constant(1, 0.5), at));
    }
    return g;
  };
  Values x;
  for (int k = 0; k < 30; ++k) x.insert(Key::state(k), Eigen::VectorXd::Zero(1));
  const Values start = x;
  const FactorGraph g = graphOf(false);
  BatchSolver solver;
  const BatchSolverSummary sum = solver.solve(g, x);
  ASSERT_TRUE(sum.converged) << sum.toString();
  EXPECT_EQ(sum.linear_solver, "dense");
  Eigen::MatrixXd H;
  Eigen::VectorXd grad;
  denseNormalEquations(g, x, H, grad);
  EXPECT_LT(grad.lpNorm<Eigen::Infinity>(), 1e-9);
  const Eigen::MatrixXd Sigma = H.inverse();
  for (auto [a, b] : {std::pair{0, 29}, {3, 26}, {5, 6}, {10, 10}}) {
    const Eigen::MatrixXd pair = solver.jointMarginalCovariance({Key::state(a), Key::state(b == a ? 29 - a : b)});
    const int c = b == a ? 29 - a : b;
    EXPECT_NEAR(pair(0, 1), Sigma(a, c), 1e-12 * std::sqrt(Sigma(a, a) * Sigma(c, c))) << a << ", " << c;
    EXPECT_NEAR(pair(0, 0), Sigma(a, a), 1e-12 * Sigma(a, a));
  }
  Values y = start;
  try {
    BatchSolver().solve(graphOf(true), y);
    FAIL() << "a state no factor reaches was accepted";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find(Key::state(3).toString()), std::string::npos) << e.what();
  }
}

namespace {
// The radar window of the paper's scheme: priors on x_c(0) and x_b, then
// `steps` steps of factors (process and range), by step.
struct RadarWindow {
  std::vector<FactorPtr> priors;
  std::vector<std::vector<FactorPtr>> steps;  // steps[k − 1]: the step into x_c(k)
  FactorGraph graph(std::size_t from_step = 0, const std::vector<FactorPtr>* other_priors = nullptr) const {
    FactorGraph g;
    for (const auto& f : other_priors ? *other_priors : priors) g.add(f);
    for (std::size_t k = from_step; k < steps.size(); ++k)
      for (const auto& f : steps[k]) g.add(f);
    return g;
  }
};

RadarWindow radarWindow(const Model& radar, const SimulatedRun& run, int steps) {
  RadarWindow w;
  w.priors = priorFactors(radar, radar.priorState(), radar.priorConstants());
  for (int k = 1; k <= steps; ++k)
    w.steps.push_back(stepFactors(radar, k, radar.noise().T, Eigen::VectorXd(0), &run.measurements[k - 1], 1));
  return w;
}
}  // namespace

// The step after dropping x_c(0) with its factors and re-prioritizing
// x_c(1) and x_b (the paper window's re-solve) against the dense
// Gauss–Newton step of the changed graph, linearized afresh at the same
// point; with the last factorization before the last step and at the solution.
TEST(BatchSolver, AStepAfterAChangeEqualsTheDenseStepOfTheChangedGraph) {
  const models::Radar2D radar = radarWithPriorsAtTheTruth();
  const SimulatedRun run = radarPaperRun(radar, 12, 5);
  const RadarWindow w = radarWindow(radar, run, 12);
  for (const bool at_solution : {false, true}) {
    SCOPED_TRACE(at_solution ? "factored at the solution" : "factored before the last step");
    BatchSolverOptions o;
    o.method = BatchSolverOptions::Method::GaussNewton;
    o.relative_cost_tolerance = 1e-9;
    o.relinearize_at_solution = at_solution;
    BatchSolver solver(o);
    Problem p = buildProblem(radar, std::vector<Measurement>(run.measurements.begin(), run.measurements.begin() + 12));
    Values x = p.initial;
    ASSERT_TRUE(solver.solve(w.graph(), x).converged);
    const Values x_f = solver.factoredAt(x);
    // New priors away from the estimate: the step has somewhere to go.
    const Gaussian state{x.at(Key::state(1)) + Eigen::VectorXd::Constant(1, 0.3), Eigen::MatrixXd::Identity(1, 1) * 0.04};
    const Gaussian constants{x.at(Key::constants()) + Eigen::Vector2d(0.5, -2.0), Eigen::Vector2d(0.25, 9.0).asDiagonal()};
    const std::vector<FactorPtr> new_priors = priorFactors(radar, state, constants, 1);
    GraphChange change;
    for (const auto& f : w.priors) change.removed.add(f);
    for (const auto& f : w.steps[0]) change.removed.add(f);
    for (const auto& f : new_priors) change.added.add(f);
    change.dropped = {Key::state(0)};
    const ChangeStep step = solver.stepAfterChange(change, x);

    const FactorGraph changed = w.graph(1, &new_priors);
    Values at = x_f;
    at.erase(Key::state(0));
    Eigen::MatrixXd H;
    Eigen::VectorXd g;
    denseNormalEquations(changed, at, H, g);
    const Eigen::VectorXd delta = -H.ldlt().solve(g);
    ASSERT_EQ(x.size(), at.size());
    Eigen::Index off = 0;
    for (const auto& kv : at) {
      const Eigen::VectorXd expected = kv.second + delta.segment(off, kv.second.size());
      EXPECT_LT((x.at(kv.first) - expected).norm(), 1e-9 * (1 + expected.norm())) << kv.first.toString();
      off += kv.second.size();
    }
    EXPECT_NEAR(step.cost_before, changed.cost(at), 1e-9 * changed.cost(at));
    EXPECT_NEAR(step.predicted_decrease, -0.5 * g.dot(delta), 1e-8 * std::abs(g.dot(delta)));
    EXPECT_EQ(step.rank, 3);  // x_c(1) (x) and x_b (ẋ, h): the columns the change touches
    EXPECT_GT(step.predicted_decrease, 1.0);
    EXPECT_THROW(solver.marginalCovariance(Key::constants()), InvalidArgument) << "the factorization is the old graph's";
  }
}

TEST(BatchSolver, AChangeThatLeavesAVariableUndeterminedIsRefusedAndChangesNothing) {
  const models::Radar2D radar = radarWithPriorsAtTheTruth();
  const SimulatedRun run = radarPaperRun(radar, 6, 2);
  const RadarWindow w = radarWindow(radar, run, 6);
  BatchSolver solver;
  Problem p = buildProblem(radar, std::vector<Measurement>(run.measurements.begin(), run.measurements.begin() + 6));
  Values x = p.initial;
  solver.solve(w.graph(), x);
  const Values before = x;
  const auto unchanged = [&] {
    for (const auto& kv : before) EXPECT_EQ(x.at(kv.first), kv.second) << kv.first.toString();
  };
  GraphChange nothing_fixes_it;  // x_c(0) dropped, none of its factors removed
  nothing_fixes_it.dropped = {Key::state(0)};
  try {
    solver.stepAfterChange(nothing_fixes_it, x);
    ADD_FAILURE() << "expected NumericalError";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("x_c(0)"), std::string::npos) << e.what();
  }
  unchanged();
  GraphChange on_dropped;  // a new factor on the variable that leaves
  on_dropped.dropped = {Key::state(0)};
  for (const auto& f : priorFactors(radar, radar.priorState(), radar.priorConstants(), 0)) on_dropped.added.add(f);
  EXPECT_THROW(solver.stepAfterChange(on_dropped, x), InvalidArgument);
  unchanged();
  GraphChange no_prior;  // the constants' prior and steps 2–6 removed: x_c(2…6) and x_b undetermined
  no_prior.removed.add(w.priors[1]);
  for (std::size_t k = 1; k < w.steps.size(); ++k)
    for (const auto& f : w.steps[k]) no_prior.removed.add(f);
  EXPECT_THROW(solver.stepAfterChange(no_prior, x), NumericalError);
  unchanged();
  BatchSolver fresh;
  EXPECT_THROW(fresh.stepAfterChange(GraphChange{}, x), InvalidArgument) << "no factorization yet";
}

// A chain of states tied together 10⁶ times more tightly than the data see
// them, each seen with a constant whose coefficient varies by 5 %: the
// constant's variance is what little of the data the chain's common motion
// leaves, and JᵀJ, squaring J's condition number, loses its digits. With
// covariance_by_qr the batch's covariances (the constant's, a state's and
// their cross term) equal a dense Householder QR of J, R⁻¹R⁻ᵀ; the normal
// equations' do not, which is why the option exists.
TEST(BatchSolver, CovariancesByQrKeepWhatTheNormalEquationsLose) {
  const int steps = 400;
  FactorGraph graph;
  Values x;
  std::mt19937 rng(17);
  std::normal_distribution<double> noise;
  const Key b = Key::constants();
  for (int k = 0; k <= steps; ++k) {
    x.insert(Key::state(k), Eigen::VectorXd::Zero(1));
    if (k > 0)
      graph.add(std::make_shared<ScalarFactor>(std::vector<Key>{Key::state(k - 1), Key::state(k)},
                                               Eigen::Vector2d(-1e6, 1e6), noise(rng)));
    graph.add(std::make_shared<ScalarFactor>(std::vector<Key>{Key::state(k), b},
                                             Eigen::Vector2d(1.0, 1.0 + 0.05 * std::sin(0.3 * k)), noise(rng)));
  }
  x.insert(b, Eigen::VectorXd::Zero(1));
  graph.add(std::make_shared<ScalarFactor>(std::vector<Key>{b}, Eigen::VectorXd::Constant(1, 1e-3), 0.0));
  Eigen::MatrixXd J;
  Eigen::VectorXd r;
  denseJacobian(graph, x, J, r);  // linear: the same at any x
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(J);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(J.cols()).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd Rinv = R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(J.cols(), J.cols()));
  const Eigen::MatrixXd reference = Rinv * Rinv.transpose();  // states 0 … steps, then b
  const Eigen::Index ib = steps + 1, ik = steps / 2;
  double worst_normal = 0;
  for (bool by_qr : {false, true}) {
    BatchSolverOptions options;
    options.covariance_by_qr = by_qr;
    BatchSolver solver(options);
    Values v = x;
    ASSERT_TRUE(solver.solve(graph, v).converged);
    const Eigen::MatrixXd P = solver.jointMarginalCovariance({Key::state(ik), b});
    const double errors[] = {std::abs(P(1, 1) / reference(ib, ib) - 1), std::abs(P(0, 0) / reference(ik, ik) - 1),
                             std::abs(P(0, 1) / reference(ik, ib) - 1)};
    const double worst = *std::max_element(std::begin(errors), std::end(errors));
    std::cout << (by_qr ? "QR" : "normal equations") << ": worst relative error " << worst << "\n";
    if (by_qr) {
      EXPECT_LT(worst, 1e-8) << "b " << P(1, 1) << " vs " << reference(ib, ib);
    } else {
      worst_normal = worst;
    }
  }
  EXPECT_GT(worst_normal, 1e-5) << "the normal equations lost nothing here: the test shows no difference";
}

// Anderson mixing of a linear iteration x ← x + f(x), f(x) = −M(x − x*), is
// GMRES on M (Walker & Ni 2011, Theorem 2.2): with a memory of at least the
// dimension it lands on x* within dimension + 1 mixed steps, where the plain
// iteration keeps (1 − 0.05)ᵏ of the error along M's slowest direction.
TEST(AndersonMixing, OnALinearIterationItIsExactInDimensionPlusOneSteps) {
  const Eigen::Vector3d x_star(1.0, -2.0, 0.5);
  Eigen::Matrix3d Q = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  const Eigen::Matrix3d M = Q * Eigen::Vector3d(0.05, 0.5, 0.9).asDiagonal() * Q.transpose();
  const Eigen::VectorXd w = Eigen::Vector3d(1.0, 4.0, 0.25);  // any positive metric
  for (int memory : {0, 3}) {
    internal::AndersonMixing mixing(memory);
    Eigen::VectorXd x = Eigen::Vector3d::Zero(), step;
    for (int k = 0; k < 5; ++k) {
      const Eigen::VectorXd f = -M * (x - x_star);
      mixing.mix(f, w, step);
      x += step;
      mixing.accepted(step);
    }
    if (memory == 0) EXPECT_GT((x - x_star).norm(), 0.1) << "the plain iteration after 5 steps";
    else EXPECT_LT((x - x_star).norm(), 1e-10) << x.transpose();
  }
}

// After reset() the next step is f itself (no difference spans a break in
// the sequence), and without a kept step no difference is formed.
TEST(AndersonMixing, AResetOrAStepNotKeptLeavesTheNextStepUnmixed) {
  internal::AndersonMixing mixing(2);
  const Eigen::VectorXd w = Eigen::VectorXd::Ones(2), f1 = Eigen::Vector2d(1.0, 0.5), f2 = Eigen::Vector2d(0.4, 0.1);
  Eigen::VectorXd step;
  EXPECT_FALSE(mixing.mix(f1, w, step));
  EXPECT_EQ(step, f1);
  EXPECT_FALSE(mixing.mix(f2, w, step)) << "f1's step was never kept";
  mixing.accepted(step);
  EXPECT_TRUE(mixing.mix(f1, w, step));
  EXPECT_NE(step, f1);
  mixing.reset();
  EXPECT_FALSE(mixing.mix(f2, w, step));
  EXPECT_EQ(step, f2);
}

// The paper's radar start-up (seven steps from its 143σ-wrong prior): the
// residuals stay large at the MAP and Levenberg–Marquardt crawls (some 350
// iterations). Anderson-mixed, it reaches the MAP that Newton's method
// (the Hessian with its second-order terms: an independent route) polishes
// to a vanishing gradient, in a few dozen iterations at most.
TEST(BatchSolver, AndersonMixedStepsReachTheNewtonPolishedMapFasterWhereGaussNewtonCrawls) {
  const models::Radar2D radar;
  Problem p = radarStartup(radar);
  BatchSolverOptions plain;
  plain.max_iterations = 5000;
  BatchSolverOptions polished = plain, mixed = plain;
  polished.newton_polish_steps = 10;
  mixed.anderson_memory = 2;
  Values reference = p.initial, x_plain = p.initial, x = p.initial;
  const auto rn = BatchSolver(polished).solve(p.graph, reference);
  const auto rp = BatchSolver(plain).solve(p.graph, x_plain);
  const auto rm = BatchSolver(mixed).solve(p.graph, x);
  ASSERT_TRUE(rn.converged && rp.converged && rm.converged) << rn.toString() << "\n" << rp.toString() << "\n" << rm.toString();
  ASSERT_LT(rn.gradient_norm, 1e-9) << rn.toString();
  EXPECT_GT(rp.iterations, 100) << rp.toString();
  EXPECT_LT(rm.iterations, 30) << rm.toString();
  EXPECT_GT(rm.anderson_steps, 0) << rm.toString();
  EXPECT_NE(rm.toString().find("Anderson-mixed"), std::string::npos) << rm.toString();
  for (const auto& kv : reference)
    EXPECT_LT(relativeError(x.at(kv.first), kv.second), 1e-8) << kv.first.toString() << ": " << rm.toString();
  mixed.anderson_memory = -1;
  EXPECT_THROW(BatchSolver{mixed}, InvalidArgument);
  mixed.anderson_memory = 17;
  EXPECT_THROW(BatchSolver{mixed}, InvalidArgument);
}


namespace {
// r(x) on one scalar variable, from two functions (its value and slope).
class ScalarFunctionFactor final : public Factor {
 public:
  ScalarFunctionFactor(std::function<double(double)> r, std::function<double(double)> slope)
      : Factor({Key::state(0)}, 1), r_(std::move(r)), slope_(std::move(slope)) {}
  void linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                   std::vector<Eigen::MatrixXd>* J) const override {
    const double v = (*x[0])[0];
    r = Eigen::VectorXd::Constant(1, r_(v));
    if (J) {
      J->resize(1);
      (*J)[0] = Eigen::MatrixXd::Constant(1, 1, slope_(v));
    }
  }
  std::string describe() const override { return "r(x)"; }

 private:
  std::function<double(double)> r_, slope_;
};
}  // namespace

// r = (x − 1, x²/4 − 1) from x = 3: Gauss–Newton approaches the minimum
// 1.3646556 from above, each step ~0.18 of the last; the first mix lands on
// it. A cliff (r = 10 below 1.36466, no slope: unseen by the linearization)
// turns that mix into a rise of the cost: refused, the solve goes back and
// follows plain Levenberg–Marquardt's path to the very same end.
TEST(BatchSolver, AnAndersonMixThatRaisesTheCostIsRefusedAndThePlainPathFollows) {
  FactorGraph graph;
  graph.add(std::make_shared<ScalarFunctionFactor>([](double x) { return x - 1; }, [](double) { return 1.0; }));
  graph.add(std::make_shared<ScalarFunctionFactor>([](double x) { return x * x / 4 - 1; }, [](double x) { return x / 2; }));
  Values smooth_plain, smooth_mixed;
  smooth_plain.insert(Key::state(0), Eigen::VectorXd::Constant(1, 3.0));
  smooth_mixed = smooth_plain;
  BatchSolverOptions plain, mixed;
  mixed.anderson_memory = 2;
  const auto sp = BatchSolver(plain).solve(graph, smooth_plain);
  const auto sm = BatchSolver(mixed).solve(graph, smooth_mixed);
  ASSERT_TRUE(sp.converged && sm.converged) << sp.toString() << "\n" << sm.toString();
  EXPECT_NEAR(smooth_mixed.at(Key::state(0))[0], smooth_plain.at(Key::state(0))[0], 1e-8) << sm.toString();
  EXPECT_GT(sm.anderson_steps, 0) << sm.toString();
  EXPECT_LT(sm.iterations, sp.iterations) << sm.toString() << "\n" << sp.toString();

  graph.add(std::make_shared<ScalarFunctionFactor>([](double x) { return x < 1.36466 ? 10.0 : 0.0; },
                                                   [](double) { return 0.0; }));
  Values cliff_plain, cliff_mixed;
  cliff_plain.insert(Key::state(0), Eigen::VectorXd::Constant(1, 3.0));
  cliff_mixed = cliff_plain;
  const auto cp = BatchSolver(plain).solve(graph, cliff_plain);
  const auto cm = BatchSolver(mixed).solve(graph, cliff_mixed);
  ASSERT_TRUE(cp.converged && cm.converged) << cp.toString() << "\n" << cm.toString();
  EXPECT_GT(cm.anderson_rejected, 0) << cm.toString();
  EXPECT_EQ(cm.anderson_steps, 0) << cm.toString();
  EXPECT_EQ(cliff_mixed.at(Key::state(0))[0], cliff_plain.at(Key::state(0))[0]) << cm.toString() << "\n" << cp.toString();
  EXPECT_GE(cliff_mixed.at(Key::state(0))[0], 1.36466);
  EXPECT_EQ(cm.final_cost, cp.final_cost);
}
