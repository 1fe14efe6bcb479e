#pragma once
// The full-history GSSM factor graph of one run (docs/DESIGN.md §1): one node for
// the constants x_b for the whole run, one node x_c(k) per measurement time,
// priors on x_c(0) and x_b, a process factor per step and a measurement
// factor per measurement.
#include <vector>

#include "gssm/core/data.h"
#include "gssm/factors/factors.h"

namespace gssm {

struct Problem {
  FactorGraph graph;
  Values initial;             ///< dead reckoning from the prior means
  std::vector<double> times;  ///< t_k of x_c(k), k = 0..N
};

/// Priors on x_c(step) and, when the model has constants, on x_b (in that
/// order). The model's own priors are priorFactors(m, m.priorState(),
/// m.priorConstants()); the paper window re-prioritizes its oldest state.
std::vector<FactorPtr> priorFactors(const Model& model, const Gaussian& state_prior,
                                    const Gaussian& constants_prior, std::int64_t step = 0);

/// What the step k−1 → k adds to the graph: its process factor x_c(k−1) →
/// x_c(k) under input u over dt (touching x_b), and the measurement at
/// x_c(k) of each of measurements[0..count) (docs/DESIGN.md §1, eqs. 2–3).
std::vector<FactorPtr> stepFactors(const Model& model, std::int64_t k, double dt, const Eigen::VectorXd& u,
                                   const Measurement* measurements = nullptr, std::size_t count = 0);

/// x_c(0) sits at t0; each measurement opens a new step. Inputs are held
/// (zero-order hold) from their time on; before the first input u = 0.
/// Throws InvalidArgument naming the measurement index when a time is not
/// increasing or a value has the wrong size or is not finite.
Problem buildProblem(const Model& model, const std::vector<Measurement>& measurements,
                     const std::vector<Input>& inputs = {}, double t0 = 0.0);

/// p's priors (buildProblem puts them first) re-made from `model`'s: for a
/// model that differs from the one p was built with in its priors alone
/// (EM's constants' prior σs), whose other factors p keeps (they refer to
/// p's model, which must outlive p).
void replacePriors(Problem& p, const Model& model);

/// One state of a run after x_c(0): its time and the measurements taken at it.
struct ScheduledStep {
  double t = 0;
  std::vector<std::size_t> measurements;  ///< indices into the measurement list
};

/// The states a run creates, as the streaming estimators make them: one per
/// input time after t0 and per measurement time (merged, in time order);
/// measurements attach at their time. Entry i is x_c(i + 1).
std::vector<ScheduledStep> stepSchedule(const std::vector<Measurement>& measurements,
                                        const std::vector<Input>& inputs, double t0);

/// The input in force at time t (zero-order hold); zeros before the first.
Eigen::VectorXd inputAt(const Model& model, const std::vector<Input>& inputs, double t);

}  // namespace gssm
