#pragma once
// Models, estimator options and scenarios from an INI configuration. Each
// component reads its own section:
//   [model]  type (radar2d | linear), T, Q, R  (linear: A_c, A_b, B, C_c, C_b,
//            discretization = euler | exact)
//   [prior]  state_mean, state_cov, constants_mean, constants_cov
//   [truth]  state0, constants (absent: drawn from the prior), process_noise,
//            measurement_noise
//   [scenario] name, seed, steps
//   [ekf]    constant_process_noise, joseph_form
//   [smoother], [fixed_lag], [paper_window]  estimator settings (below)
#include <memory>
#include <string>

#include "gssm/ekf.h"
#include "gssm/io/ini.h"
#include "gssm/model.h"
#include "gssm/simulation.h"
#include "gssm/smoothers.h"

namespace gssm::io {

/// Builds the model described by [model] and [prior]. Throws InputError
/// naming file, line and key for an unknown type or a bad value.
std::unique_ptr<Model> makeModel(const IniDocument& ini);
/// Writes a model's [model] and [prior] sections (radar2d and linear).
void writeModel(const Model& model, IniDocument& ini);

ExtendedKalmanFilterOptions ekfOptions(const IniDocument& ini, const Model& model);
/// [smoother]: relinearize, relinearize_threshold, constants_check_sigmas,
/// max_local_iterations, wildfire_threshold, ordering (colamd | time);
/// [fixed_lag] / [paper_window]: window. Absent keys keep the defaults.
SmootherOptions smootherOptions(const IniDocument& ini);
int windowOption(const IniDocument& ini, const std::string& section, int fallback);
SimulationSpec simulationSpec(const IniDocument& ini, const Model& model);

/// Names of the built-in scenarios ("paper", "consistent").
std::vector<std::string> scenarioNames();
/// The full configuration of a built-in scenario (model, priors, truth, EKF
/// settings, seed, steps). Throws InvalidArgument for an unknown name.
IniDocument builtinScenario(const std::string& name, unsigned seed, int steps);

}  // namespace gssm::io
