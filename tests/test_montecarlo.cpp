#include <gtest/gtest.h>

#include <random>

#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/analysis/montecarlo.h"

using namespace gssm;

TEST(ChiSquare, QuantilesMatchTables) {
  // Reference values from standard χ² tables.
  EXPECT_NEAR(chiSquareQuantile(0.025, 10), 3.247, 0.03);
  EXPECT_NEAR(chiSquareQuantile(0.975, 10), 20.483, 0.05);
  EXPECT_NEAR(chiSquareQuantile(0.025, 100), 74.222, 0.05);
  EXPECT_NEAR(chiSquareQuantile(0.975, 100), 129.561, 0.05);
  EXPECT_NEAR(chiSquareQuantile(0.5, 300), 299.334, 0.05);
}

TEST(MonteCarlo, SmallRunIsConsistentWithItsOwnDefinitions) {
  io::LoadedScenario loaded = io::loadScenario(io::builtinScenario("consistent", 1, 60));
  loaded.scenario.options.fixed_lag.window = loaded.scenario.options.paper_window.window = 5;
  const MonteCarloScenario& scenario = loaded.scenario;
  MonteCarloOptions o;
  o.seeds = 6;
  o.threads = 2;
  auto sampler = [](unsigned seed) {
    auto rng = std::make_shared<std::mt19937>(seed);
    auto d = std::make_shared<std::normal_distribution<double>>(0.0, 1.0);
    return NormalSampler([rng, d] { return (*d)(*rng); });
  };
  const MonteCarloResult a = runMonteCarlo(scenario, o, sampler);
  o.threads = 1;
  const MonteCarloResult b = runMonteCarlo(scenario, o, sampler);
  ASSERT_EQ(a.methods.size(), 5u);
  for (std::size_t m = 0; m < a.methods.size(); ++m) {
    const auto& ma = a.methods[m];
    EXPECT_EQ(ma.failures, 0) << ma.method << ": " << ma.first_failure;
    // parallel and serial runs give identical numbers (seeds are independent)
    EXPECT_EQ(ma.mean_rmse, b.methods[m].mean_rmse) << ma.method;
    EXPECT_EQ(ma.rmse_over_time.size(), 60u);
    // the RMS over time of the last step is the RMS final error
    EXPECT_LT((ma.rmse_over_time.back() - ma.rms_final_error).norm(), 1e-9 * (1 + ma.rms_final_error.norm()));
    for (Eigen::Index i = 0; i < 3; ++i) {
      EXPECT_GE(ma.beats_ekf[i], 0.0);
      EXPECT_LE(ma.beats_ekf[i], 1.0);
    }
  }
  // Seeds computed one by one, in any order, and summarized in seed order
  // give the same table bit for bit (what a distributed campaign relies on).
  std::vector<MonteCarloSeedResult> seeds(static_cast<std::size_t>(o.seeds));
  for (int s = o.seeds - 1; s >= 0; --s) {
    const unsigned seed = o.first_seed + static_cast<unsigned>(s);
    seeds[static_cast<std::size_t>(s)] = runMonteCarloSeed(scenario, o, seed, sampler(seed));
  }
  const MonteCarloResult c = summarizeMonteCarlo(scenario, o, seeds);
  for (std::size_t m = 0; m < a.methods.size(); ++m) {
    EXPECT_EQ(c.methods[m].mean_rmse, a.methods[m].mean_rmse);
    EXPECT_EQ(c.methods[m].mean_nees, a.methods[m].mean_nees);
    EXPECT_EQ(c.methods[m].rmse_over_time, a.methods[m].rmse_over_time);
  }
  EXPECT_EQ(c.markdown(), a.markdown());
  std::swap(seeds[0], seeds[1]);  // out of seed order: refused, naming the position
  EXPECT_THROW(summarizeMonteCarlo(scenario, o, seeds), InvalidArgument);
  EXPECT_EQ(a.methods[0].method, Method::Ekf);
  EXPECT_NE(a.markdown().find("| fixed-lag |"), std::string::npos);
  MonteCarloOptions bad;
  bad.methods = {Method::FixedLag};
  EXPECT_THROW(runMonteCarlo(scenario, bad, sampler), InvalidArgument);
}

// The Monte Carlo reads every estimator section of its scenario, as
// gssm-process does (it once ignored [smoother] and [fixed_lag]).
TEST(MonteCarlo, ScenarioCarriesEveryEstimatorSection) {
  io::IniDocument ini = io::builtinScenario("paper", 1, 20);
  ini.set("fixed_lag", "window", "3");
  ini.set("smoother", "relinearize_threshold", "0.25");
  const io::LoadedScenario loaded = io::loadScenario(io::IniDocument::parse(ini.toString(), "s.ini"));
  EXPECT_EQ(loaded.scenario.options.fixed_lag.window, 3);
  EXPECT_EQ(loaded.scenario.options.smoother.relinearize_threshold, 0.25);
  EXPECT_EQ(loaded.scenario.options.ekf.constant_process_noise[0], 0.005 * 0.005);
  EXPECT_EQ(loaded.scenario.truth, loaded.truth.get());
  EXPECT_EQ(loaded.scenario.estimator, nullptr);
}

#include "gssm/models/linear.h"
#include "reference_kalman.h"

// NEES of the Kalman filter (the EKF on a linear model) over 200 runs of a
// consistent linear scenario averages inside its 95% interval; the same
// filter with the measurement noise underestimated 4× is flagged.
TEST(Consistency, KalmanFilterIsConsistentAndAnOverConfidentOneIsFlagged) {
  std::mt19937 rng(61);
  models::LinearSystem sys = gssm::testing::randomLinearSystem(rng, 2, 1, 1, 0.1);
  const models::LinearModel truth(sys);
  io::IniDocument scenario;
  io::writeModel(truth, scenario);
  scenario.set("scenario", "name", "linear-consistent");
  scenario.set("scenario", "steps", "60");
  MonteCarloOptions o;
  o.seeds = 200;
  o.methods = {Method::Ekf};
  const auto sampler = [](unsigned seed) { return gssm::testing::normalSampler(seed); };
  const MonteCarloResult good = runMonteCarlo(io::loadScenario(scenario).scenario, o, sampler);
  EXPECT_GT(good.methods[0].mean_nees, good.nees_lo);
  EXPECT_LT(good.methods[0].mean_nees, good.nees_hi);
  EXPECT_EQ(good.methods[0].consistency, "consistent");
  EXPECT_GT(good.methods[0].mean_nis, good.nis_lo);
  EXPECT_LT(good.methods[0].mean_nis, good.nis_hi);
  EXPECT_EQ(good.methods[0].nis_consistency, "consistent");
  sys.noise.R /= 4.0;  // the estimator believes the sensor is twice as precise
  io::IniDocument overconfident;
  io::writeModel(models::LinearModel(sys), overconfident);
  const io::LoadedScenario mistuned = io::loadScenario(scenario, &overconfident);
  ASSERT_NE(mistuned.scenario.estimator, nullptr);
  const MonteCarloResult bad = runMonteCarlo(mistuned.scenario, o, sampler);
  EXPECT_EQ(bad.methods[0].consistency, "over-confident") << "mean NEES " << bad.methods[0].mean_nees;
  EXPECT_EQ(bad.methods[0].nis_consistency, "over-confident") << "mean NIS " << bad.methods[0].mean_nis;
  EXPECT_NE(bad.markdown().find("over-confident"), std::string::npos);
}

#include "gssm/solvers/ekf.h"
#include "gssm/estimator/estimator.h"

// The generic NIS (from the estimate before each update) is the EKF's own
// innovation statistic, and the same for the exact GSSM filters on a linear model.
TEST(Consistency, GenericNisEqualsTheKalmanFiltersInnovationStatistic) {
  std::mt19937 rng(62);
  const models::LinearModel model(gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1));
  SimulationSpec spec;
  spec.steps = 30;
  const SimulatedRun run = simulate(model, spec, gssm::testing::normalSampler(63));
  ExtendedKalmanFilter kf(model);
  std::vector<std::unique_ptr<Estimator>> ests;
  for (const Method m : {Method::Ekf, Method::FixedLag, Method::Incremental}) {
    EstimatorOptions o;
    o.method = m;
    o.compute_nis = true;
    ests.push_back(makeEstimator(model, o));
  }
  for (const auto& m : run.measurements) {
    kf.predict(m.t, Eigen::VectorXd(0));
    kf.update(m.y);
    for (auto& e : ests) {
      e->addMeasurement(m.t, m.y);
      EXPECT_NEAR(e->report().nis, kf.lastNis(), 1e-8 * (1 + kf.lastNis())) << e->method() << " t " << m.t;
    }
  }
}
