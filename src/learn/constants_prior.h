#pragma once
// EM on the factor graph for the σs that shape the constants' prior
// (docs/DESIGN.md §10): the E-step is a batch solve of the whole log, whose
// posterior of x_b is N(m, P); the M-step maximizes the expected log prior
//   Q(σ) = −½ (log det Σ(σ) + tr(Σ(σ)⁻¹ (P + (m − μ(σ))(m − μ(σ))ᵀ)))
// over log σ, with μ, Σ the prior of x_b the model builds from σ.
#include <cmath>
#include <string>
#include <vector>

#include "gssm/learn/noise_learning.h"

namespace gssm::internal {

/// The values with the chosen σs set: a Real directly; a Matrix as D M D
/// with D = diag(σ_new / σ_given) on its learnt entries (correlations kept).
ParamValues withSigmas(const ParamValues& base, const std::vector<LearntParameter>& ps, const Eigen::VectorXd& sigmas);

/// σ = exp(θ), element by element with std::exp: the value a LearntParameter
/// reports and the learnt scenario.ini holds, to the bit (Eigen's vectorized
/// exp can differ in the last bit, and a model built from it would not be
/// the one the written file rebuilds).
inline Eigen::VectorXd sigmasOf(const Eigen::VectorXd& theta) {
  return theta.unaryExpr([](double t) { return std::exp(t); });
}

/// Learns `params` (σs of the constants' prior of model type `type_name`)
/// starting from r.values, by EM; appends them to r.parameters and sets
/// r.values, r.model and the prior_* fields. Throws NumericalError when the
/// batch solve fails at the start.
void learnConstantsPrior(const std::string& type_name, std::vector<LearntParameter> params,
                         const std::vector<Measurement>& measurements, const std::vector<Input>& inputs, double t0,
                         const NoiseLearningOptions& options, NoiseLearningReport& r);

}  // namespace gssm::internal
