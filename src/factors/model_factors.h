#pragma once
// Internal: what ProcessFactor and MeasurementFactor compute, as functions
// of their parameters, so that a solver holding a model's factors as their
// numbers (the Bayes tree engine: one process and one measurement factor a
// step for the whole run) evaluates them with the very same code.
#include <Eigen/Core>
#include <vector>

#include "gssm/core/gaussian.h"
#include "gssm/core/robust_loss.h"
#include "gssm/factors/factors.h"
#include "gssm/model/model.h"

namespace gssm::internal {

/// r = L_Q⁻¹ (x_c(k+1) − f(x_c(k), x_b, u, dt)) (docs/DESIGN.md eq. 2) with
/// its Jacobian blocks J = [J_r_xk, J_r_xk1, J_r_xb]; x = [x_c(k), x_c(k+1),
/// x_b], x_b only if the model has constants.
void processResidual(const Model& model, const Eigen::VectorXd& u, double dt, const GaussianNoise& noise,
                     const Eigen::VectorXd* const* x, Eigen::VectorXd& r, std::vector<Eigen::MatrixXd>* J);

/// r = L_R⁻¹ (h_c(x_c(k), x_b) − y) on `channel` (eq. 3), its angle
/// components wrapped; x = [x_c(k), x_b], x_b only if the model has constants;
/// h reads `regressors` (Measurement::regressors) on a channel that takes any.
void measurementResidual(const Model& model, int channel, const Eigen::Ref<const Eigen::VectorXd>& y,
                         const GaussianNoise& noise, const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                         std::vector<Eigen::MatrixXd>* J, const Eigen::VectorXd& regressors = {});

/// Where a variable of `model` holds rotations: its stacked blocks, from 0
/// in x_c, from n_c in x_b (constants true); null blocks for a model without.
Factor::Rotations rotationsOfVariable(const Model& model, bool constants);

/// r and J scaled by √ρ'(s), s = ‖r‖², for a robust loss; returns ½ρ(s).
double robustify(const RobustLoss& loss, Eigen::VectorXd& r, std::vector<Eigen::MatrixXd>* J);

}  // namespace gssm::internal
