#pragma once
// Noise learnt from the log (docs/DESIGN.md §10): the noise levels a model
// declares learnable (ParamSpec::learnable: its σs, the diagonals of its Q
// and R) fitted by maximum likelihood from the measurements and inputs
// alone, no truth. The likelihood is the prediction-error decomposition of
// an ungated EKF pass, Σ_k log N(e_k; 0, S_k) (exact for a linear model),
// maximized over log σ by scoring (or Nelder–Mead); standard errors come
// from the curvature of the log-likelihood at the maximum.
//
//   gssm::NoiseLearningOptions o;
//   o.start = 1.0;                            // every σ from 1 in its unit
//   auto learnt = gssm::learnNoise(model, data.measurements, data.inputs, data.t0, o);
//   auto est = gssm::makeEstimator(*learnt.model, {gssm::Method::FixedLag});
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "gssm/core/data.h"
#include "gssm/model/model.h"
#include "gssm/model/param_values.h"
#include "gssm/solvers/batch_solver.h"
#include "gssm/solvers/ekf.h"

namespace gssm {

/// One fitted σ: a learnable Real parameter, one diagonal entry of a
/// learnable Matrix (its square root), or one entry of a learnable Vector of σs.
struct LearntParameter {
  std::string section;  ///< "model", or a sub-section ("channel.gps")
  std::string key;      ///< "range_sd", "Q", "R"
  int index = -1;       ///< diagonal entry of a Matrix parameter, or entry of a Vector of σs; −1 for a Real
  /// A learnable Vector of σs (its entry `index`, or its one value with index
  /// −1), not a Real or a Matrix's diagonal.
  bool of_vector = false;
  double given = 0;     ///< the model's σ before learning
  double start = 0;     ///< where learning started
  double value = 0;     ///< the learnt σ
  /// Of the learnt σ, from the curvature of the log-likelihood in log σ
  /// (delta method); NaN where the curvature does not determine it.
  double standard_error = std::numeric_limits<double>::quiet_NaN();
  /// False when the log does not determine it: its relative standard error
  /// exceeds 100%, or it trades off with another (|correlation| > 0.95).
  bool identifiable = true;
  std::string note;     ///< why it is flagged, naming the other parameter
  /// How it was learnt: "likelihood" (the EKF's prediction-error
  /// likelihood) or "em" (a σ of the constants' prior, by EM on the batch
  /// posterior of x_b).
  std::string method = "likelihood";
  /// "range_sd", "Q[1]", "channel.gps R[0]".
  std::string name() const;
};

struct NoiseLearningOptions {
  /// What to learn, by name ("range_sd", "Q" for every diagonal entry of Q,
  /// "Q[1]" for one); empty: every learnable parameter of the model.
  std::vector<std::string> parameters;
  /// > 0: every learnt σ starts here (1.0: "one in its unit", so that the
  /// result does not depend on hand-tuned values); 0: from the model's.
  double start = 0;
  /// Each σ is searched within this factor of its start. The likelihood
  /// of a σ the log does not resolve can keep rising towards 0, where the
  /// smoothers' information matrices lose their conditioning: it stops at
  /// start/search_range, and is flagged.
  double search_range = 1e4;
  int max_evaluations = 4000;  ///< likelihood evaluations (EKF passes) in all
  /// How the likelihood is maximized over log σ. "nelder-mead":
  /// derivative-free, with restarts; its large first simplex explores, so
  /// from a generic start it can pass a lesser local maximum. "scoring":
  /// quasi-Newton from forward differences of every measurement's term
  /// (the outer product of their gradients as the first curvature, then
  /// BFGS), p + 1 or 2 passes an iteration: several times fewer passes, but
  /// it climbs to the nearest maximum (docs/DESIGN.md §10).
  std::string optimizer = "nelder-mead";
  /// Converged when a Nelder–Mead restart from the best point (scoring:
  /// the next quasi-Newton step, predicted) gains less than
  /// tolerance·(1 + |log-likelihood|).
  double tolerance = 1e-7;
  int max_restarts = 6;  ///< Nelder–Mead's
  /// Filter passes run at once (scoring's differences, the curvature's):
  /// a family whose models call into Python takes 1.
  int threads = 1;
  /// After the Gaussian maximum, learn again with each measurement an
  /// outlier (uniform over its channel's span) with a learnt probability ε:
  /// a bounded likelihood that gross errors do not inflate the σs with.
  bool outliers = false;
  /// The likelihood's curvature and standard errors at its maximum (2p²
  /// further passes). The constants' prior σs learnt by EM have theirs
  /// from the expected log prior's curvature whatever this says (no pass).
  bool standard_errors = true;
  /// EM for the σs of the constants' prior (ParamSpec::constants_prior):
  /// at most this many E-steps (batch solves); converged when no σ changes
  /// by more than prior_tolerance, relative.
  int prior_iterations = 20;
  double prior_tolerance = 1e-3;
  /// The batch solver of the E-steps.
  BatchSolverOptions batch;
  /// > 0: the likelihood channels' measurements (ekf.likelihood_channels;
  /// none named: every channel's) kept at least this far apart in time (s),
  /// per channel, the others left out of the learning passes: each counted
  /// measurement is then predicted over that span of inputs and the other
  /// channels, the horizon an estimator bridges in a gap, not one step (0:
  /// every measurement). docs/DESIGN.md §10.
  double likelihood_spacing = 0;
  /// The filter the likelihood is computed with (its gates are not applied:
  /// a gated Gaussian likelihood grows without bound as σ → 0).
  ExtendedKalmanFilterOptions ekf;
  bool validate(std::string* why = nullptr) const;
};

struct NoiseLearningReport {
  std::vector<LearntParameter> parameters;
  /// The best log-likelihood after each iteration of the optimizer (never
  /// decreasing within a stage; the outlier stage's is another likelihood).
  std::vector<double> log_likelihood;
  double given_log_likelihood = 0;  ///< at the model's own values
  double start_log_likelihood = 0;  ///< where learning started
  double final_log_likelihood = 0;
  double gaussian_log_likelihood = 0;  ///< at the Gaussian stage's maximum
  /// With `outliers`: the learnt ε, and where its stage starts in log_likelihood (0: no such stage).
  double outlier_probability = 0;
  std::size_t mixture_from = 0;
  int evaluations = 0;  ///< EKF passes
  std::string optimizer;  ///< the options' ("nelder-mead", "scoring")
  int iterations = 0;
  int restarts = 0;
  bool converged = false;  ///< false: stopped at max_evaluations
  /// EM for the constants' prior (0 iterations: none learnt): the expected
  /// complete-data log prior E[log p(x_b | σ)] after each M-step (never
  /// decreasing for a fixed posterior), E-steps run, converged.
  std::vector<double> prior_expected_log_prior;
  double prior_start_expected_log_prior = 0;  ///< Q at the start σ, at the first E-step's posterior
  int prior_iterations = 0;
  bool prior_converged = false;
  double seconds = 0;
  std::size_t measurements = 0;
  ParamValues values;                  ///< every parameter of the learnt model
  std::shared_ptr<const Model> model;  ///< the learnt model
  /// EM's last E-step: the batch MAP of the run under the σ before the last
  /// M-step, which moved it by less than the tolerance (empty without EM):
  /// where a batch solve of the learnt model starts nearly converged.
  Values posterior;
  /// A few lines: each parameter's start, learnt value ± standard error.
  std::string toString() const;
};

/// The prediction-error log-likelihood of the data under `model`: one EKF
/// pass, every measurement taken (gates off). Throws NumericalError when the
/// filter fails.
double predictionErrorLogLikelihood(const Model& model, const std::vector<Measurement>& measurements,
                                    const std::vector<Input>& inputs, double t0,
                                    ExtendedKalmanFilterOptions ekf = {});

/// The models of a noise family: `make(σ)` builds the model with the σs
/// named `names` (a model without a registered type, a Python model).
/// `parameters` (optional) describes each σ; by default each is a Real
/// parameter `[model] <name>` started at `start` (or `given`).
struct NoiseFamily {
  std::vector<std::string> names;
  Eigen::VectorXd given;  ///< the σs of the model as given
  std::function<std::shared_ptr<const Model>(const Eigen::VectorXd& sigmas)> make;
  std::vector<LearntParameter> parameters;
};

/// Learns the σs of a family of models from the data (options.parameters
/// is not used: the family names what is learnt).
NoiseLearningReport learnNoise(const NoiseFamily& family, const std::vector<Measurement>& measurements,
                               const std::vector<Input>& inputs, double t0,
                               const NoiseLearningOptions& options = {});

/// Learns the model's noise from the data. Throws InvalidArgument for bad
/// options, a model without a registered type, an unknown parameter name;
/// NumericalError when the likelihood cannot be evaluated at the start.
NoiseLearningReport learnNoise(const Model& model, const std::vector<Measurement>& measurements,
                               const std::vector<Input>& inputs, double t0,
                               const NoiseLearningOptions& options = {});

}  // namespace gssm
