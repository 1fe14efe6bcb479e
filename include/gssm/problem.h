#pragma once
// The full-history GSSM factor graph of one run (DESIGN.md §1): one node for
// the constants x_b for the whole run, one node x_c(k) per measurement time,
// priors on x_c(0) and x_b, a process factor per step and a measurement
// factor per measurement.
#include <vector>

#include "gssm/data.h"
#include "gssm/factors.h"

namespace gssm {

struct Problem {
  FactorGraph graph;
  Values initial;             ///< dead reckoning from the prior means
  std::vector<double> times;  ///< t_k of x_c(k), k = 0..N
};

/// x_c(0) sits at t0; each measurement opens a new step. Inputs are held
/// (zero-order hold) from their time on; before the first input u = 0.
/// Throws InvalidArgument naming the measurement index when a time is not
/// increasing or a value has the wrong size or is not finite.
Problem buildProblem(const Model& model, const std::vector<Measurement>& measurements,
                     const std::vector<Input>& inputs = {}, double t0 = 0.0);

/// The input in force at time t (zero-order hold); zeros before the first.
Eigen::VectorXd inputAt(const Model& model, const std::vector<Input>& inputs, double t);

}  // namespace gssm
