#pragma once
// Incremental smoothers over a GSSM factor graph (docs/DESIGN.md §6):
//
// * IncrementalSmoother — full history, iSAM2 class: each update re-eliminates
//   only the top of the Bayes tree that new or relinearized factors touch,
//   with the constants at the root.
// * FixedLagSmoother — keeps the newest `window` states x_c and the
//   constants; older states are marginalized exactly into a dense prior on
//   their separator (Schur complement), with first-estimate Jacobians.
//
// Both take factors and initial values of new variables (graph level); the
// streaming Estimator API (estimator.h) builds those from a model.
#include <Eigen/Core>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gssm/core/serialization_fwd.h"
#include "gssm/model/model.h"
#include "gssm/factors/factors.h"

namespace gssm {

/// Every field is filled by every update.
struct UpdateReport {
  int new_factors = 0;
  int new_variables = 0;
  int cliques_reeliminated = 0;    ///< summed over all re-eliminations of this update
  int orphans = 0;                 ///< subtrees detached and re-attached
  int factors_checked = 0;         ///< nonlinear factors whose linearization error was evaluated
  int factors_relinearized = 0;
  bool relinearization_pass = false;  ///< a check of every factor ran (constants moved)
  int iterations = 0;              ///< engine updates (1 + relinearization rounds)
  int variables_backsubstituted = 0;
  int variables_marginalized = 0;  ///< FixedLagSmoother only
  std::size_t num_variables = 0, num_factors = 0, num_cliques = 0;  ///< after the update
  double seconds = 0;
  std::string note;                ///< e.g. a skipped relinearization and why; empty if none
  std::string toString() const;
};

enum class EliminationOrdering {
  /// CCOLAMD over the re-eliminated variables, constrained: constants last
  /// (root), the newest variables next to them.
  ConstrainedColamd,
  /// States by time step, constants last: the oldest state is always a leaf.
  TimeOrdered,
};
/// "colamd" or "time": the ordering's name in INI files and in Python.
const char* orderingName(EliminationOrdering ordering);
/// The ordering called `name`, if any.
std::optional<EliminationOrdering> orderingNamed(const std::string& name);

/// The relinearization policy both smoothers share (the ordering is the
/// IncrementalSmoother's choice; the fixed lag always orders by time).
struct SmootherOptions {
  /// false: every factor keeps the linearization it was added with
  /// (exact for linear models; the cheapest mode).
  bool relinearize = true;
  /// A factor is relinearized when its whitened linearization error
  /// ‖r(x̂) − r_lin(x̂)‖ exceeds this (units of its noise sigma).
  double relinearize_threshold = 1e-2;
  /// Factors of the re-eliminated top are checked every update; all factors
  /// are checked (an O(n) pass) when the constants moved more than this many
  /// of their marginal standard deviations since the last such pass.
  double constants_check_sigmas = 1.0;
  /// A full pass costs O(n): every factor checked, and the tree
  /// re-eliminated from the oldest relinearized factor up (with constants
  /// in every factor, old factors' robust weights and poses move with
  /// them). > 1: a pass runs only once the variables added since the last
  /// one reach (growth − 1) times those held then — at most log_growth(n)
  /// passes, O(n) work in all, amortized O(1) per update (the fixed lag,
  /// whose n is its window, every (growth − 1)·window states). 1: whenever
  /// the constants moved.
  double full_pass_growth = 1.0;
  /// Relinearize-and-re-eliminate rounds of a full pass, each until no
  /// factor is stale. 1: one Gauss–Newton step from the pass's point. When
  /// the constants have moved far since the factors were linearized (a
  /// mounting learnt in an outage, the GNSS/INS drive) one step can leave
  /// the newest states far from the causal optimum; a second converges
  /// there (docs/DESIGN.md §12), at the cost of the pass's O(n) work again.
  int full_pass_rounds = 1;
  /// Relinearize-and-re-eliminate rounds on the top per update (start-up).
  int max_local_iterations = 3;
  /// Back-substitution descends into a subtree only while the solution
  /// change exceeds this (iSAM2's wildfire). Default: never (lazy) — the top
  /// (newest state, constants) is always solved, and estimate(k) refreshes
  /// the root path of k on demand. With iSAM2's 1e-3 the radar's median
  /// update grows from 39 µs at step 10³ to 129 µs at 10⁵, because a tiny
  /// change of xdot moves every old smoothed state by more than 1e-3; lazy it
  /// stays at 14–21 µs (bench/history_probe).
  double wildfire_threshold = std::numeric_limits<double>::infinity();
  /// Iterate each update to convergence over ALL factors (Levenberg–Marquardt
  /// on the whole graph, the batch solver's damping policy; O(n) per
  /// iteration, equals the batch solution). It converges only linearly where
  /// the problem is nearly singular (the radar
  /// start-up needs up to ~2000 iterations in its first 15 steps), so the
  /// stopping rule is the change of the estimate, not the linearization error.
  bool iterate_to_convergence = false;
  /// Converged when no estimate changes by more than this, relative
  /// (|Δx_i| ≤ tol·(1 + |x_i|)), between two iterations.
  double convergence_tolerance = 1e-11;
  int max_iterations = 5000;
  /// With iterate_to_convergence: up to this many full Newton steps after
  /// the iteration converged (see BatchSolverOptions::newton_polish_steps),
  /// each followed by a re-elimination at the new point. 0 = off.
  int newton_polish_steps = 0;
  bool validate(std::string* why = nullptr) const;
};

class SmootherCore;

/// What both smoothers share: the current estimates, covariances and report.
class Smoother {
 public:
  virtual ~Smoother();
  Smoother(const Smoother&) = delete;
  Smoother& operator=(const Smoother&) = delete;

  /// Adds factors and the initial values of the variables they introduce.
  /// Strong exception guarantee: on throw the smoother is unchanged.
  virtual UpdateReport update(const std::vector<FactorPtr>& new_factors, const Values& new_values) = 0;

  /// Removes every factor on both states of each pair, then adds `new_factors`
  /// and `new_values` in the same update (strong guarantee): the cliques of
  /// the removed factors' variables and those above them are re-eliminated
  /// without them. A process factor split by a state inserted between two
  /// states is replaced this way (the new variables must not be newer
  /// states: a fixed lag's window is not moved). InvalidArgument when a pair
  /// has no factor.
  UpdateReport replace(const std::vector<std::pair<Key, Key>>& remove_between, const std::vector<FactorPtr>& new_factors,
                       const Values& new_values);

  bool contains(const Key& k) const;
  /// Current estimate of a variable (refreshes its root path first).
  Eigen::VectorXd estimate(const Key& k);
  /// Every variable, after a full back-substitution.
  Values calculateEstimate();
  /// Joint marginal covariance of any variables held, blocks in the given order.
  Eigen::MatrixXd jointMarginalCovariance(const std::vector<Key>& keys) const;
  Eigen::MatrixXd marginalCovariance(const Key& k) const { return jointMarginalCovariance({k}); }
  const UpdateReport& lastReport() const;
  std::size_t numVariables() const;
  std::size_t numFactors() const;

  /// Checkpoint: the engine (every factor with its linearization, the Bayes
  /// tree), the last report and the relinearization state. load() validates
  /// everything against `model` and changes nothing unless all is well.
  virtual void save(internal::ByteWriter& out) const;
  virtual void load(internal::ByteReader& in, const Model& model);

 protected:
  explicit Smoother(std::unique_ptr<SmootherCore> core);
  std::unique_ptr<SmootherCore> core_;
};

class IncrementalSmoother final : public Smoother {
 public:
  explicit IncrementalSmoother(SmootherOptions options = {},
                               EliminationOrdering ordering = EliminationOrdering::ConstrainedColamd);
  UpdateReport update(const std::vector<FactorPtr>& new_factors, const Values& new_values) override;
  const SmootherOptions& options() const;
  EliminationOrdering ordering() const { return ordering_; }

 private:
  EliminationOrdering ordering_;
};

struct FixedLagSmootherOptions {
  int window = 10;  ///< states x_c kept (the newest ones); constants are never marginalized
  SmootherOptions smoother;  ///< eliminated in time order (the oldest state is a leaf)
  bool validate(std::string* why = nullptr) const;
};

class FixedLagSmoother final : public Smoother {
 public:
  explicit FixedLagSmoother(FixedLagSmootherOptions options = {});
  /// As IncrementalSmoother::update, then marginalizes states older than the
  /// window (those with step < newest step − window + 1).
  UpdateReport update(const std::vector<FactorPtr>& new_factors, const Values& new_values) override;
  /// Oldest state still in the window (−1 before any state).
  std::int64_t oldestStep() const { return oldest_; }
  const FixedLagSmootherOptions& options() const { return options_; }
  /// As Smoother's, then the window's oldest and newest steps.
  void save(internal::ByteWriter& out) const override;
  void load(internal::ByteReader& in, const Model& model) override;

 private:
  FixedLagSmootherOptions options_;
  std::int64_t oldest_ = -1, newest_ = -1;
};

}  // namespace gssm
