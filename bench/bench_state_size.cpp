// Per-update latency vs state size: a synthetic linear GSSM with n_c
// time-series states and n_b constants (n_y = n_c measurements), fixed-lag
// smoother (w = 10) against the EKF on the same data, in one run.
#include <benchmark/benchmark.h>

#include <chrono>
#include <random>

#include "gssm/estimator/estimator.h"
#include "gssm/analysis/metrics.h"
#include "gssm/models/linear.h"
#include "gssm/model/simulation.h"

namespace {

gssm::models::LinearModel syntheticModel(int nc, int nb) {
  std::mt19937 rng(static_cast<unsigned>(nc * 100 + nb));
  std::normal_distribution<double> g(0, 1);
  auto rnd = [&](int r, int c, double s) {
    Eigen::MatrixXd m(r, c);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < c; ++j) m(i, j) = s * g(rng);
    return m;
  };
  gssm::models::LinearSystem s;
  s.A_c = rnd(nc, nc, 0.3 / std::sqrt(nc));
  s.A_b = rnd(nc, nb, 1.0 / std::sqrt(nb));
  s.B = Eigen::MatrixXd::Zero(nc, 0);
  s.C_c = Eigen::MatrixXd::Identity(nc, nc);
  s.C_b = rnd(nc, nb, 0.1 / std::sqrt(nb));
  s.noise.T = 0.1;
  s.noise.Q = 0.01 * Eigen::MatrixXd::Identity(nc, nc);
  s.noise.R = 0.1 * Eigen::MatrixXd::Identity(nc, nc);
  s.noise.prior_state = {Eigen::VectorXd::Zero(nc), Eigen::MatrixXd::Identity(nc, nc)};
  s.noise.prior_constants = {Eigen::VectorXd::Zero(nb), Eigen::MatrixXd::Identity(nb, nb)};
  return gssm::models::LinearModel(s);
}

void stateSize(benchmark::State& state, gssm::Method method) {
  const int nc = static_cast<int>(state.range(0)), nb = static_cast<int>(state.range(1));
  const auto model = syntheticModel(nc, nb);
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  gssm::SimulationSpec spec;
  spec.steps = 300;
  const gssm::SimulatedRun run = gssm::simulate(model, spec, [&] { return g(rng); });
  gssm::EstimatorOptions o;
  o.method = method;
  o.fixed_lag.window = o.paper_window.window = 10;
  o.smoother.relinearize = false;  // linear: nothing to relinearize
  std::vector<double> times;
  for (auto _ : state) {
    auto est = gssm::makeEstimator(model, o);
    for (const auto& m : run.measurements) {
      const auto t0 = std::chrono::steady_clock::now();
      est->addMeasurement(m.t, m.y);
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
  }
  state.counters["median_s"] = gssm::percentile(times, 50);
  state.counters["p99_s"] = gssm::percentile(times, 99);
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int nc : {1, 4, 16, 64})
    for (int nb : {1, 4, 16, 64}) b->Args({nc, nb});
}

}  // namespace

BENCHMARK_CAPTURE(stateSize, ekf, gssm::Method::Ekf)->Apply(sizes)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(stateSize, fixed_lag_w10, gssm::Method::FixedLag)->Apply(sizes)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
