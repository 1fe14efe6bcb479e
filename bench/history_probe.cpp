#include <chrono>
#include <iostream>
#include <random>
#include <sys/resource.h>
#include "gssm/estimator.h"
#include "gssm/metrics.h"
#include "gssm/models/radar2d.h"
#include "gssm/simulation.h"
#include "gssm/offline.h"
#include "gssm/batch_solver.h"
int main(int argc, char** argv) {
  const int steps = std::atoi(argv[1]); const std::string method = argv[2];
  gssm::models::Radar2D radar;
  gssm::SimulationSpec spec; spec.steps = steps; spec.x0 = Eigen::VectorXd::Constant(1,0.0); spec.xb = Eigen::Vector2d(100,1000); spec.process_noise=false;
  std::mt19937 rng(1); std::normal_distribution<double> n(0,1);
  auto run = gssm::simulate(radar, spec, [&]{return n(rng);});
  if (method == "batch") {
    auto t0 = std::chrono::steady_clock::now();
    gssm::OfflineRun r = gssm::runBatch(radar, gssm::BatchSolverOptions{}, run.measurements);
    struct rusage ru; getrusage(RUSAGE_SELF, &ru);
    std::cout << "batch " << steps << " steps: " << r.summary << "\n  total incl. EKF initial guess and all marginals "
              << std::chrono::duration<double>(std::chrono::steady_clock::now()-t0).count() << " s, maxrss " << ru.ru_maxrss/1024 << " MB\n";
    return 0;
  }
  gssm::EstimatorOptions o; o.method = method; if (argc > 3) o.smoother.wildfire_threshold = std::atof(argv[3]);
  auto est = gssm::makeEstimator(radar, o);
  std::vector<double> t; int passes = 0;
  for (int k = 0; k < steps; ++k) {
    auto t0 = std::chrono::steady_clock::now();
    est->addMeasurement(run.measurements[k].t, run.measurements[k].y);
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now()-t0).count());
    passes += est->report().smoother.relinearization_pass;
    const int kk = k + 1;
    if (kk == 1000 || kk == 10000 || kk == 100000 || kk == 1000000) {
      std::vector<double> w(t.end() - std::min<int>(1000, kk), t.end());
      struct rusage ru; getrusage(RUSAGE_SELF, &ru);
      std::cout << "step " << kk << ": median(last 1000) " << gssm::percentile(w, 50)*1e6 << " us, p99 " << gssm::percentile(w, 99)*1e6 << " us, passes so far " << passes << ", maxrss " << ru.ru_maxrss/1024 << " MB\n";
    }
  }
}
