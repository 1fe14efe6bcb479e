#include <gtest/gtest.h>

#include <random>

#include "gssm/error.h"
#include "gssm/io/config.h"
#include "gssm/montecarlo.h"

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
  const auto scenario = io::builtinScenario("consistent", 1, 60);
  MonteCarloOptions o;
  o.seeds = 6;
  o.threads = 2;
  o.window = 5;
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
  EXPECT_EQ(a.methods[0].method, "ekf");
  EXPECT_NE(a.markdown().find("| fixed-lag |"), std::string::npos);
  MonteCarloOptions bad;
  bad.methods = {"fixed-lag"};
  EXPECT_THROW(runMonteCarlo(scenario, bad, sampler), InvalidArgument);
}
