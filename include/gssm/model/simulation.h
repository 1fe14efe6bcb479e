#pragma once
// Simulates a run of a GSSM model: true states and noisy measurements. The
// random source is injected (a standard-normal sampler), so the core library
// has no random-number dependency; the apps plug in MRPT's seeded generator.
#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

#include "gssm/core/data.h"
#include "gssm/model/model.h"

namespace gssm {

/// Returns independent N(0, 1) draws.
using NormalSampler = std::function<double()>;

struct SimulationSpec {
  int steps = 400;                    ///< measurements k = 1..steps
  std::optional<Eigen::VectorXd> x0;  ///< true x_c(0); drawn from the prior if absent
  std::optional<Eigen::VectorXd> xb;  ///< true x_b; drawn from the prior if absent
  bool process_noise = true;          ///< draw q_c ~ N(0, Q) each step
  bool measurement_noise = true;      ///< draw r ~ N(0, R) each measurement
  /// The measured input u over [t_k, t_k+1) (zero-order hold), given the
  /// true constants x_b (a sensor reading includes its bias); empty: zeros.
  std::function<Eigen::VectorXd(double t, const Eigen::VectorXd& xb)> input;
  int measure_every = 1;              ///< a measurement every this many steps (multi-rate)
  /// The channel of each measurement, in turn (several sensors taking turns,
  /// e.g. one beacon per range); default: the default channel only.
  std::vector<int> channels{0};
};

struct SimulatedRun {
  std::vector<double> times;             ///< t_k, k = 0..steps (t_0 = 0, step T)
  std::vector<Eigen::VectorXd> states;   ///< true x_c(k), k = 0..steps
  Eigen::VectorXd constants;             ///< true x_b
  std::vector<Measurement> measurements; ///< y(k) at every measure_every-th step
  std::vector<Input> inputs;             ///< u at t_k, k = 0..steps−1 (empty without an input profile)
  /// The true stacked [x_c(k); x_b] at every t_k.
  Truth truth() const;
};

/// Draws x ~ N(mean, cov) with `draw`.
Eigen::VectorXd sampleGaussian(const Eigen::VectorXd& mean, const Eigen::MatrixXd& cov,
                               const NormalSampler& draw);

SimulatedRun simulate(const Model& model, const SimulationSpec& spec, const NormalSampler& draw);

}  // namespace gssm
