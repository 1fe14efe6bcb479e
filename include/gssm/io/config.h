#pragma once
// Models, estimator options and scenarios from an INI configuration. Each
// component reads its own section:
//   [model]  type (a registered model: radar_2d, nav_2d, range_beacon_2d,
//            linear, ...) and its parameters; [prior] its priors (each
//            model type declares its keys: docs/DESIGN.md §3, "Adding a model")
//   [truth]  state0, constants (absent: drawn from the prior), process_noise,
//            measurement_noise
//   [scenario] name, seed, steps
//   [ekf]    constant_process_noise, joseph_form
//   [smoother], [fixed_lag], [paper_window], [batch]  estimator settings (below)
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "gssm/estimator/estimator.h"
#include "gssm/io/ini.h"
#include "gssm/io/ini_keys.h"
#include "gssm/model/model.h"
#include "gssm/analysis/montecarlo.h"
#include "gssm/model/simulation.h"
#include "gssm/solvers/smoothers.h"

namespace gssm::io {

/// Builds the model described by [model] and [prior]. Throws InputError
/// naming file, line and key for an unknown type or a bad value.
/// Files the INI names (a range-beacon model's beacons.csv, the truth file
/// its start position comes from) are read from `data_dir` when given, else
/// from the INI's folder.
std::unique_ptr<Model> makeModel(const IniDocument& ini, const std::string& data_dir = "");
/// Writes a model's [model] and [prior] sections (and a linear model's
/// channel sections, `[channel.NAME]`); InvalidArgument for a model type not registered.
void writeModel(const Model& model, IniDocument& ini);
/// Writes the values a type's parameters take when an INI leaves them out
/// (ModelType::defaults; nothing for a type without them).
void writeModelDefaults(const ModelType& type, IniDocument& ini);
/// A file named in the INI: in `data_dir` when given, else beside the INI.
std::string dataFile(const IniDocument& ini, const std::string& data_dir, const std::string& file);

/// The method named by `text`; InputError naming `where` (e.g. "option
/// --method" or "s.ini: [run] method") and the known names otherwise.
Method parseMethod(const std::string& text, const std::string& where);

/// Every method's settings from its section, for a run of `method`:
/// [ekf] constant_process_noise, joseph_form; [smoother] relinearize,
/// relinearize_threshold, constants_check_sigmas, max_local_iterations,
/// wildfire_threshold, iterate_to_convergence, convergence_tolerance,
/// max_iterations, newton_polish_steps, ordering (colamd | time: the
/// incremental smoother's); [fixed_lag] window; [paper_window] window;
/// [batch] algorithm (levenberg-marquardt | gauss-newton), max_iterations,
/// newton_polish_steps. Absent keys keep the defaults; an unknown key or a
/// bad value is an InputError naming file, section and key.
EstimatorOptions estimatorOptions(const IniDocument& ini, const Model& model,
                                  Method method = Method::FixedLag);
/// The [batch] section's solver options alone (as estimatorOptions reads them).
BatchSolverOptions batchOptions(const IniDocument& ini);
/// Writes every method's settings into its section (the keys estimatorOptions
/// reads; a wildfire threshold of ∞, the default, is left out).
void writeEstimatorOptions(const EstimatorOptions& options, IniDocument& ini);
/// Each estimator section and the keys it takes, in order (the INI side of
/// the Python options objects: docs/DESIGN.md §4).
std::vector<std::pair<std::string, std::vector<std::string>>> estimatorIniKeys();
SimulationSpec simulationSpec(const IniDocument& ini, const Model& model);
/// [scenario]'s and [truth]'s keys, with type, default and meaning.
std::vector<IniKey> scenarioIniKeys();
std::vector<IniKey> truthIniKeys();
/// Refuses a key of [scenario] or [truth] not in those tables (file and
/// line), and a bad [scenario] band_sigmas.
void requireScenarioKeys(const IniDocument& ini);
/// [scenario] band_sigmas (default 3): the figures' bands, estimate ± this
/// many σ; throws InputError (file and line) unless positive and finite.
double figureBandSigmas(const IniDocument& ini);

/// A Monte Carlo scenario from INI documents, with the models it points to.
struct LoadedScenario {
  std::unique_ptr<Model> truth;      ///< [model], [prior] of the scenario
  std::unique_ptr<Model> estimator;  ///< of `estimator_config`; null: the truth's
  MonteCarloScenario scenario;       ///< points into the models above
};
/// The scenario's truth model and simulation ([scenario], [truth]), and the
/// estimators' model and every method's settings from `estimator_config`
/// when given (a deliberately mis-tuned model), else from the scenario.
LoadedScenario loadScenario(const IniDocument& scenario, const IniDocument* estimator_config = nullptr);

/// Names of the built-in scenarios ("paper", "consistent").
std::vector<std::string> scenarioNames();
/// The full configuration of a built-in scenario (model, priors, truth, EKF
/// settings, seed, steps). Throws InvalidArgument for an unknown name.
IniDocument builtinScenario(const std::string& name, unsigned seed, int steps);

}  // namespace gssm::io
