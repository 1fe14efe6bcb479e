// Per-epoch latency on the real UWB log (datasets/uwb-fast: 24 ranges an
// epoch, 24 link-bias constants): each streaming estimator fed the first
// 2000 epochs, an epoch as one update (Estimator::addMeasurements) or range
// by range; the median and p99 of the epoch times as counters (seconds), in
// one run so the ratios to the EKF share the machine's state; and the
// resident memory the estimator grew by per epoch (memory per step).
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <chrono>
#include <fstream>

#include "gssm/analysis/metrics.h"
#include "gssm/estimator/estimator.h"
#include "gssm/io/config.h"
#include "gssm/io/dataset.h"
#include "bundled_dataset.h"

namespace {

// Resident memory now (bytes), from /proc/self/statm.
double residentBytes() {
  std::ifstream statm("/proc/self/statm");
  double size = 0, resident = 0;
  statm >> size >> resident;
  return resident * static_cast<double>(sysconf(_SC_PAGESIZE));
}

// The log and its first 2000 epochs (a log line: all its ranges).
struct Log : gssm::bench::BundledDataset {
  std::vector<std::vector<gssm::Measurement>> epochs;
};

const Log& uwbLog() {
  static Log log = [] {
    Log l{gssm::bench::loadBundledDataset("uwb-fast"), {}};
    for (const auto& m : l.data.measurements) {
      if (l.epochs.empty() || l.epochs.back().front().t != m.t) {
        if (l.epochs.size() == 2000) break;
        l.epochs.emplace_back();
      }
      l.epochs.back().push_back(m);
    }
    return l;
  }();
  return log;
}

void streamEpochs(benchmark::State& state, gssm::Method method, bool grouped) {
  const Log& log = uwbLog();
  gssm::EstimatorOptions o = log.options;
  o.method = method;
  std::vector<double> times;
  times.reserve(log.epochs.size() * 4);
  double grown = 0;
  for (auto _ : state) {
    const double before = residentBytes();
    auto est = gssm::makeEstimator(*log.model, o);
    for (const auto& epoch : log.epochs) {
      const auto t0 = std::chrono::steady_clock::now();
      if (grouped) est->addMeasurements(epoch);
      else
        for (const auto& m : epoch) est->addMeasurement(m);
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    benchmark::DoNotOptimize(est->current().mean.data());
    grown = residentBytes() - before;
  }
  state.counters["rss_bytes_per_epoch"] = grown / static_cast<double>(log.epochs.size());
  state.counters["epoch_median_s"] = gssm::percentile(times, 50);
  state.counters["epoch_p99_s"] = gssm::percentile(times, 99);
  state.counters["epochs"] = static_cast<double>(times.size());
}

void BM_UwbEkf(benchmark::State& s) { streamEpochs(s, gssm::Method::Ekf, true); }
void BM_UwbFixedLag(benchmark::State& s) { streamEpochs(s, gssm::Method::FixedLag, true); }
void BM_UwbFixedLagRangeByRange(benchmark::State& s) { streamEpochs(s, gssm::Method::FixedLag, false); }
void BM_UwbIncremental(benchmark::State& s) { streamEpochs(s, gssm::Method::Incremental, true); }

}  // namespace

BENCHMARK(BM_UwbEkf)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_UwbFixedLag)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_UwbFixedLagRangeByRange)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_UwbIncremental)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_MAIN();
