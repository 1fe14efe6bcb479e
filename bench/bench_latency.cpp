// Per-update latency of every streaming estimator on the radar paper
// scenario, in one run so the ratios to the EKF share the machine's state.
// Each benchmark streams the whole scenario once per iteration and reports
// the median and p99 of the individual update times as counters (seconds).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <random>

#include "gssm/solvers/batch_solver.h"
#include "gssm/estimator/estimator.h"
#include "gssm/analysis/metrics.h"
#include "gssm/models/radar2d.h"
#include "gssm/analysis/offline.h"
#include "gssm/model/simulation.h"

namespace {

const gssm::SimulatedRun& paperRun(int steps) {
  static std::map<int, gssm::SimulatedRun> cache;
  auto it = cache.find(steps);
  if (it != cache.end()) return it->second;
  gssm::models::Radar2D radar;
  gssm::SimulationSpec spec;
  spec.steps = steps;
  spec.x0 = Eigen::VectorXd::Constant(1, 0.0);
  spec.xb = Eigen::Vector2d(100, 1000);
  spec.process_noise = false;
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0, 1);
  return cache[steps] = gssm::simulate(radar, spec, [&] { return n(rng); });
}

void streamEstimator(benchmark::State& state, gssm::Method method, int window) {
  const gssm::models::Radar2D radar;
  const int steps = static_cast<int>(state.range(0));
  const auto& run = paperRun(steps);
  gssm::EstimatorOptions o;
  o.method = method;
  o.fixed_lag.window = o.paper_window.window = window;
  if (method == gssm::Method::Ekf) o.ekf.constant_process_noise = Eigen::Vector2d(0.005 * 0.005, 0);  // the paper's EKF
  std::vector<double> times;
  times.reserve(static_cast<std::size_t>(steps) * 4);
  for (auto _ : state) {
    auto est = gssm::makeEstimator(radar, o);
    for (const auto& m : run.measurements) {
      const auto t0 = std::chrono::steady_clock::now();
      est->addMeasurement(m.t, m.y);
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    benchmark::DoNotOptimize(est->current().mean.data());
  }
  state.counters["median_s"] = gssm::percentile(times, 50);
  state.counters["p99_s"] = gssm::percentile(times, 99);
  state.counters["max_s"] = gssm::percentile(times, 100);
  state.counters["updates"] = static_cast<double>(times.size());
}

void BM_Batch(benchmark::State& state) {
  const gssm::models::Radar2D radar;
  const auto& run = paperRun(static_cast<int>(state.range(0)));
  int iterations = 0;
  for (auto _ : state) {
    const gssm::OfflineRun r = gssm::runBatch(radar, gssm::EstimatorOptions(gssm::Method::Batch), run.measurements);
    iterations = r.iterations;
    benchmark::DoNotOptimize(r.rows.back().mean.data());
  }
  state.counters["iterations"] = iterations;
}

}  // namespace

BENCHMARK_CAPTURE(streamEstimator, ekf, gssm::Method::Ekf, 10)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(streamEstimator, fixed_lag_w5, gssm::Method::FixedLag, 5)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(streamEstimator, fixed_lag_w10, gssm::Method::FixedLag, 10)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(streamEstimator, fixed_lag_w20, gssm::Method::FixedLag, 20)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(streamEstimator, fixed_lag_w50, gssm::Method::FixedLag, 50)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(streamEstimator, fixed_lag_w100, gssm::Method::FixedLag, 100)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(streamEstimator, incremental, gssm::Method::Incremental, 10)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(streamEstimator, paper_window_w10, gssm::Method::PaperWindow, 10)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(streamEstimator, paper_window_w100, gssm::Method::PaperWindow, 100)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Batch)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
