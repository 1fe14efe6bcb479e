#include "gssm/offline.h"

#include <chrono>

#include "gssm/problem.h"

namespace gssm {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
}  // namespace

OfflineRun runEkf(const Model& model, const ExtendedKalmanFilterOptions& options,
                  const std::vector<Measurement>& measurements, const std::vector<Input>& inputs) {
  OfflineRun out;
  out.method = "ekf";
  const auto start = Clock::now();
  ExtendedKalmanFilter ekf(model, options);
  for (const auto& m : measurements) {
    const auto t0 = Clock::now();
    ekf.predict(m.t, inputAt(model, inputs, ekf.time()));
    ekf.update(m.y);
    out.update_seconds.push_back(since(t0));
    out.rows.push_back({m.t, ekf.mean(), ekf.covariance()});
  }
  out.total_seconds = since(start);
  out.summary = "ExtendedKalmanFilter: " + std::to_string(measurements.size()) + " updates";
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
  for (std::size_t k = 1; k < p.times.size(); ++k) {
    const Key key = Key::state(static_cast<std::int64_t>(k));
    EstimateRow row;
    row.t = p.times[k];
    row.mean.resize(nc + nb);
    row.mean.head(nc) = x.at(key);
    if (nb) row.mean.tail(nb) = x.at(Key::constants());
    row.covariance = nb ? solver.jointMarginalCovariance({key, Key::constants()})
                        : solver.marginalCovariance(key);
    out.rows.push_back(std::move(row));
  }
  out.total_seconds = since(start);
  return out;
}

}  // namespace gssm
