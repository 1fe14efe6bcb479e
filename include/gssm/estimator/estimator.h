#pragma once
// The streaming estimator API (docs/DESIGN.md §3, layer 5; §4): feed inputs and
// measurements as they arrive, read the current estimate at any time. One
// interface over the EKF, the IncrementalSmoother, the FixedLagSmoother and
// the paper's window re-solve, so applications switch by name.
//
//   gssm::models::Radar2D radar;
//   auto est = gssm::makeEstimator(radar, {gssm::Method::FixedLag});
//   for (const auto& m : measurements) est->addMeasurement(m.t, m.y);
//   std::cout << est->current().mean.transpose() << "\n";
//
// Every call has the strong exception guarantee: one that throws (wrong
// dimension, NaN, time not increasing, a singular system) leaves the
// estimator exactly as it was, and the message names the input at fault.
// An estimator is not thread-safe: use each from one thread at a time (even
// report() formats its detail line lazily).
#include <Eigen/Core>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gssm/solvers/batch_solver.h"
#include "gssm/solvers/ekf.h"
#include "gssm/core/serialization_fwd.h"
#include "gssm/estimator/method.h"
#include "gssm/model/model.h"
#include "gssm/solvers/smoothers.h"

namespace gssm {

/// Estimate of the stacked state [x_c(k); x_b] at step k (time t).
struct StateEstimate {
  double t = 0;
  std::int64_t step = 0;
  Eigen::VectorXd mean;
  Eigen::MatrixXd covariance;
};

struct EstimatorReport {
  Method method = Method::FixedLag;
  /// What the method was run with: the states it keeps (fixed-lag,
  /// paper-window; 0 = all or not a window method) and, for the smoothers,
  /// the elimination ordering (the fixed lag always orders by time).
  int window = 0;
  std::optional<EliminationOrdering> ordering;
  std::int64_t measurements = 0;  ///< measurements processed
  /// Measurements taken out of sequence (their time before the newest
  /// state's, at a state the smoother still holds), and those dropped as too
  /// late (EstimatorOptions::drop_late).
  std::int64_t late = 0, late_dropped = 0;
  double seconds = 0;         ///< wall time of the last addMeasurement
  int iterations = 0;         ///< solver iterations of the last update (1 for the EKF)
  /// Measurements rejected by their channel's EKF gate so far (EKF only;
  /// the smoothers down-weight by robust losses instead).
  std::int64_t rejected = 0;
  UpdateReport smoother;      ///< the smoother's report (incremental, fixed-lag; zeros otherwise)
  std::string detail;         ///< one line from the underlying estimator
  /// Normalized innovation squared of the last measurement, eᵀS⁻¹e with the
  /// innovation e = y − h(prediction) and S = H P_pred Hᵀ + R from the
  /// estimate before it (same definition for every method); NaN unless
  /// EstimatorOptions::compute_nis.
  double nis = std::numeric_limits<double>::quiet_NaN();
};

/// Settings of the methods that read them (the method table, method.h,
/// says which; io::estimatorOptions reads each group from its INI section).
struct EstimatorOptions {
  Method method = Method::FixedLag;
  double t0 = 0.0;            ///< time of x_c(0)
  /// Compute the NIS of every measurement (costs one covariance query per update).
  bool compute_nis = false;
  /// A measurement too late to take (see Estimator::addMeasurement) is
  /// dropped and counted in report().late_dropped instead of refused.
  bool drop_late = false;

  ExtendedKalmanFilterOptions ekf;  ///< ekf  [ekf]
  SmootherOptions smoother;         ///< incremental, fixed-lag: relinearization  [smoother]
  struct Incremental {
    EliminationOrdering ordering = EliminationOrdering::ConstrainedColamd;  ///< [smoother] ordering
  } incremental;
  struct Window {
    int window = 10;                ///< states x_c kept (the newest), ≥ 1; the paper window solves one more, then drops the oldest
  };
  struct FixedLag : Window {
    /// [fixed_lag] constants_check_sigmas: the fixed lag's own, in place of
    /// [smoother]'s (NaN: that one). Its marginal prior holds the constants
    /// linearized where each state left the window; relinearizing the
    /// window's factors at newer constants makes the two disagree (a large
    /// value, 1e9: the window's factors keep the constants they were added
    /// with, only the newest are checked). docs/DESIGN.md §12.
    double constants_check_sigmas = std::numeric_limits<double>::quiet_NaN();
  };
  FixedLag fixed_lag;               ///< [fixed_lag] window, constants_check_sigmas; always time-ordered
  Window paper_window;              ///< [paper_window] window
  BatchSolverOptions batch;         ///< batch  [batch]

  /// The window of a window method (fixed-lag, paper-window), else 0.
  int window() const {
    return method == Method::FixedLag ? fixed_lag.window : method == Method::PaperWindow ? paper_window.window : 0;
  }
  EstimatorOptions() = default;
  EstimatorOptions(Method m) : method(m) {}  // NOLINT: {Method::Ekf} reads as intended
  bool validate(const Model& model, std::string* why = nullptr) const;
};

class Estimator {
 public:
  virtual ~Estimator() = default;
  Method method() const { return report_.method; }
  const char* methodName() const { return gssm::methodName(report_.method); }

  /// Input u held from time t on (zero-order hold). A t after the newest
  /// state first advances the state to t (a step with no measurement, under
  /// the input in force until then): inputs at a high rate (an IMU) define
  /// the steps. t before the newest state is an error.
  void addInput(double t, const Eigen::VectorXd& u);
  /// A measurement y at time t. After the newest state: a new step to t. At
  /// the newest state's time (after t0): attached to that state (multi-rate
  /// sensors, several measurements per step). Before it (out of sequence:
  /// a sensor's buffer, a late radio block): the smoothers attach it to the
  /// state at its time when they still hold one (the incremental smoother:
  /// any; the fixed lag: inside its window), re-eliminating only what it
  /// touches, so the result is the one of the same data in order. Between
  /// two held states they insert a state at its time (the process factor
  /// between them split in two). Older than the fixed lag's window, before
  /// the start, and for the EKF and paper window: refused (InvalidArgument,
  /// estimator unchanged), or dropped and counted with
  /// EstimatorOptions::drop_late.
  void addMeasurement(double t, const Eigen::VectorXd& y);
  /// A measurement on the model's channel called `channel` (several
  /// sensors: any rate, any interleaving, several at one time stamp).
  void addMeasurement(double t, const std::string& channel, const Eigen::VectorXd& y);
  /// A measurement on m.channel, with its own noise covariance m.R when given
  /// (a receiver that reports its accuracy).
  void addMeasurement(const Measurement& m);
  /// Several measurements of one instant (an epoch: every sensor read at
  /// once) as one update: the smoothers add all their factors in one
  /// elimination, the EKF updates with each in turn. All share one time,
  /// checked like addMeasurement's; none is taken if one is refused. With
  /// compute_nis they go one by one (each NIS before its own update).
  void addMeasurements(const std::vector<Measurement>& ms);
  /// The same for ms[0..count), where they already lie in order.
  void addMeasurements(const Measurement* ms, std::size_t count);

  /// Newest state and constants with their joint covariance.
  virtual StateEstimate current() = 0;
  /// The estimate of x_c(k) given all data so far, when the method keeps it
  /// (incremental: any k; fixed-lag/paper-window: inside the window; EKF: the
  /// newest only). nullopt otherwise.
  virtual std::optional<StateEstimate> smoothed(std::int64_t k) = 0;

  /// Joint marginal covariance of the given variables (blocks in order), when
  /// the method holds them all (EKF: the newest state and the constants).
  virtual std::optional<Eigen::MatrixXd> marginalCovariance(const std::vector<Key>& keys) = 0;

  /// The last call's report; its `detail` line is formatted here, on demand
  /// (formatting it on every update cost 10% of a fixed-lag update).
  const EstimatorReport& report() const;
  /// The same numbers without formatting `detail` (which may be stale):
  /// for loops that read a counter after every update.
  const EstimatorReport& reportNumbers() const { return report_; }
  double time() const { return t_; }
  std::int64_t step() const { return k_; }
  const Model& model() const { return model_; }
  /// The options it was made with (by makeEstimator).
  const EstimatorOptions& options() const { return options_; }

  /// Checkpoint: time, step, input in force, report, then the method's own
  /// state (the options are written apart, see writeOptions). load()
  /// validates what it reads; on a CheckpointError the estimator must be
  /// discarded (restoreCheckpoint loads into a fresh one).
  void save(internal::ByteWriter& out) const;
  void load(internal::ByteReader& in);

 protected:
  /// Validated options (makeEstimator); the report starts with what they say is used.
  Estimator(const Model& model, const EstimatorOptions& options);
  /// Processes a validated step k−1 → k under input u, with the `count`
  /// measurements ms[0..count) at x_c(k); must be strongly exception safe.
  virtual void doStep(std::int64_t k, double dt, const Eigen::VectorXd& u, const Measurement* ms,
                      std::size_t count) = 0;
  /// Adds measurements ms[0..count) at the newest state x_c(k), k ≥ 1; strongly safe.
  virtual void doMeasurements(std::int64_t k, const Measurement* ms, std::size_t count) = 0;
  /// The one-line `detail` of the last update, called by report() only
  /// after markDetail() (default: the smoother report's line).
  virtual std::string formatDetail() const { return report_.smoother.toString(); }
  void markDetail() { detail_stale_ = true; }
  /// addMeasurement's checks of one measurement (time, channel, values, R).
  void requireUsable(const Measurement& m) const;
  /// requireUsable's checks but the time's (a late measurement's time is checked against the states held).
  void requireValues(const Measurement& m) const;
  void addAt(double t, const Measurement* ms, std::size_t count);
  /// The step of a held state at time t < time() that a late measurement
  /// can join; none by default (the EKF and the paper window keep none).
  virtual std::optional<std::int64_t> stateAt(double /*t*/) const { return std::nullopt; }
  /// A late measurement at a time between two held states: a state inserted
  /// there (the process factor between them split in two) carrying it.
  /// False when the method cannot (default); strongly exception safe.
  virtual bool insertLate(const Measurement& /*m*/) { return false; }

  const Model& model_;
  mutable EstimatorReport report_;

 private:
  /// The method's own state, for checkpoints. Defaults throw
  /// CheckpointError: an estimator that does not implement them cannot be saved.
  virtual void saveState(internal::ByteWriter& out) const;
  virtual void loadState(internal::ByteReader& in);
  void advance(double t);  // process-only step to t
  /// NIS of y at a step dt after the current estimate (dt = 0: at it).
  double innovationNis(double dt, const Eigen::VectorXd& u, const Measurement& m);
  /// A measurement before the newest state: joined to its state, or refused / dropped.
  void addLate(const Measurement& m);
  Eigen::VectorXd inputInForce() const;
  double t_;            // time of the newest state
  std::int64_t k_ = 0;  // its step
  Eigen::VectorXd input_;  // in force from the newest state on (empty: zeros)
  EstimatorOptions options_;
  mutable bool detail_stale_ = false;
};

namespace internal {
/// The options record of a checkpoint (format v1: method name, the method's
/// window, EKF options, incremental ordering, smoother options, t0, NIS).
void writeOptions(ByteWriter& out, const EstimatorOptions& options);
EstimatorOptions readOptions(ByteReader& in);
}  // namespace internal

/// Builds the streaming estimator options.method names; the model must
/// outlive it. Throws InvalidArgument naming the option at fault (and for
/// Method::Batch, which needs the whole run: see runOffline, BatchSolver).
std::unique_ptr<Estimator> makeEstimator(const Model& model, const EstimatorOptions& options = {});

}  // namespace gssm
