// Per-update latency of every streaming estimator on the radar paper
// scenario, in one run so the ratios to the EKF share the machine's state.
// Each benchmark streams the whole scenario once per iteration and reports
// the median and p99 of the individual update times as counters (seconds).
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <random>

#include "gssm/factors/problem.h"
#include "gssm/solvers/batch_solver.h"
#include "gssm/solvers/ekf.h"
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

// The batch MAP solve on a long run, timed in parts: LM from the EKF's
// estimates (BatchSolver::solve, a new solver each time, as runBatch does)
// and every step's marginal covariance, with an EKF pass over the same
// measurements as the in-run baseline; medians over the iterations. Also
// the page faults per solve: memory the allocator gave back between solves
// is fresh again, and on this VM a fault costs ~7 µs (gssm_history_probe
// STEPS batch measures the first solve of a fresh process).
void BM_BatchSolve(benchmark::State& state) {
  const gssm::models::Radar2D radar;
  const auto& run = paperRun(static_cast<int>(state.range(0)));
  const gssm::Problem problem = gssm::buildProblem(radar, run.measurements, {}, 0.0);
  const gssm::Values guess = gssm::ekfInitialGuess(radar, gssm::ExtendedKalmanFilterOptions{}, run.measurements, {}, 0.0);
  const gssm::EstimatorOptions ekf(gssm::Method::Ekf);
  std::vector<double> solve_s, marginals_s, ekf_s, faults;
  int iterations = 0;
  auto minorFaults = [] {
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return static_cast<double>(ru.ru_minflt);
  };
  using Clock = std::chrono::steady_clock;
  auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  for (auto _ : state) {
    state.PauseTiming();
    gssm::Values x = guess;
    state.ResumeTiming();
    const double faults0 = minorFaults();
    const auto t0 = Clock::now();
    gssm::BatchSolver solver;
    iterations = solver.solve(problem.graph, x).iterations;
    const auto t1 = Clock::now();
    faults.push_back(minorFaults() - faults0);
    for (std::int64_t k = 1; k <= static_cast<std::int64_t>(run.measurements.size()); ++k)
      benchmark::DoNotOptimize(solver.jointMarginalCovariance(gssm::stackedKeys(radar, k)).data());
    const auto t2 = Clock::now();
    auto est = gssm::makeEstimator(radar, ekf);
    for (const auto& m : run.measurements) est->addMeasurement(m.t, m.y);
    benchmark::DoNotOptimize(est->current().mean.data());
    const auto t3 = Clock::now();
    solve_s.push_back(seconds(t0, t1));
    marginals_s.push_back(seconds(t1, t2));
    ekf_s.push_back(seconds(t2, t3));
  }
  state.counters["solve_s"] = gssm::percentile(solve_s, 50);
  state.counters["marginals_s"] = gssm::percentile(marginals_s, 50);
  state.counters["ekf_s"] = gssm::percentile(ekf_s, 50);
  state.counters["solve_faults"] = gssm::percentile(faults, 50);
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
BENCHMARK(BM_BatchSolve)->Arg(20000)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
