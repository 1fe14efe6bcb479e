// Per-update latency and peak memory of a streaming estimator over a long
// radar run (paper scenario), at steps 10³, 10⁴, 10⁵, 10⁶. Measurements are
// simulated on the fly and only the last 1000 latencies are kept, so the
// peak RSS is the estimator's own. Usage: gssm_history_probe STEPS METHOD
//   METHOD: ekf | fixed-lag | incremental | batch (the whole run, once)
#include <sys/resource.h>

#include <chrono>
#include <deque>
#include <iostream>
#include <random>

#include "gssm/factors/problem.h"
#include "gssm/solvers/batch_solver.h"
#include "gssm/solvers/ekf.h"
#include "gssm/estimator/estimator.h"
#include "gssm/analysis/metrics.h"
#include "gssm/models/radar2d.h"
#include "gssm/analysis/offline.h"

namespace {
long maxRssMb() {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss / 1024;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: gssm_history_probe STEPS ekf|fixed-lag|incremental|batch\n";
    return 2;
  }
  const long steps = std::atol(argv[1]);
  const std::string method = argv[2];
  const gssm::models::Radar2D radar;
  std::mt19937 rng(1);
  std::normal_distribution<double> n01(0, 1);
  double x = 0;  // truth: x(0) = 0, xdot = 100, h = 1000
  auto next = [&](long k) {
    x += 100 * 0.05;
    return gssm::Measurement{k * 0.05, Eigen::VectorXd::Constant(1, std::hypot(x, 1000.0) + 3 * n01(rng))};
  };
  if (gssm::methodNamed(method) == gssm::Method::Batch) {
    std::vector<gssm::Measurement> ms;
    for (long k = 1; k <= steps; ++k) ms.push_back(next(k));
    // As gssm-process's batch does it (runBatch), in its parts: the problem
    // and the EKF's initial guess, the solve, every step's marginal
    // covariance — in a fresh process, so the solver's memory is all new.
    using Clock = std::chrono::steady_clock;
    auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
    const auto t0 = Clock::now();
    gssm::Problem problem = gssm::buildProblem(radar, ms);
    gssm::Values x = gssm::ekfInitialGuess(radar, gssm::ExtendedKalmanFilterOptions{}, ms, {}, 0.0);
    const auto t1 = Clock::now();
    gssm::BatchSolver solver;
    const gssm::BatchSolverSummary sum = solver.solve(problem.graph, x);
    const auto t2 = Clock::now();
    double sink = 0;
    for (long k = 1; k <= steps; ++k) sink += solver.jointMarginalCovariance(gssm::stackedKeys(radar, k))(0, 0);
    const auto t3 = Clock::now();
    std::cout << "batch, " << steps << " steps: " << sum.toString() << "\n  solve " << seconds(t1, t2)
              << " s + every step's marginal covariance " << seconds(t2, t3) << " s = " << seconds(t1, t3)
              << " s; with the problem and the EKF initial guess " << seconds(t0, t3) << " s, peak RSS "
              << maxRssMb() << " MB" << (sink > 0 ? "" : " (no covariance?)") << "\n";
    return 0;
  }
  gssm::EstimatorOptions o;
  if (!gssm::methodNamed(method)) {
    std::cerr << "history_probe: unknown method '" << method << "' (" << gssm::methodNameList() << ")\n";
    return 2;
  }
  o.method = *gssm::methodNamed(method);
  auto est = gssm::makeEstimator(radar, o);
  std::deque<double> window;
  for (long k = 1; k <= steps; ++k) {
    const gssm::Measurement m = next(k);
    const auto t0 = std::chrono::steady_clock::now();
    est->addMeasurement(m.t, m.y);
    window.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (window.size() > 1000) window.pop_front();
    if (k == 1000 || k == 10000 || k == 100000 || k == 1000000) {
      const std::vector<double> w(window.begin(), window.end());
      std::cout << method << " step " << k << ": median " << gssm::percentile(w, 50) * 1e6 << " us, p99 "
                << gssm::percentile(w, 99) * 1e6 << " us (last 1000 updates), peak RSS " << maxRssMb() << " MB\n";
    }
  }
  return 0;
}
