#include <set>
#include <gtest/gtest.h>

#include <random>

#include "gssm/solvers/batch_solver.h"
#include "gssm/checkpoint/checkpoint.h"
#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/io/dataset.h"
#include "gssm/factors/problem.h"
#include "gssm/estimator/estimator.h"
#include "gssm/models/linear.h"
#include "gssm/models/radar2d.h"
#include "gssm/model/simulation.h"
#include "expect_error.h"
#include "reference_kalman.h"

using namespace gssm;
using gssm::testing::expectThrowsNaming;
using gssm::testing::relativeError;

namespace {
using gssm::testing::normalSampler;

// Everything observable about an estimator, to compare before/after a throw.
struct Snapshot {
  double t;
  std::int64_t step;
  Eigen::VectorXd mean;
  Eigen::MatrixXd cov;
  EstimatorReport report;
  explicit Snapshot(Estimator& e)
      : t(e.time()), step(e.step()), mean(e.current().mean), cov(e.current().covariance), report(e.report()) {}
  void expectSame(Estimator& e, const std::string& what) const {
    EXPECT_EQ(e.time(), t) << what;
    EXPECT_EQ(e.step(), step) << what;
    EXPECT_EQ(e.current().mean, mean) << what;
    EXPECT_EQ(e.current().covariance, cov) << what;
    EXPECT_EQ(e.report().measurements, report.measurements) << what;
    EXPECT_EQ(e.report().smoother.num_variables, report.smoother.num_variables) << what;
    EXPECT_EQ(e.report().smoother.num_factors, report.smoother.num_factors) << what;
    EXPECT_EQ(e.report().detail, report.detail) << what;
  }
};

}  // namespace

TEST(Estimator, EveryThrowingPathLeavesTheEstimatorUnchanged) {
  const models::Radar2D radar;
  SimulationSpec spec;
  spec.steps = 20;
  const SimulatedRun run = simulate(radar, spec, normalSampler(2));
  for (const auto& method : streamingMethods()) {
    EstimatorOptions o;
    o.method = method;
    o.fixed_lag.window = o.paper_window.window = 5;
    auto est = makeEstimator(radar, o);
    for (int k = 0; k < 12; ++k) est->addMeasurement(run.measurements[k].t, run.measurements[k].y);
    const Snapshot before(*est);
    const double t = run.measurements[12].t;
    // Late, between two states: no state to join for the EKF and the paper
    // window (the smoothers insert one: LateMeasurements.*; a bad value
    // there is refused too).
    const double between = 0.5 * (run.measurements[9].t + run.measurements[10].t);
    if (method == Method::Ekf || method == Method::PaperWindow)  // the smoothers insert a state there
      expectThrowsNaming([&] { est->addMeasurement(between, run.measurements[12].y); }, "is before the newest state");
    expectThrowsNaming([&] { est->addMeasurement(between, Eigen::VectorXd::Constant(1, NAN)); }, "measurement");
    expectThrowsNaming([&] { est->addMeasurement(t, Eigen::VectorXd::Constant(1, NAN)); }, "measurement y");
    expectThrowsNaming([&] { est->addMeasurement(t, Eigen::VectorXd::Constant(2, 1.0)); }, "expected 1 entries");
    expectThrowsNaming([&] { est->addMeasurement(NAN, run.measurements[12].y); }, "measurement time");
    expectThrowsNaming([&] { est->addInput(t, Eigen::VectorXd::Constant(1, 1.0)); }, "input u");
    expectThrowsNaming([&] { est->addInput(0.0, Eigen::VectorXd(0)); }, "newest state");
    before.expectSame(*est, methodName(method));
    // and it carries on normally afterwards
    est->addMeasurement(t, run.measurements[12].y);
    EXPECT_EQ(est->step(), 13) << method;
  }
}

namespace {
// Failure injection: f goes non-finite for a step longer than 1 s, so the
// failure happens inside the update (linearization / prediction / solve),
// after validation has passed.
class FailsOnLongSteps final : public Model {
 public:
  FailsOnLongSteps() : Model({1, 1, 0, 1}, {{"x"}, {"b"}, {}, {"y"}}, noise()) {}
  std::string name() const override { return "fails-on-long-steps"; }
  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd&,
                    double dt, Eigen::MatrixXd* J_f_xc = nullptr, Eigen::MatrixXd* J_f_xb = nullptr) const override {
    const double bad = dt > 1.0 ? NAN : 0.0;
    if (J_f_xc) *J_f_xc = Eigen::MatrixXd::Constant(1, 1, 1.0 + bad);
    if (J_f_xb) *J_f_xb = Eigen::MatrixXd::Constant(1, 1, dt);
    return Eigen::VectorXd::Constant(1, xc[0] + xb[0] * dt + bad);
  }
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc = nullptr,
                    Eigen::MatrixXd* J_h_xb = nullptr) const override {
    if (J_h_xc) *J_h_xc = Eigen::MatrixXd::Ones(1, 1);
    if (J_h_xb) *J_h_xb = Eigen::MatrixXd::Ones(1, 1);
    return xc + xb;
  }

 private:
  static ModelNoise noise() {
    ModelNoise n;
    n.T = 0.1;
    n.Q = Eigen::MatrixXd::Constant(1, 1, 0.01);
    n.R = Eigen::MatrixXd::Constant(1, 1, 0.1);
    n.prior_state = {Eigen::VectorXd::Zero(1), Eigen::MatrixXd::Identity(1, 1)};
    n.prior_constants = {Eigen::VectorXd::Zero(1), Eigen::MatrixXd::Identity(1, 1)};
    return n;
  }
};
}  // namespace

TEST(Estimator, NumericalFailureInsideAnUpdateLeavesTheEstimatorUnchanged) {
  const FailsOnLongSteps model;
  for (const auto& method : streamingMethods()) {
    EstimatorOptions o;
    o.method = method;
    o.fixed_lag.window = o.paper_window.window = 3;
    auto est = makeEstimator(model, o);
    for (int k = 1; k <= 6; ++k) est->addMeasurement(0.1 * k, Eigen::VectorXd::Constant(1, 0.5));
    const Snapshot before(*est);
    try {
      est->addMeasurement(5.0, Eigen::VectorXd::Constant(1, 0.5));  // a 4.4 s gap: f is NaN
      ADD_FAILURE() << method << ": no exception from a non-finite prediction";
    } catch (const NumericalError& e) {
      EXPECT_FALSE(std::string(e.what()).empty());
    }
    before.expectSame(*est, std::string(methodName(method)) + " after a failed update");
    est->addMeasurement(0.8, Eigen::VectorXd::Constant(1, 0.5));  // and it goes on
    EXPECT_EQ(est->step(), 7) << method;
  }
}

TEST(Estimator, FixedLagNewestStateEqualsKalmanFilterThroughTheStreamingApi) {
  std::mt19937 rng(77);
  const models::LinearModel model(gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1));
  SimulationSpec spec;
  spec.steps = 25;
  const SimulatedRun run = simulate(model, spec, normalSampler(8));
  const auto ref = gssm::testing::kalmanAndRts(gssm::testing::stack(model, 0.1), run.measurements);
  for (const Method method : {Method::Ekf, Method::FixedLag, Method::Incremental}) {
    EstimatorOptions o;
    o.method = method;
    o.fixed_lag.window = o.paper_window.window = 4;
    auto est = makeEstimator(model, o);
    for (int k = 1; k <= spec.steps; ++k) {
      est->addMeasurement(run.measurements[k - 1].t, run.measurements[k - 1].y);
      // times are k*T exactly as the reference; the KF uses T throughout
      const StateEstimate e = est->current();
      EXPECT_LT(relativeError(e.mean, ref.zf[k]), 1e-8) << method << " step " << k;
      EXPECT_LT(relativeError(e.covariance, ref.Pf[k]), 1e-8) << method << " step " << k;
      EXPECT_EQ(e.step, k);
    }
    if (method == Method::Incremental) {
      const auto s = est->smoothed(3);
      ASSERT_TRUE(s.has_value());
      EXPECT_LT(relativeError(s->mean, ref.zs[3]), 1e-8);
      // any pair of variables: compare with the batch solution of the same data
      Problem p = buildProblem(model, run.measurements);
      Values x = p.initial;
      BatchSolver batch;
      ASSERT_TRUE(batch.solve(p.graph, x).converged);
      const std::vector<Key> pair{Key::state(2), Key::state(20)};
      const auto cov = est->marginalCovariance(pair);
      ASSERT_TRUE(cov.has_value());
      EXPECT_LT(relativeError(*cov, batch.jointMarginalCovariance(pair)), 1e-8);
    }
    if (method == Method::Ekf) {
      EXPECT_FALSE(est->marginalCovariance({Key::state(3)}).has_value());
      EXPECT_LT(relativeError(*est->marginalCovariance({Key::constants()}), ref.Pf.back().bottomRightCorner(2, 2)), 1e-8);
    }
    if (method == Method::FixedLag) {
      EXPECT_FALSE(est->smoothed(3).has_value());  // left the window
    }
  }
}

TEST(Estimator, OptionsValidateNamesTheField) {
  const models::Radar2D radar;
  EstimatorOptions o;
  o.method = Method::Batch;  // in the method table, but not streaming
  expectThrowsNaming([&] { makeEstimator(radar, o); }, "'batch' needs the whole run");
  o.method = Method::FixedLag;
  o.fixed_lag.window = 0;
  expectThrowsNaming([&] { makeEstimator(radar, o); }, "fixed_lag.window must be >= 1");
  o.method = Method::PaperWindow;  // reads only its own window
  EXPECT_NO_THROW(makeEstimator(radar, o));
  o.paper_window.window = 0;
  expectThrowsNaming([&] { makeEstimator(radar, o); }, "paper_window.window must be >= 1, got 0");
}

TEST(Method, OneTableNamesEveryMethodOnce) {
  std::set<std::string> names;
  for (const auto& info : methods()) {
    EXPECT_TRUE(names.insert(info.name).second) << info.name;
    EXPECT_EQ(methodNamed(info.name), info.method);
    EXPECT_EQ(&methodInfo(info.method), &info);
    EXPECT_EQ(info.streaming, info.method != Method::Batch);
  }
  EXPECT_EQ(names.size(), 5u);
  EXPECT_FALSE(methodNamed("kalman").has_value());
  EXPECT_EQ(streamingMethods().size(), 4u);
}

TEST(Estimator, ReportSaysWhatWasUsed) {
  const models::Radar2D radar;
  EstimatorOptions o(Method::FixedLag);
  o.fixed_lag.window = 7;
  o.incremental.ordering = EliminationOrdering::ConstrainedColamd;  // not read by the fixed lag
  auto fl = makeEstimator(radar, o);
  EXPECT_EQ(fl->report().method, Method::FixedLag);
  EXPECT_EQ(fl->report().window, 7);
  EXPECT_EQ(fl->report().ordering, EliminationOrdering::TimeOrdered);
  o.method = Method::Incremental;
  auto inc = makeEstimator(radar, o);
  EXPECT_EQ(inc->report().window, 0);
  EXPECT_EQ(inc->report().ordering, EliminationOrdering::ConstrainedColamd);
  o.method = Method::Ekf;
  EXPECT_FALSE(makeEstimator(radar, o)->report().ordering.has_value());
}

// [fixed_lag] constants_check_sigmas: the fixed lag's own relinearization
// policy, in place of [smoother]'s, for it alone; a checkpoint carries it.
TEST(Estimator, TheFixedLagsOwnConstantsCheckIsItsAloneAndCheckpointed) {
  // The paper's radar run (its prior far from the truth: the constants move).
  const std::string dir = GSSM_SOURCE_DIR "/datasets/radar-paper";
  const io::IniDocument ini = io::readScenario(dir);
  const auto model = io::makeModel(ini, dir);
  const Model& radar = *model;
  io::Dataset run;
  io::readDatasetData(dir, radar, run, io::BadRows::Throw, &ini);
  auto means = [&](EstimatorOptions o, std::size_t resume_at = 0) {
    std::vector<Eigen::VectorXd> out;
    o.t0 = run.t0;
    auto est = makeEstimator(radar, o);
    for (std::size_t k = 0; k < run.measurements.size(); ++k) {
      if (k == resume_at && k > 0) est = restoreCheckpointBytes(radar, checkpointBytes(*est));
      est->addMeasurement(run.measurements[k].t, run.measurements[k].y);
      out.push_back(est->current().mean);
    }
    return out;
  };
  EstimatorOptions shared(Method::FixedLag), own(Method::FixedLag), plain(Method::FixedLag);
  shared.smoother.constants_check_sigmas = 1e9;
  own.fixed_lag.constants_check_sigmas = 1e9;
  const auto a = means(shared), b = means(own), c = means(plain), d = means(own, 200);
  ASSERT_EQ(a.size(), b.size());
  double moved = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k], b[k]) << "step " << k;
    EXPECT_EQ(b[k], d[k]) << "step " << k << " (resumed at 200)";
    moved = std::max(moved, (c[k] - b[k]).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(moved, 1e-3) << "the radar's fixed lag relinearizes when its constants move: the option must show";
  own.method = plain.method = Method::Incremental;  // not the incremental smoother's
  EXPECT_EQ(means(own).back(), means(plain).back());
  own.method = Method::FixedLag;
  own.fixed_lag.constants_check_sigmas = 0;
  expectThrowsNaming([&] { makeEstimator(radar, own); }, "fixed_lag.constants_check_sigmas must be > 0");
}
