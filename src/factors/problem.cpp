#include "gssm/factors/problem.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/core/time.h"

namespace gssm {

Eigen::VectorXd inputAt(const Model& model, const std::vector<Input>& inputs, double t) {
  auto it = std::upper_bound(inputs.begin(), inputs.end(), t,  // in force: at or before t (core/time.h)
                             [](double tt, const Input& in) { return tt < in.t && !sameTime(tt, in.t); });
  if (it == inputs.begin()) return Eigen::VectorXd::Zero(model.dims().nu);
  return std::prev(it)->u;
}

std::vector<ScheduledStep> stepSchedule(const std::vector<Measurement>& measurements,
                                        const std::vector<Input>& inputs, double t0) {
  std::vector<ScheduledStep> steps;
  std::size_t mi = 0, ii = 0;
  while (ii < inputs.size() && inputs[ii].t <= t0) ++ii;
  while (mi < measurements.size() || ii < inputs.size()) {
    const double t = std::min(mi < measurements.size() ? measurements[mi].t : INFINITY,
                              ii < inputs.size() ? inputs[ii].t : INFINITY);
    // An event at the newest step's instant (core/time.h) joins it.
    if (steps.empty() || (t > steps.back().t && !sameTime(t, steps.back().t))) steps.push_back({t, {}});
    for (; mi < measurements.size() && measurements[mi].t == t; ++mi) steps.back().measurements.push_back(mi);
    while (ii < inputs.size() && inputs[ii].t == t) ++ii;
  }
  return steps;
}

std::vector<FactorPtr> priorFactors(const Model& model, const Gaussian& state_prior,
                                    const Gaussian& constants_prior, std::int64_t step) {
  // The model's angle components, split between x_c and x_b.
  const int nc = model.dims().nc;
  std::vector<int> state_angles, constant_angles;
  for (int a : model.angleStates()) (a < nc ? state_angles : constant_angles).push_back(a < nc ? a : a - nc);
  std::vector<FactorPtr> f{
      std::make_shared<PriorFactor>(Key::state(step), state_prior, state_angles, model.rotationBlocksIn(false))};
  if (model.dims().nb > 0)
    f.push_back(std::make_shared<PriorFactor>(Key::constants(), constants_prior, constant_angles,
                                              model.rotationBlocksIn(true)));
  return f;
}

std::vector<FactorPtr> stepFactors(const Model& model, std::int64_t k, double dt, const Eigen::VectorXd& u,
                                   const Measurement* measurements, std::size_t count) {
  std::vector<FactorPtr> f{std::make_shared<ProcessFactor>(model, k - 1, u, dt)};
  for (std::size_t i = 0; i < count; ++i) f.push_back(std::make_shared<MeasurementFactor>(model, k, measurements[i]));
  return f;
}

Problem buildProblem(const Model& model, const std::vector<Measurement>& measurements,
                     const std::vector<Input>& inputs, double t0) {
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    requireVector(inputs[i].u, model.dims().nu, "input " + std::to_string(i));
    if (!std::isfinite(inputs[i].t) || (i > 0 && !(inputs[i].t > inputs[i - 1].t)))
      throw InvalidArgument("input " + std::to_string(i) + ": time " + std::to_string(inputs[i].t) +
                            " is not after the previous input");
  }
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    const double t = measurements[i].t;
    const double prev = i ? measurements[i - 1].t : t0;
    if (!std::isfinite(t) || !(t > t0) || t < prev) {
      std::ostringstream os;
      os << "measurement " << i << ": time " << t << " must be after t0 = " << t0
         << " and not before the previous measurement (" << prev << ")";
      throw InvalidArgument(os.str());
    }
  }
  Problem p;
  p.times.push_back(t0);
  const bool has_constants = model.dims().nb > 0;
  for (const auto& f : priorFactors(model, model.priorState(), model.priorConstants())) p.graph.add(f);
  p.initial.insert(Key::state(0), model.priorState().mean);
  if (has_constants) p.initial.insert(Key::constants(), model.priorConstants().mean);
  const Eigen::VectorXd xb0 = has_constants ? model.priorConstants().mean : Eigen::VectorXd();
  for (const ScheduledStep& step : stepSchedule(measurements, inputs, t0)) {
    const double prev = p.times.back();
    const auto k = static_cast<std::int64_t>(p.times.size()) - 1;
    const Eigen::VectorXd u = inputAt(model, inputs, prev);
    for (const auto& f : stepFactors(model, k + 1, step.t - prev, u)) p.graph.add(f);
    p.initial.insert(Key::state(k + 1), model.f(p.initial.at(Key::state(k)), xb0, u, step.t - prev));
    p.times.push_back(step.t);
    for (std::size_t i : step.measurements)
      p.graph.add(std::make_shared<MeasurementFactor>(model, k + 1, measurements[i]));
  }
  return p;
}

void replacePriors(Problem& p, const Model& model) {
  const auto priors = priorFactors(model, model.priorState(), model.priorConstants());
  for (std::size_t i = 0; i < priors.size(); ++i) p.graph.replace(i, priors[i]);
  p.initial.at(Key::state(0)) = model.priorState().mean;
  if (model.dims().nb > 0) p.initial.at(Key::constants()) = model.priorConstants().mean;
}

}  // namespace gssm
