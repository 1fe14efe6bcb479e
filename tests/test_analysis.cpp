#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "gssm/analysis/bounds.h"
#include "gssm/analysis/metrics.h"
#include "gssm/core/error.h"
#include "gssm/models/linear.h"
#include "reference_kalman.h"

using namespace gssm;
using gssm::testing::normalSampler;
using gssm::testing::relativeError;

// On a linear model the bound is attained: the filtering bound is the Kalman
// filter's covariance and the smoothing bound the RTS smoother's.
TEST(CramerRao, LinearModelBoundEqualsKalmanAndRtsCovariances) {
  std::mt19937 rng(51);
  const models::LinearModel model(gssm::testing::randomLinearSystem(rng, 3, 2, 2, 0.1));
  SimulationSpec spec;
  spec.steps = 40;
  const SimulatedRun run = simulate(model, spec, normalSampler(52));
  const CramerRaoBound b = posteriorCramerRao(model, run);
  const auto ref = gssm::testing::kalmanAndRts(gssm::testing::stack(model, 0.1), run.measurements);
  ASSERT_EQ(b.filtering.size(), 40u);
  for (int k = 1; k <= 40; ++k) {
    EXPECT_LT(relativeError(b.filtering[static_cast<std::size_t>(k - 1)], ref.Pf[k]), 1e-9) << "step " << k;
    EXPECT_LT(relativeError(b.smoothing[static_cast<std::size_t>(k - 1)], ref.Ps[k]), 1e-9) << "step " << k;
  }
}

// Two constants that enter only as their sum: the data determine b1 + b2 and
// say nothing about b1 − b2; the report names that combination.
TEST(Identifiability, ConstantsEnteringOnlyAsTheirSumAreReported) {
  models::LinearSystem s;
  s.A_c = Eigen::MatrixXd::Constant(1, 1, -0.5);
  s.A_b = Eigen::RowVector2d(1.0, 1.0);  // drift driven by b1 + b2
  s.B = Eigen::MatrixXd::Zero(1, 0);
  s.C_c = Eigen::MatrixXd::Ones(1, 1);
  s.C_b = Eigen::RowVector2d(0.5, 0.5);  // and measured through b1 + b2
  s.noise.T = 0.1;
  s.noise.Q = Eigen::MatrixXd::Constant(1, 1, 0.01);
  s.noise.R = Eigen::MatrixXd::Constant(1, 1, 0.04);
  s.noise.prior_state = {Eigen::VectorXd::Zero(1), Eigen::MatrixXd::Identity(1, 1)};
  s.noise.prior_constants = {Eigen::VectorXd::Zero(2), Eigen::MatrixXd::Identity(2, 2)};
  const models::LinearModel model(s);
  SimulationSpec spec;
  spec.steps = 200;
  const SimulatedRun run = simulate(model, spec, normalSampler(53));
  const CramerRaoBound b = posteriorCramerRao(model, run, 50);
  const ConstantsIdentifiability id = constantsIdentifiability(model, b.smoothing.back().bottomRightCorner(2, 2));
  EXPECT_EQ(id.rank, 1);
  EXPECT_FALSE(id.determined());
  EXPECT_NEAR(std::abs(id.directions(0, 0)), std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(id.directions(0, 0), -id.directions(1, 0), 1e-6);  // b1 − b2
  // names both constants with opposite signs ("0.707*b1 - 0.707*b2" up to an overall sign)
  EXPECT_NE(id.weakest.find("0.707*b1"), std::string::npos) << id.weakest;
  EXPECT_NE(id.weakest.find("0.707*b2"), std::string::npos) << id.weakest;
  EXPECT_TRUE(id.weakest.find("b1 - ") != std::string::npos || id.weakest.find("b1 + ") != std::string::npos)
      << id.weakest;
  // and with C_b = [0.5, -0.2] both become determined
  s.C_b = Eigen::RowVector2d(0.5, -0.2);
  const models::LinearModel observable(s);
  const SimulatedRun run2 = simulate(observable, spec, normalSampler(54));
  const auto b2 = posteriorCramerRao(observable, run2, 100);
  const auto id2 = constantsIdentifiability(observable, b2.smoothing.back().bottomRightCorner(2, 2));
  EXPECT_EQ(id2.rank, 2);
  EXPECT_TRUE(id2.determined());
}

// The latency percentiles by selection equal the sorted sample's linear
// interpolation between order statistics, for any size and p, with ties.
TEST(Percentile, EqualsInterpolationInTheSortedSample) {
  std::mt19937 rng(7);
  for (std::size_t n : {1u, 2u, 3u, 10u, 101u, 1000u}) {
    std::vector<double> v(n);
    std::uniform_int_distribution<int> value(0, 20);  // ties
    for (double& x : v) x = value(rng) * 0.5;
    std::vector<double> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    for (double p : {0.0, 1.0, 37.5, 50.0, 99.0, 100.0}) {
      const double pos = p / 100.0 * static_cast<double>(n - 1);
      const auto lo = static_cast<std::size_t>(pos);
      const auto hi = std::min(lo + 1, n - 1);
      const double expected = sorted[lo] + (pos - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
      EXPECT_DOUBLE_EQ(gssm::percentile(v, p), expected) << "n = " << n << ", p = " << p;
    }
  }
  EXPECT_EQ(gssm::percentile({}, 50), 0.0);
}
