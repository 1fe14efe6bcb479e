#include <gtest/gtest.h>

#include <random>

#include "gssm/core/error.h"
#include "gssm/estimator/estimator.h"
#include "gssm/io/config.h"
#include "gssm/models/function_model.h"
#include "gssm/models/linear.h"
#include "gssm/models/radar2d.h"
#include "gssm/model/simulation.h"
#include "jacobian_check.h"
#include "reference_kalman.h"

using namespace gssm;
using gssm::testing::relativeError;

namespace {
using gssm::testing::normalSampler;

// The radar written by a user as callables, with or without Jacobians.
models::FunctionModel userRadar(bool analytic, bool wrong_jacobian = false) {
  const models::Radar2D ref;
  models::ModelFunctions fns;
  fns.name = analytic ? "radar-analytic" : "radar-numeric";
  fns.f = [](const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd&, double dt) {
    return Eigen::VectorXd::Constant(1, xc[0] + xb[0] * dt);
  };
  fns.h = [](const Eigen::VectorXd& xc, const Eigen::VectorXd& xb) {
    return Eigen::VectorXd::Constant(1, std::hypot(xc[0], xb[1]));
  };
  if (analytic) {
    fns.jacobians_f = [](const Eigen::VectorXd&, const Eigen::VectorXd&, const Eigen::VectorXd&, double dt,
                         Eigen::MatrixXd& a, Eigen::MatrixXd& b) {
      a = Eigen::MatrixXd::Ones(1, 1);
      b = Eigen::RowVector2d(dt, 0);
    };
    fns.jacobians_h = [wrong_jacobian](const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd& a,
                                       Eigen::MatrixXd& b) {
      const double rho = std::hypot(xc[0], xb[1]);
      a = Eigen::MatrixXd::Constant(1, 1, (wrong_jacobian ? 2 : 1) * xc[0] / rho);
      b = Eigen::RowVector2d(0, xb[1] / rho);
    };
    fns.verify_jacobians = true;
  }
  return models::FunctionModel(ref.dims(), ref.names(), ref.noise(), fns);
}
}  // namespace

TEST(FunctionModel, NumericJacobianPathGivesTheSameEstimatesAsTheAnalyticPath) {
  const models::Radar2D analytic;
  const auto numeric = userRadar(false);
  EXPECT_EQ(numeric.jacobianSource(), "central differences");
  SimulationSpec spec;
  spec.steps = 300;
  const SimulatedRun run = simulate(analytic, spec, normalSampler(5));
  for (const auto& method : streamingMethods()) {
    EstimatorOptions o;
    o.method = method;
    auto a = makeEstimator(analytic, o), n = makeEstimator(numeric, o);
    for (const auto& m : run.measurements) {
      a->addMeasurement(m.t, m.y);
      n->addMeasurement(m.t, m.y);
    }
    EXPECT_LT(relativeError(n->current().mean, a->current().mean), 1e-6) << method;
    EXPECT_LT(relativeError(n->current().covariance, a->current().covariance), 1e-6) << method;
  }
}

TEST(FunctionModel, VerifiedAnalyticJacobiansPassAndAWrongOneIsCaught) {
  const auto good = userRadar(true);
  gssm::testing::expectJacobiansMatchDifferences(good, [](std::mt19937& rng) {
    gssm::testing::JacobianPoint p{gssm::testing::uniformVector(rng, 1, -500, 500),
                                   gssm::testing::uniformVector(rng, 2, 500, 3000), Eigen::VectorXd(0), 0.05};
    return p;
  });
  auto est = makeEstimator(good);
  est->addMeasurement(0.05, Eigen::VectorXd::Constant(1, 2000));  // verified: no throw
  const auto bad = userRadar(true, true);
  auto est_bad = makeEstimator(bad);
  try {
    est_bad->addMeasurement(0.05, Eigen::VectorXd::Constant(1, 2000));
    FAIL() << "a wrong J_h_xc was not caught";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("J_h_xc"), std::string::npos) << e.what();
  }
  EXPECT_EQ(est_bad->step(), 0);  // and the estimator is unchanged
}

TEST(LinearModel, ReadFromIniGivesTheSameEstimatesAsBuiltInCpp) {
  std::mt19937 rng(3);
  models::LinearSystem sys = gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1);
  sys.B = Eigen::MatrixXd::Random(3, 1);
  const models::LinearModel cpp(sys, models::Discretization::Exact);
  io::IniDocument ini;
  io::writeModel(cpp, ini);
  const auto from_ini = io::makeModel(io::IniDocument::parse(ini.toString(), "linear.ini"));
  EXPECT_EQ(from_ini->name(), "linear");
  SimulationSpec spec;
  spec.steps = 50;
  const SimulatedRun run = simulate(cpp, spec, normalSampler(4));
  for (const Method method : {Method::Ekf, Method::FixedLag, Method::Incremental}) {
    EstimatorOptions o;
    o.method = method;
    auto a = makeEstimator(cpp, o), b = makeEstimator(*from_ini, o);
    for (std::size_t k = 0; k < run.measurements.size(); ++k) {
      const double t = run.measurements[k].t;
      a->addInput(a->time(), Eigen::VectorXd::Constant(1, std::sin(t)));
      b->addInput(b->time(), Eigen::VectorXd::Constant(1, std::sin(t)));
      a->addMeasurement(t, run.measurements[k].y);
      b->addMeasurement(t, run.measurements[k].y);
    }
    EXPECT_EQ(a->current().mean, b->current().mean) << method;  // same bits: round-trip formatting
    EXPECT_EQ(a->current().covariance, b->current().covariance) << method;
  }
}

#include "gssm/models/nav2d.h"

TEST(FunctionModel, NumericJacobiansOnNav2DGiveTheSameEstimates) {
  const models::Nav2D nav;
  models::ModelFunctions fns;
  fns.name = "nav2d-numeric";
  fns.f = [&nav](const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt) {
    return nav.f(xc, xb, u, dt);
  };
  fns.h = [&nav](const Eigen::VectorXd& xc, const Eigen::VectorXd& xb) { return nav.h(xc, xb); };
  const models::FunctionModel numeric(nav.dims(), nav.names(), nav.noise(), fns);
  SimulationSpec spec;
  spec.steps = 200;
  spec.measure_every = 2;
  spec.input = [](double t, const Eigen::VectorXd&) { return Eigen::VectorXd(Eigen::Vector2d(0.3 * std::cos(t), 0.2)); };
  const SimulatedRun run = simulate(nav, spec, normalSampler(17));
  for (const auto& method : streamingMethods()) {
    EstimatorOptions o;
    o.method = method;
    auto a = makeEstimator(nav, o), n = makeEstimator(numeric, o);
    std::size_t m = 0;
    for (std::size_t k = 0; k < run.inputs.size(); ++k) {
      for (auto* e : {a.get(), n.get()}) e->addInput(run.inputs[k].t, run.inputs[k].u);
      for (; m < run.measurements.size() && run.measurements[m].t <= run.times[k + 1] + 1e-12; ++m)
        for (auto* e : {a.get(), n.get()}) e->addMeasurement(run.measurements[m].t, run.measurements[m].y);
    }
    EXPECT_LT(relativeError(n->current().mean, a->current().mean), 1e-6) << method;
    EXPECT_LT(relativeError(n->current().covariance, a->current().covariance), 1e-6) << method;
  }
}
