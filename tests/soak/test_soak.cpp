// Soak: streams many radar steps through the FixedLagSmoother and checks that
// the number of graph variables and the process's peak memory stay bounded.
// Short form by default (2·10⁵ steps, a few seconds); the long form by hand:
//   GSSM_SOAK_STEPS=1000000 ctest --test-dir build -L soak
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdlib>
#include <random>

#include "gssm/estimator/estimator.h"
#include "gssm/models/radar2d.h"

namespace {
long peakRssKb() {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss;
}
}  // namespace

TEST(Soak, FixedLagSmootherMemoryAndGraphStayBounded) {
  const char* env = std::getenv("GSSM_SOAK_STEPS");
  const long steps = env ? std::atol(env) : 200000;
  ASSERT_GE(steps, 20000);
  const gssm::models::Radar2D radar;
  gssm::EstimatorOptions o;
  o.method = gssm::Method::FixedLag;
  o.fixed_lag.window = o.paper_window.window = 10;
  auto est = gssm::makeEstimator(radar, o);
  std::mt19937 rng(7);
  std::normal_distribution<double> n01(0, 1);
  double x = 0;
  long rss_after_warmup = 0;
  for (long k = 1; k <= steps; ++k) {
    x += 100 * 0.05;
    est->addMeasurement(k * 0.05, Eigen::VectorXd::Constant(1, std::hypot(x, 1000.0) + 3 * n01(rng)));
    if (k == steps / 10) rss_after_warmup = peakRssKb();
    const auto& r = est->report().smoother;
    if (k > 10 && (r.num_variables != 11u || r.num_factors > 22u)) {
      FAIL() << "step " << k << ": " << r.toString();
    }
  }
  const long rss_end = peakRssKb();
  // A leak of even 20 bytes per step would add > 3 MB over the last 90%.
  EXPECT_LT(rss_end - rss_after_warmup, 1024) << "peak RSS grew from " << rss_after_warmup << " KB to "
                                              << rss_end << " KB";
  EXPECT_TRUE(est->current().mean.allFinite());
}
