#pragma once
// Monte Carlo comparison of estimators on a scenario over many seeds
// (the paper's claim, tested honestly).
#include "gssm/analysis/chi_square.h"  // the consistency verdicts' intervals
#include <Eigen/Core>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "gssm/estimator/estimator.h"
#include "gssm/model/simulation.h"

namespace gssm {

/// What a Monte Carlo simulates and with what it estimates (io::
/// monteCarloScenario builds one from a scenario.ini).
struct MonteCarloScenario {
  std::string name;
  const Model* truth = nullptr;      ///< simulates every seed's run (must outlive the call)
  SimulationSpec spec;
  /// The estimators' own model and priors when they differ from the truth's
  /// (e.g. a deliberately mis-tuned R); null: the truth's. Same dimensions.
  const Model* estimator = nullptr;
  /// Every method's settings (windows, [smoother], [ekf], [batch]); the
  /// method is set per run.
  EstimatorOptions options;
};

struct MonteCarloOptions {
  int seeds = 100;
  unsigned first_seed = 1;
  int threads = 2;
  std::vector<Method> methods{Method::Ekf, Method::FixedLag, Method::Incremental, Method::PaperWindow,
                              Method::Batch};
  /// Called from worker threads after each seed (done, total); may be empty.
  std::function<void(int, int)> progress;
  bool validate(std::string* why = nullptr) const;
};

struct MethodSummary {
  Method method = Method::Ekf;
  Eigen::VectorXd mean_rmse;        ///< per stacked state, mean over seeds of the run's RMSE
  Eigen::VectorXd rms_final_error;  ///< per stacked state, RMS over seeds of the last error
  double mean_nees = 0;             ///< average over seeds and steps
  double nees_step_in_interval = 0; ///< fraction of steps whose seed-average NEES is inside the 95% interval
  Eigen::VectorXd beats_ekf;        ///< per stacked state: fraction of seeds with RMSE below the EKF's
  std::vector<double> times;        ///< measurement times
  std::vector<Eigen::VectorXd> rmse_over_time;  ///< per step: sqrt(mean over seeds of e²)
  /// "consistent", "over-confident" (mean NEES above the 95% interval: the
  /// covariance is too small) or "under-confident" (below it).
  std::string consistency;
  double mean_nis = 0;              ///< average over seeds and steps (NaN for batch: no innovations)
  std::string nis_consistency;      ///< verdict of the NIS against its interval ("" for batch)
  double nis_step_in_interval = 0;  ///< fraction of steps whose seed-average NIS is inside its interval
  int failures = 0;                 ///< seeds where the estimator threw (excluded)
  std::string first_failure;
};

struct MonteCarloResult {
  std::string scenario;
  int seeds = 0, steps = 0, dof = 0;
  double nees_lo = 0, nees_hi = 0;  ///< 95% interval of a seed-average NEES at one step
  int nis_dof = 0;                  ///< measurement dimension
  double nis_lo = 0, nis_hi = 0;    ///< 95% interval of a seed-average NIS at one step
  std::vector<std::string> state_names;
  std::vector<MethodSummary> methods;
  double seconds = 0;
  /// The Markdown table (one row per method).
  std::string markdown() const;
};

/// One seed of a campaign: its simulated run estimated by every method.
/// The unit of work a distributed campaign ships (Python `gssm.campaign`
/// runs seeds on Dask workers and summarizes them in seed order).
struct MonteCarloSeedResult {
  struct PerMethod {
    Method method = Method::Ekf;
    bool ok = false;
    std::string error;                 ///< what the estimator threw (when !ok)
    std::vector<Eigen::VectorXd> sq;   ///< per measurement: squared error of each stacked state
    std::vector<double> nees, nis;     ///< per measurement (nis empty for batch)
    Eigen::VectorXd rmse, final_error; ///< over the run; at the last measurement
  };
  unsigned seed = 0;
  std::vector<double> times;           ///< measurement times
  std::vector<PerMethod> methods;      ///< in MonteCarloOptions::methods order
};

/// Simulates seed `seed` (N(0, 1) draws from `draw`) and runs every method of
/// `options` on it. Checks nothing: runMonteCarlo and campaigns validate first
/// (validateMonteCarlo).
MonteCarloSeedResult runMonteCarloSeed(const MonteCarloScenario& scenario, const MonteCarloOptions& options,
                                       unsigned seed, const NormalSampler& draw);

/// Throws InvalidArgument unless the options, the scenario's models and every
/// method's settings are usable together.
void validateMonteCarlo(const MonteCarloScenario& scenario, const MonteCarloOptions& options);

/// The table of a campaign from its seeds' results, which must be seeds
/// first_seed, first_seed + 1, ... in that order (sums run in seed order, so
/// the result is the same bit for bit however the seeds were computed).
/// `seconds` is left 0 for the caller.
MonteCarloResult summarizeMonteCarlo(const MonteCarloScenario& scenario, const MonteCarloOptions& options,
                                     const std::vector<MonteCarloSeedResult>& seeds);

/// Runs the scenario for seeds first_seed.. with every method, on
/// options.threads threads. `sampler_for_seed` makes the N(0, 1) source of
/// one seed.
MonteCarloResult runMonteCarlo(const MonteCarloScenario& scenario, const MonteCarloOptions& options,
                               const std::function<NormalSampler(unsigned)>& sampler_for_seed);

}  // namespace gssm
