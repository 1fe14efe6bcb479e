#include "gssm/offline.h"

#include <algorithm>
#include <chrono>

#include "gssm/problem.h"

namespace gssm {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
}  // namespace

OfflineRun runStreaming(const Model& model, const EstimatorOptions& options,
                        const std::vector<Measurement>& measurements,
                        const std::vector<Input>& inputs,
                        const std::function<void(std::size_t, std::size_t)>& progress) {
  OfflineRun out;
  out.method = options.method;
  const std::size_t every = std::max<std::size_t>(1, measurements.size() / 100);
  const auto start = Clock::now();
  auto est = makeEstimator(model, options);
  std::size_t next_input = 0;
  out.rows.reserve(measurements.size());
  out.update_seconds.reserve(measurements.size());
  for (const auto& m : measurements) {
    for (; next_input < inputs.size() && inputs[next_input].t < m.t; ++next_input)
      est->addInput(std::max(inputs[next_input].t, est->time()), inputs[next_input].u);
    const auto t0 = Clock::now();
    est->addMeasurement(m.t, m.y);
    out.update_seconds.push_back(since(t0));
    if (options.compute_nis) out.nis.push_back(est->report().nis);
    const StateEstimate e = est->current();
    out.rows.push_back({e.t, e.mean, e.covariance});
    out.iterations = std::max(out.iterations, est->report().iterations);
    if (progress && (out.rows.size() % every == 0 || out.rows.size() == measurements.size()))
      progress(out.rows.size(), measurements.size());
  }
  out.total_seconds = since(start);
  out.summary = est->report().detail;
  return out;
}

OfflineRun runBatch(const Model& model, const BatchSolverOptions& options,
                    const std::vector<Measurement>& measurements,
                    const std::vector<Input>& inputs) {
  OfflineRun out;
  out.method = "batch";
  const auto start = Clock::now();
  Problem p = buildProblem(model, measurements, inputs);
  Values x = ekfInitialGuess(model, ExtendedKalmanFilterOptions{}, measurements, inputs);
  BatchSolver solver(options);
  const BatchSolverSummary sum = solver.solve(p.graph, x);
  out.iterations = sum.iterations;
  out.summary = sum.toString();
  out.update_seconds.push_back(sum.seconds);
  const int nc = model.dims().nc, nb = model.dims().nb;
  // One row per measurement time (states between measurements, made by
  // inputs, have no row), as the streaming runs report.
  std::size_t mi = 0;
  for (std::size_t k = 1; k < p.times.size(); ++k) {
    if (mi >= measurements.size() || measurements[mi].t != p.times[k]) continue;
    while (mi < measurements.size() && measurements[mi].t == p.times[k]) ++mi;
    const Key key = Key::state(static_cast<std::int64_t>(k));
    EstimateRow row;
    row.t = p.times[k];
    row.mean.resize(nc + nb);
    row.mean.head(nc) = x.at(key);
    if (nb) row.mean.tail(nb) = x.at(Key::constants());
    row.covariance = solver.jointMarginalCovariance(stackedKeys(model, key.step));
    out.rows.push_back(std::move(row));
  }
  out.total_seconds = since(start);
  return out;
}

}  // namespace gssm
