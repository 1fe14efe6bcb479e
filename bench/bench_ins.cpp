// Latency on the real GNSS/INS drive (datasets/gnss-ins-drive, issue #37):
// each streaming estimator fed the first 60 s of the log in time order (an
// input is one step: Estimator::addInput; the measurements of one instant
// — a GNSS fix, the non-holonomic and zero-velocity constraints — one
// update: addMeasurements), with a state at every IMU sample
// (imu_per_state = 1: an input is one reading) and as the scenario ships it
// (a state every 10 readings and at every measurement: an input packs the
// readings of a step). Counters (seconds): the median and p99 of the
// per-input and the per-epoch times, and the time per IMU reading (the
// whole run's, inputs and epochs, over the readings), in one run so the ratios to the EKF share
// the machine's state. The scenario's own noise values (the start of its
// learning: latency does not depend on them).
#include <benchmark/benchmark.h>

#include <chrono>

#include "gssm/analysis/metrics.h"
#include "gssm/analysis/offline.h"
#include "gssm/estimator/estimator.h"
#include "gssm/factors/problem.h"
#include "gssm/solvers/ekf.h"
#include "gssm/io/config.h"
#include "gssm/io/dataset.h"
#include "gssm/model/packed_inputs.h"
#include "bundled_dataset.h"

namespace {

using Drive = gssm::bench::BundledDataset;

const Drive& drive(bool packed) {
  static const Drive per_sample = gssm::bench::loadBundledDataset("gnss-ins-drive", {{"model", "imu_per_state", "1"}});
  static const Drive as_shipped = gssm::bench::loadBundledDataset("gnss-ins-drive");
  return packed ? as_shipped : per_sample;
}

// The IMU readings in [t0, end): one an input, or the durations a pack holds.
double readingsBefore(const Drive& d, double end) {
  double n = 0;
  const int per = d.model->readingsPerStep();
  for (const auto& in : d.data.inputs) {
    if (in.t >= end) break;
    n += per == 1 ? 1 : gssm::packedReadings(in.u, per);
  }
  return n;
}

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void streamDrive(benchmark::State& state, gssm::Method method, bool packed) {
  const Drive& d = drive(packed);
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
  double total = 0;  // the run's time: inputs and epochs
  for (double s : samples) total += s;
  for (double s : epochs) total += s;
  state.counters["input_median_s"] = gssm::percentile(samples, 50);
  state.counters["input_p99_s"] = gssm::percentile(samples, 99);
  state.counters["per_imu_reading_s"] = total / readingsBefore(d, end);
  state.counters["epoch_median_s"] = gssm::percentile(epochs, 50);
  state.counters["epoch_p99_s"] = gssm::percentile(epochs, 99);
  state.counters["inputs"] = static_cast<double>(samples.size());
  state.counters["epochs"] = static_cast<double>(epochs.size());
}

// One filter pass over the whole drive as noise learning runs it (the
// offline loop over a step schedule, the fixes' likelihood terms kept):
// learning is tens of these.
void BM_InsLearningPass(benchmark::State& state) {
  const Drive& d = drive(true);
  const auto schedule = gssm::stepSchedule(d.data.measurements, d.data.inputs, d.data.t0);
  gssm::ExtendedKalmanFilterOptions e = d.options.ekf;
  e.keep_log_likelihood_terms = true;
  for (auto _ : state) {
    gssm::ExtendedKalmanFilter filter(*d.model, e, d.data.t0);
    gssm::filterAlong(filter, schedule, d.data.measurements, d.data.inputs);
    benchmark::DoNotOptimize(filter.logLikelihood());
  }
  state.counters["steps"] = static_cast<double>(schedule.size());
}

// The batch over the whole drive as the scenario ships it (rows at every
// measurement with their covariances), the covariances from the normal
// equations' factor (0) or from a QR of the Jacobian (1: [batch]
// covariance_by_qr, the drive's setting).
void BM_InsBatch(benchmark::State& state) {
  const Drive& d = drive(true);
  gssm::EstimatorOptions o = d.options;
  o.method = gssm::Method::Batch;
  o.batch.covariance_by_qr = state.range(0) != 0;
  for (auto _ : state) {
    const gssm::OfflineRun run = gssm::runBatch(*d.model, o, d.data.measurements, d.data.inputs);
    benchmark::DoNotOptimize(run.rows.back().covariance.data());
  }
}

void BM_InsEkf(benchmark::State& s) { streamDrive(s, gssm::Method::Ekf, s.range(0) != 0); }
void BM_InsFixedLag(benchmark::State& s) { streamDrive(s, gssm::Method::FixedLag, s.range(0) != 0); }
void BM_InsIncremental(benchmark::State& s) { streamDrive(s, gssm::Method::Incremental, s.range(0) != 0); }

}  // namespace

// Argument: 0 a state per IMU sample, 1 the scenario's packed steps.
BENCHMARK(BM_InsLearningPass)->Unit(benchmark::kMillisecond)->Iterations(10);
BENCHMARK(BM_InsEkf)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_InsFixedLag)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_InsIncremental)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(1);
// Argument: 0 covariances from the normal equations, 1 by QR.
BENCHMARK(BM_InsBatch)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_MAIN();
