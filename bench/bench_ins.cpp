// Latency on the real GNSS/INS drive (datasets/gnss-ins-drive, issue #37):
// each streaming estimator fed the first 60 s of the log in time order (an
// IMU sample is one step: Estimator::addInput; the measurements of one
// instant — a GNSS fix, the non-holonomic and zero-velocity constraints —
// one update: addMeasurements). Counters (seconds): the median and p99 of
// the per-IMU-sample and the per-epoch times, in one run so the ratios to
// the EKF share the machine's state. The scenario's own noise values (the
// start of its learning: latency does not depend on them).
#include <benchmark/benchmark.h>

#include <chrono>

#include "gssm/analysis/metrics.h"
#include "gssm/estimator/estimator.h"
#include "gssm/io/config.h"
#include "gssm/io/dataset.h"
#include "bundled_dataset.h"

namespace {

using Drive = gssm::bench::BundledDataset;

const Drive& drive() {
  static const Drive d = gssm::bench::loadBundledDataset("gnss-ins-drive");
  return d;
}

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void streamDrive(benchmark::State& state, gssm::Method method) {
  const Drive& d = drive();
  gssm::EstimatorOptions o = d.options;
  o.method = method;
  const double end = d.data.t0 + 60.0;
  std::vector<double> samples, epochs;
  for (auto _ : state) {
    samples.clear(), epochs.clear();
    auto est = gssm::makeEstimator(*d.model, o);
    std::size_t i = 0, m = 0;
    const auto& in = d.data.inputs;
    const auto& ms = d.data.measurements;
    while ((i < in.size() && in[i].t < end) || (m < ms.size() && ms[m].t < end)) {
      if (i < in.size() && in[i].t < end && (m >= ms.size() || in[i].t < ms[m].t)) {
        const auto t0 = std::chrono::steady_clock::now();
        est->addInput(std::max(in[i].t, est->time()), in[i].u);
        samples.push_back(since(t0));
        ++i;
        continue;
      }
      std::size_t j = m;
      while (j < ms.size() && ms[j].t == ms[m].t) ++j;
      const auto t0 = std::chrono::steady_clock::now();
      est->addMeasurements(&ms[m], j - m);
      epochs.push_back(since(t0));
      m = j;
    }
    benchmark::DoNotOptimize(est->current().mean.data());
  }
  state.counters["imu_sample_median_s"] = gssm::percentile(samples, 50);
  state.counters["imu_sample_p99_s"] = gssm::percentile(samples, 99);
  state.counters["epoch_median_s"] = gssm::percentile(epochs, 50);
  state.counters["epoch_p99_s"] = gssm::percentile(epochs, 99);
  state.counters["imu_samples"] = static_cast<double>(samples.size());
  state.counters["epochs"] = static_cast<double>(epochs.size());
}

void BM_InsEkf(benchmark::State& s) { streamDrive(s, gssm::Method::Ekf); }
void BM_InsFixedLag(benchmark::State& s) { streamDrive(s, gssm::Method::FixedLag); }
void BM_InsIncremental(benchmark::State& s) { streamDrive(s, gssm::Method::Incremental); }

}  // namespace

BENCHMARK(BM_InsEkf)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_InsFixedLag)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_InsIncremental)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_MAIN();
