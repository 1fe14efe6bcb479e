#include "gssm/model/simulation.h"

#include <Eigen/Cholesky>

#include "gssm/core/angles.h"
#include "gssm/core/rotation_blocks.h"
#include "gssm/core/error.h"

namespace gssm {

Eigen::VectorXd sampleGaussian(const Eigen::VectorXd& mean, const Eigen::MatrixXd& cov,
                               const NormalSampler& draw) {
  Eigen::VectorXd e(mean.size());
  for (Eigen::Index i = 0; i < e.size(); ++i) e[i] = draw();
  if (mean.size() == 0) return mean;
  const Eigen::MatrixXd L = Eigen::LLT<Eigen::MatrixXd>(cov).matrixL();
  return mean + L * e;
}

SimulatedRun simulate(const Model& model, const SimulationSpec& spec, const NormalSampler& draw) {
  if (spec.steps < 0) throw InvalidArgument("simulate: steps must be >= 0");
  if (spec.measure_every < 1) throw InvalidArgument("simulate: measure_every must be >= 1");
  const ModelDims& d = model.dims();
  SimulatedRun run;
  // Draw order is fixed (x0, xb, then per step q then r) so a seed gives one run.
  // x ~ mean ⊕ N(0, P) on the rotation blocks (docs/DESIGN.md §12), mean + N(0, P) elsewhere.
  const std::vector<int>& rot = model.rotationBlocks();
  auto around = [&](const Gaussian& g, int offset) {
    if (!hasRotationIn(rot, g.mean.size(), offset)) return sampleGaussian(g.mean, g.covariance, draw);
    Eigen::VectorXd x = g.mean;
    retractBlocks(x, sampleGaussian(Eigen::VectorXd::Zero(g.mean.size()), g.covariance, draw), rot, offset);
    return x;
  };
  run.states.push_back(spec.x0 ? *spec.x0 : around(model.priorState(), 0));
  run.constants = spec.xb ? *spec.xb : around(model.priorConstants(), d.nc);
  requireVector(run.states[0], d.nc, "simulate: true x_c(0)");
  requireVector(run.constants, d.nb, "simulate: true x_b");
  const double T = model.nominalStep();
  const Eigen::VectorXd zc = Eigen::VectorXd::Zero(d.nc);
  if (spec.channels.empty()) throw InvalidArgument("simulate: no measurement channels");
  for (int c : spec.channels)  // model.channel throws naming a channel the model does not have
    if (model.channel(c).regressors > 0)
      throw InvalidArgument("simulate: channel '" + model.channel(c).name +
                            "' reads known values beside the state (regressors), which a simulation has not got");
  run.times.push_back(0.0);
  for (int k = 1; k <= spec.steps; ++k) {
    const double t_prev = (k - 1) * T;
    const Eigen::VectorXd u = spec.input ? spec.input(t_prev, run.constants) : Eigen::VectorXd(Eigen::VectorXd::Zero(d.nu));
    requireVector(u, d.nu, "simulate: input at t = " + std::to_string(t_prev));
    if (spec.input) run.inputs.push_back({t_prev, u});
    Eigen::VectorXd x = model.f(run.states.back(), run.constants, u, T);
    if (spec.process_noise) retractBlocks(x, sampleGaussian(zc, model.processNoiseOf(T, u), draw), rot);
    wrapAngles(x, model.angleStates());  // stacked indices below n_c are x_c's
    const double t = k * T;
    if (k % spec.measure_every == 0) {
      const int c = spec.channels[run.measurements.size() % spec.channels.size()];
      const MeasurementChannel& ch = model.channel(c);
      Eigen::VectorXd y = model.hWith(c, Eigen::VectorXd(), x, run.constants);
      if (spec.measurement_noise) y += sampleGaussian(Eigen::VectorXd::Zero(ch.dim()), ch.R, draw);
      wrapAngles(y, ch.angles);
      run.measurements.push_back({t, std::move(y), c, {}});
    }
    run.times.push_back(t);
    run.states.push_back(std::move(x));
  }
  return run;
}

Truth SimulatedRun::truth() const {
  Truth t;
  t.times = times;
  for (const auto& x : states) {
    Eigen::VectorXd z(x.size() + constants.size());
    z << x, constants;
    t.states.push_back(std::move(z));
  }
  return t;
}

}  // namespace gssm
