#include <algorithm>
#include <cmath>

#include "gssm/analysis/metrics.h"

namespace gssm {

namespace {
// x_c at `from` carried to `to` by f, each input held over its interval
// (inputs[input]: the newest at or before `from`, if any).
Eigen::VectorXd carried(const Model& model, Eigen::VectorXd xc, const Eigen::VectorXd& xb,
                        const std::vector<Input>& inputs, std::size_t input, double from, double to) {
  bool in_force = !inputs.empty() && inputs[input].t <= from;
  Eigen::VectorXd u = in_force ? inputs[input].u : Eigen::VectorXd::Zero(model.dims().nu);
  std::size_t next = in_force ? input + 1 : input;
  for (double t = from; t < to;) {
    const double until = next < inputs.size() ? std::min(to, inputs[next].t) : to;
    if (until > t) xc = model.f(xc, xb, u, until - t);
    t = until;
    if (next < inputs.size() && inputs[next].t <= t) u = inputs[next++].u;
  }
  return xc;
}
}  // namespace

std::vector<PointError> predictionErrorSeries(const Model& model, const OfflineRun& run,
                                              const std::vector<Input>& inputs, const std::vector<Measurement>& at) {
  std::vector<PointError> out;
  const int nc = model.dims().nc, nb = model.dims().nb;
  std::size_t row = 0, input = 0;
  for (const Measurement& m : at) {
    while (row + 1 < run.rows.size() && run.rows[row + 1].t <= m.t) ++row;
    if (run.rows.empty() || run.rows[row].t > m.t) continue;
    const EstimateRow& r = run.rows[row];
    while (input + 1 < inputs.size() && inputs[input + 1].t <= r.t) ++input;
    const Eigen::VectorXd xb = r.mean.tail(nb);
    const Eigen::VectorXd xc = carried(model, r.mean.head(nc), xb, inputs, input, r.t, m.t);
    out.push_back({m.t, model.hWith(m.channel, m.regressors, xc, xb) - m.y});
  }
  return out;
}

double horizontalNorm(const Eigen::VectorXd& error) { return error.head(std::min<Eigen::Index>(2, error.size())).norm(); }

PointErrors summarizePointErrors(const std::vector<PointError>& errors) {
  PointErrors e;
  double sum_h = 0, sum = 0, max_h = 0, max = 0;
  for (const PointError& p : errors) {
    const Eigen::VectorXd& d = p.error;
    const double h = horizontalNorm(d), n = d.norm();
    sum_h += h * h, sum += n * n, max_h = std::max(max_h, h), max = std::max(max, n);
    ++e.count;
  }
  if (e.count == 0) return e;
  const double count = static_cast<double>(e.count);
  e.horizontal_rms = std::sqrt(sum_h / count), e.horizontal_max = max_h;
  e.rms = std::sqrt(sum / count), e.max = max;
  return e;
}

PointErrors predictionErrors(const Model& model, const OfflineRun& run, const std::vector<Input>& inputs,
                             const std::vector<Measurement>& at) {
  return summarizePointErrors(predictionErrorSeries(model, run, inputs, at));
}

}  // namespace gssm
