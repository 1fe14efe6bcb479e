// Latency of a late measurement by its lateness (#25): a reading joining the
// state L steps before the newest costs re-eliminating the path from that
// state to the root, not a rebuild; L = 0 is an in-order update at the newest
// state, the baseline in the same run.
#include <benchmark/benchmark.h>

#include <chrono>
#include <random>

#include "gssm/estimator/estimator.h"
#include "gssm/models/linear.h"
#include "track_with_bias.h"

namespace {

void lateMeasurement(benchmark::State& state, gssm::Method method) {
  static const gssm::models::LinearModel model(gssm::testing::trackWithBias(0.01, 0.04, 0.25, 0.1));
  const auto lateness = static_cast<std::int64_t>(state.range(0));
  gssm::EstimatorOptions o(method);
  o.fixed_lag.window = 10;
  auto est = gssm::makeEstimator(model, o);
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.5);
  const int steps = 2000;
  for (int k = 1; k <= steps; ++k) est->addMeasurement(0.1 * k, Eigen::VectorXd::Constant(1, 0.1 * k + noise(rng)));
  int k = steps;
  for (auto _ : state) {
    // A new state in order (not timed), then the timed reading: a second one
    // of the state `lateness` steps back (each state gets one).
    ++k;
    est->addMeasurement(0.1 * k, Eigen::VectorXd::Constant(1, 0.1 * k + noise(rng)));
    const double t = 0.1 * static_cast<double>(k - lateness);
    const auto start = std::chrono::steady_clock::now();
    est->addMeasurement(t, Eigen::VectorXd::Constant(1, t + noise(rng)));
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  state.counters["late"] = static_cast<double>(est->report().late);
}

}  // namespace

BENCHMARK_CAPTURE(lateMeasurement, incremental, gssm::Method::Incremental)
    ->Arg(0)->Arg(1)->Arg(10)->Arg(100)->Arg(1000)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(lateMeasurement, fixed_lag, gssm::Method::FixedLag)
    ->Arg(0)->Arg(1)->Arg(5)->Arg(9)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
