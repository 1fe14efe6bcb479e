// The exact causal MAP at withheld measurements (gssm-process --causal-map):
// on a linear model, a batch solve of the data up to each time is the Kalman
// filter's estimate there, so its errors equal the filter's.
#include <gtest/gtest.h>

#include <random>

#include "gssm/analysis/causal_map.h"
#include "gssm/models/linear.h"
#include "reference_kalman.h"

namespace gssm {
namespace {

// A random linear model (nc time-series states, nb constants, 2-D
// measurements) and a run of it.
struct LinearRun {
  models::LinearModel model;
  SimulatedRun run;
};
LinearRun simulatedLinear(unsigned seed, int nc, int nb, int steps) {
  std::mt19937 rng(seed);
  LinearRun r{models::LinearModel(testing::randomLinearSystem(rng, nc, nb, 2, 0.1)), {}};
  SimulationSpec spec;
  spec.steps = steps;
  r.run = simulate(r.model, spec, testing::normalSampler(seed + 1));
  return r;
}

TEST(CausalMap, OnALinearModelEqualsTheKalmanFiltersErrors) {
  const LinearRun lr = simulatedLinear(61, 3, 2, 60);
  const models::LinearModel& model = lr.model;
  const SimulatedRun& run = lr.run;
  std::vector<Measurement> used, withheld;  // every fourth measurement withheld and scored
  for (std::size_t k = 0; k < run.measurements.size(); ++k)
    (k % 4 == 3 ? withheld : used).push_back(run.measurements[k]);
  EstimatorOptions ekf;
  ekf.method = Method::Ekf;
  const OfflineRun filter = runOffline(model, ekf, used);
  const std::vector<PointError> want = predictionErrorSeries(model, filter, {}, withheld);
  for (int threads : {1, 2}) {
    const CausalMapErrors got = causalMapErrors(model, EstimatorOptions{}, used, {}, withheld,
                                                RowTimes::Measurements, threads);
    EXPECT_TRUE(got.failed.empty());
    ASSERT_EQ(got.errors.size(), want.size());
    ASSERT_EQ(want.size(), withheld.size());
    for (std::size_t k = 0; k < want.size(); ++k) {
      EXPECT_EQ(got.errors[k].t, want[k].t);
      EXPECT_LT((got.errors[k].error - want[k].error).norm(), 1e-8 * (1 + want[k].error.norm())) << "at " << want[k].t;
    }
  }
  const PointErrors s = summarizePointErrors(want);
  EXPECT_EQ(s.count, withheld.size());
  EXPECT_GT(s.horizontal_rms, 0);
}

// A solve that fails is named with its time; the others are still scored.
TEST(CausalMap, AFailedSolveIsNamedAndTheOthersScored) {
  const LinearRun lr = simulatedLinear(63, 2, 1, 20);
  const models::LinearModel& model = lr.model;
  const SimulatedRun& run = lr.run;
  std::vector<Measurement> used(run.measurements.begin(), run.measurements.end() - 1);
  std::vector<Measurement> withheld{run.measurements.back()};
  withheld.insert(withheld.begin(), used[5]);
  used[3].y[0] = std::numeric_limits<double>::quiet_NaN();  // every solve from t(3) on meets it
  withheld.insert(withheld.begin(), used[1]);
  const CausalMapErrors got = causalMapErrors(model, EstimatorOptions{}, used, {}, withheld);
  ASSERT_EQ(got.errors.size(), 1u);
  EXPECT_EQ(got.errors[0].t, used[1].t);
  ASSERT_EQ(got.failed.size(), 2u);
  EXPECT_EQ(got.failed[0].first, used[5].t);
  EXPECT_FALSE(got.failed[0].second.empty());
}

}  // namespace
}  // namespace gssm
