#include "gssm/problem.h"

#include <algorithm>
#include <sstream>

#include "gssm/error.h"

namespace gssm {

Eigen::VectorXd inputAt(const Model& model, const std::vector<Input>& inputs, double t) {
  auto it = std::upper_bound(inputs.begin(), inputs.end(), t,
                             [](double tt, const Input& in) { return tt < in.t; });
  if (it == inputs.begin()) return Eigen::VectorXd::Zero(model.dims().nu);
  return std::prev(it)->u;
}

Problem buildProblem(const Model& model, const std::vector<Measurement>& measurements,
                     const std::vector<Input>& inputs, double t0) {
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    requireVector(inputs[i].u, model.dims().nu, "input " + std::to_string(i));
    if (i > 0 && !(inputs[i].t > inputs[i - 1].t))
      throw InvalidArgument("input " + std::to_string(i) + ": time " +
                            std::to_string(inputs[i].t) + " is not after the previous input");
  }
  Problem p;
  p.times.push_back(t0);
  const bool has_constants = model.dims().nb > 0;
  p.graph.add(std::make_shared<PriorFactor>(Key::state(0), model.priorState()));
  p.initial.insert(Key::state(0), model.priorState().mean);
  if (has_constants) {
    p.graph.add(std::make_shared<PriorFactor>(Key::constants(), model.priorConstants()));
    p.initial.insert(Key::constants(), model.priorConstants().mean);
  }
  const Eigen::VectorXd xb0 =
      has_constants ? model.priorConstants().mean : Eigen::VectorXd();
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    const Measurement& m = measurements[i];
    const double prev = p.times.back();
    if (!std::isfinite(m.t) || !(m.t > prev)) {
      std::ostringstream os;
      os << "measurement " << i << ": time " << m.t << " must be after " << prev
         << " (times must increase strictly)";
      throw InvalidArgument(os.str());
    }
    const auto k = static_cast<std::int64_t>(p.times.size()) - 1;
    const Eigen::VectorXd u = inputAt(model, inputs, prev);
    const double dt = m.t - prev;
    p.graph.add(std::make_shared<ProcessFactor>(model, k, u, dt));
    p.graph.add(std::make_shared<MeasurementFactor>(model, k + 1, m.y));
    p.initial.insert(Key::state(k + 1), model.f(p.initial.at(Key::state(k)), xb0, u, dt));
    p.times.push_back(m.t);
  }
  return p;
}

}  // namespace gssm
