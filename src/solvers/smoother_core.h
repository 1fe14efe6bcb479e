#pragma once
// Internal: the relinearization policy and reporting shared by
// IncrementalSmoother and FixedLagSmoother, over the Bayes tree engine.
#include <chrono>

#include "gssm/solvers/smoothers.h"
#include "solvers/bayes_tree.h"

namespace gssm {

class SmootherCore {
 public:
  SmootherCore(const SmootherOptions& options, internal::OrderingMode mode);

  using Clock = std::chrono::steady_clock;
  /// One update: apply(), then finish() (timed from the call).
  UpdateReport update(const std::vector<FactorPtr>& new_factors, const Values& new_values,
                      const std::vector<int>& remove_slots = {});
  /// The update's work: add, then relinearize the top (start-up), then a
  /// full check when the constants moved, or iterate to convergence. Strong
  /// guarantee for the add; a failed relinearization is skipped and noted in
  /// the report. The caller may do more (the fixed lag marginalizes), then
  /// finish().
  UpdateReport apply(const std::vector<FactorPtr>& new_factors, const Values& new_values,
                     const std::vector<int>& remove_slots = {});
  /// The report's sizes and its time since `start`, kept as `last`.
  const UpdateReport& finish(UpdateReport rep, Clock::time_point start);
  /// Checkpoint: the engine, the last report and the relinearization state.
  void save(internal::ByteWriter& out) const;
  void load(internal::ByteReader& in, const Model& model);

  internal::BayesTreeEngine engine;
  SmootherOptions options;
  UpdateReport last;

 private:
  void relinearize(const std::vector<int>& candidates, double threshold, UpdateReport& rep,
                   internal::EngineCounts& counts);
  template <class Gather>
  void relinearizeUntilSettled(int rounds, UpdateReport& rep, internal::EngineCounts& counts, Gather gather);
  void iterateToConvergence(UpdateReport& rep, internal::EngineCounts& counts);
  double levenbergMarquardt(UpdateReport& rep, internal::EngineCounts& counts, double& tree_lambda);
  double reEliminateUndamped(UpdateReport& rep, internal::EngineCounts& counts, double cost);
  void newtonPolishTree(UpdateReport& rep, internal::EngineCounts& counts, double cost);
  void checkAllWhenTheConstantsMoved(UpdateReport& rep, internal::EngineCounts& counts);
  Eigen::VectorXd constants_at_last_check_;
  // Variables held at the last full pass and added since (full_pass_growth).
  std::int64_t held_at_last_pass_ = 0, added_since_pass_ = 0;
  // Per-update buffers kept for their capacity (not state: not saved).
  internal::EngineCounts counts_;
  std::vector<int> local_slots_;
  Eigen::VectorXd constants_now_, constants_sd_;
};

}  // namespace gssm
