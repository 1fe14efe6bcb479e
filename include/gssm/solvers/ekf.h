#pragma once
// ExtendedKalmanFilter: the baseline (docs/DESIGN.md §1, eq. 7, "EKF
// discretization"). One stacked state z = [x_c; x_b] evolves step by step
// with x_b(k+1) = x_b(k); the constants are carried as a random walk with
// zero (or a small, optional) process noise and marginalized every step.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <functional>
#include <string>

#include <vector>

#include "gssm/core/serialization_fwd.h"
#include "gssm/core/data.h"
#include "gssm/model/model.h"
#include "gssm/core/values.h"
#include "gssm/factors/problem.h"

namespace gssm {

struct ExtendedKalmanFilterOptions {
  /// Optional process noise variance per constant per nominal step (size n_b,
  /// or empty for zeros). The paper's EKF uses diag(0.005², 0) on [xdot, h].
  Eigen::VectorXd constant_process_noise;
  /// Joseph-form covariance update (numerically safer; same result in exact
  /// arithmetic).
  bool joseph_form = true;
  /// Apply the channels' EKF gates (false: every measurement updates, as the
  /// prediction-error likelihood of noise learning needs; not an INI key).
  bool use_gates = true;
  /// A bounded outlier model (not an INI key; noise learning's): each
  /// measurement is an inlier N(h, R) with probability 1 − ε or an outlier
  /// of density exp(outlier_log_density[channel]) (uniform over its span)
  /// with probability ε. The update then moves by the inlier
  /// responsibility w (the moments of the two-component posterior) and the
  /// log-likelihood counts the mixture. 0: plain Gaussian.
  double outlier_probability = 0;
  std::vector<double> outlier_log_density;
  /// The channels whose innovations the log-likelihood counts (not an INI
  /// key; noise learning's [learn] likelihood_channels); empty: every
  /// channel. The others still update the estimate: the likelihood is then
  /// that of the counted channels given the rest (e.g. GNSS fixes given the
  /// vehicle constraints' pseudo-measurements).
  std::vector<int> likelihood_channels;
  /// Keep each counted update's log N(e; 0, S) (not an INI key; noise
  /// learning's scoring takes the gradient of every term).
  bool keep_log_likelihood_terms = false;
  bool validate(int nb, std::string* why = nullptr) const;
};

class ExtendedKalmanFilter {
 public:
  /// Starts at the model's priors at time t0. The model must outlive the filter.
  explicit ExtendedKalmanFilter(const Model& model, ExtendedKalmanFilterOptions options = {},
                                double t0 = 0.0);

  /// Propagates to time t > time() with input u held over the interval.
  /// Throws InvalidArgument (filter unchanged) on bad time or input.
  void predict(double t, const Eigen::VectorXd& u);
  /// Measurement update at the current time on the default channel; throws
  /// (filter unchanged) on a bad measurement or a non-positive-definite
  /// innovation covariance.
  void update(const Eigen::VectorXd& y);
  /// Update with a measurement on its channel (its own R when given).
  /// Returns false, leaving the estimate unchanged, when the channel has an
  /// EKF gate and the measurement's NIS exceeds it (an outlier); lastNis()
  /// is its NIS either way.
  bool update(const Measurement& m);

  double time() const { return t_; }
  /// Stacked mean [x_c; x_b] and covariance.
  const Eigen::VectorXd& mean() const { return z_; }
  const Eigen::MatrixXd& covariance() const { return P_; }
  /// Normalized innovation squared of the last update (NIS).
  double lastNis() const { return nis_; }
  /// Σ log N(e; 0, S) over the updates taken since construction: the
  /// prediction-error decomposition of the log-likelihood of the data
  /// (docs/DESIGN.md §10; not checkpointed).
  double logLikelihood() const { return log_likelihood_; }
  /// The terms of logLikelihood() in the order taken (with
  /// keep_log_likelihood_terms; empty otherwise).
  const std::vector<double>& logLikelihoodTerms() const { return log_likelihood_terms_; }
  /// Measurements rejected by their channel's gate so far.
  std::int64_t rejected() const { return rejected_; }
  const Model& model() const { return *model_; }
  /// A = [F_c F_cb] of the last predict(): the rows of the stacked
  /// transition F = [A; 0 I] that move (n_c × n; empty before any).
  const Eigen::MatrixXd& lastTransition() const { return p_.A; }

  /// Checkpoint: time, mean, covariance, last NIS (the options are the
  /// owner's). load() checks the sizes against the model and changes
  /// nothing unless all is well.
  void save(internal::ByteWriter& out) const;
  void load(internal::ByteReader& in);

 private:
  double outlierLogDensity(int channel) const;
  void commitUpdate(double w);
  // An update's intermediate results, kept from one update to the next so
  // that none allocates (a 31-state filter's 24 ranges an epoch made ~15
  // allocations each); `P` is the candidate covariance, swapped in on success.
  struct UpdateBuffers {
    Eigen::VectorXd xc, xb, yhat, innov, whitened, dz;
    // PHt = P Hᵀ, K = PHt S⁻¹ (KT: Kᵀ), At = ½ K S − PHt: n × m, contiguous columns
    Eigen::MatrixXd J_h_xc, J_h_xb, H, PHt, S, K, KT, At, P;
    std::vector<Eigen::Index> nonzero;  // H's nonzero columns
    Eigen::LLT<Eigen::MatrixXd> llt;
  };
  // A prediction's: f's Jacobians, A = [F_c F_cb], T = A P and the new P_cc.
  struct PredictBuffers {
    Eigen::MatrixXd J_f_xc, J_f_xb, A, T, Pcc;
    Eigen::VectorXd constants_var;  // P_bb's diagonal plus the constants' own process noise
  };
  void innovationCovariance(const Eigen::MatrixXd& R, double scale);
  bool josephUpdate();
  const Model* model_;
  ExtendedKalmanFilterOptions options_;
  double t_;
  Eigen::VectorXd z_;
  Eigen::MatrixXd P_;
  double nis_ = 0.0;
  double log_likelihood_ = 0.0;
  std::vector<double> log_likelihood_terms_;
  std::vector<char> counted_;  // per channel, from likelihood_channels (empty: all)
  std::int64_t rejected_ = 0;
  /// Whether P_ is exactly symmetric: every update leaves it so, the prior
  /// and a loaded P need not be (the next prediction symmetrizes all of it).
  bool symmetric_ = false;
  UpdateBuffers u_;
  PredictBuffers p_;
};

/// Runs `filter` over a step schedule (stepSchedule's): predicts to each
/// step's time under the input in force, calls `predicted` (when given),
/// updates with the step's measurements, then calls `after` (when given).
/// The one filter loop of an offline pass.
void filterAlong(ExtendedKalmanFilter& filter, const std::vector<ScheduledStep>& schedule,
                 const std::vector<Measurement>& measurements, const std::vector<Input>& inputs,
                 const std::function<void()>& after = {}, const std::function<void()>& predicted = {});

/// An initial guess for a batch solve from one EKF pass and, when
/// `smoothed`, its Rauch–Tung–Striebel smoother over the stacked state
/// (docs/DESIGN.md §5): x_b from the filter's final estimate, x_c(k) the
/// smoothed x_c(k|N) (or the filtered x_c(k|k)). From a poor prior, dead
/// reckoning drifts without bound over a long run (e.g. x off by 5·10⁵ m
/// after 10⁵ radar steps), which LM cannot recover from; the filter's
/// estimates stay near the data. The filtered states were linearized
/// before the constants were known and jump at every update; the smoothed
/// ones are the linearized MAP itself (on a linear model the batch's
/// answer), so Gauss–Newton starts next to where it ends.
Values ekfInitialGuess(const Model& model, const ExtendedKalmanFilterOptions& options,
                       const std::vector<Measurement>& measurements,
                       const std::vector<Input>& inputs = {}, double t0 = 0.0, bool smoothed = true);

}  // namespace gssm
