#include <algorithm>
#include <chrono>
#include <limits>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/solvers/smoothers.h"
#include "solvers/damping.h"
#include "solvers/newton.h"
#include "solvers/option_fields.h"
#include "solvers/smoother_core.h"

namespace gssm {

const char* orderingName(EliminationOrdering ordering) {
  return ordering == EliminationOrdering::TimeOrdered ? "time" : "colamd";
}

std::optional<EliminationOrdering> orderingNamed(const std::string& name) {
  for (auto o : {EliminationOrdering::ConstrainedColamd, EliminationOrdering::TimeOrdered})
    if (name == orderingName(o)) return o;
  return std::nullopt;
}

std::string UpdateReport::toString() const {
  std::ostringstream os;
  os << "update: +" << new_factors << " factors, +" << new_variables << " variables; "
     << cliques_reeliminated << " cliques re-eliminated (" << orphans << " orphans), "
     << factors_relinearized << "/" << factors_checked << " factors relinearized/checked"
     << (relinearization_pass ? " [full pass]" : "") << ", " << iterations << " iterations, "
     << variables_backsubstituted << " back-substituted, " << variables_marginalized
     << " marginalized; now " << num_variables << " variables, " << num_factors << " factors, "
     << num_cliques << " cliques; " << seconds * 1e6 << " us";
  if (!note.empty()) os << "; " << note;
  return os.str();
}

bool SmootherOptions::validate(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = "SmootherOptions: " + m;
    return false;
  };
  if (!(relinearize_threshold > 0)) return fail("relinearize_threshold must be > 0");
  if (!(constants_check_sigmas > 0)) return fail("constants_check_sigmas must be > 0");
  if (!(full_pass_growth >= 1) || !std::isfinite(full_pass_growth)) return fail("full_pass_growth must be >= 1");
  if (full_pass_rounds < 1 || full_pass_rounds > 100)
    return fail("full_pass_rounds must be in [1, 100], got " + std::to_string(full_pass_rounds));
  // Upper bounds: values beyond them only make an update run for minutes
  // (a checkpoint fuzzer found max_local_iterations = 4194307).
  if (max_local_iterations < 0 || max_local_iterations > 100)
    return fail("max_local_iterations must be in [0, 100], got " + std::to_string(max_local_iterations));
  if (!(wildfire_threshold >= 0)) return fail("wildfire_threshold must be >= 0");
  if (!(convergence_tolerance > 0)) return fail("convergence_tolerance must be > 0");
  if (max_iterations < 1 || max_iterations > 100000)
    return fail("max_iterations must be in [1, 100000], got " + std::to_string(max_iterations));
  if (newton_polish_steps < 0 || newton_polish_steps > 100)
    return fail("newton_polish_steps must be in [0, 100], got " + std::to_string(newton_polish_steps));
  return true;
}

bool FixedLagSmootherOptions::validate(std::string* why) const {
  if (window < 1) {
    if (why) *why = "FixedLagSmootherOptions: window must be >= 1 (got " + std::to_string(window) + ")";
    return false;
  }
  return smoother.validate(why);
}

namespace {
internal::OrderingMode toMode(EliminationOrdering o) {
  return o == EliminationOrdering::TimeOrdered ? internal::OrderingMode::TimeOrdered
                                               : internal::OrderingMode::ConstrainedColamd;
}
const SmootherOptions& validated(const SmootherOptions& o) {
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument(why);
  return o;
}
}  // namespace

SmootherCore::SmootherCore(const SmootherOptions& o, internal::OrderingMode mode)
    : engine(mode, validated(o).wildfire_threshold), options(o) {}

const UpdateReport& SmootherCore::finish(UpdateReport rep, Clock::time_point start) {
  rep.num_variables = engine.numVariables();
  rep.num_factors = engine.numFactors();
  rep.num_cliques = engine.numCliques();
  rep.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  last = std::move(rep);
  return last;
}

UpdateReport SmootherCore::update(const std::vector<FactorPtr>& new_factors, const Values& new_values,
                                  const std::vector<int>& remove_slots) {
  const auto start = Clock::now();
  return finish(apply(new_factors, new_values, remove_slots), start);
}

void SmootherCore::relinearize(const std::vector<int>& candidates, double threshold,
                               UpdateReport& rep, internal::EngineCounts& counts) {
  std::vector<int> stale;
  for (int s : candidates)
    if (engine.linearizationError(s) > threshold) stale.push_back(s);
  rep.factors_checked += static_cast<int>(candidates.size());
  if (stale.empty()) return;
  try {
    engine.update(internal::EngineUpdate::relinearizing(std::move(stale)), counts);
    ++rep.iterations;
  } catch (const NumericalError& e) {
    // The engine is unchanged: keep the previous linearization and say so.
    rep.note = "relinearization of " + std::to_string(stale.size()) + " factors skipped: " + e.what();
  }
}

namespace {
// The largest change between two estimates, relative to 1 + |b|.
double relChange(const Values& a, const Values& b) {
  double change = 0;
  for (const auto& kv : a) {
    const Eigen::VectorXd& old = b.at(kv.first);
    change = std::max(change, ((kv.second - old).array().abs() / (1.0 + old.array().abs())).maxCoeff());
  }
  return change;
}
}  // namespace

void SmootherCore::iterateToConvergence(UpdateReport& rep, internal::EngineCounts& counts) {
  counts.variables_backsubstituted += engine.solveAll();
  double tree_lambda = 0;  // the damping in the tree as it stands
  double cost = levenbergMarquardt(rep, counts, tree_lambda);
  if (tree_lambda > 0) cost = reEliminateUndamped(rep, counts, cost);
  newtonPolishTree(rep, counts, cost);
}

// Levenberg–Marquardt over the whole tree, as the batch solver does: every
// iteration relinearizes every nonlinear factor at the current estimate
// (not only those with a large residual error: that error is O(Δ²) while the
// Jacobian, which sets the fixed point, changes O(Δ)) and re-eliminates with
// Marquardt damping; a step that raises the cost is undone from a snapshot.
// Undamped Gauss–Newton cycles on the radar start-up (prior 143σ off), where
// x is determined only to ±5 m along a flat valley. Returns the cost reached;
// tree_lambda is the damping the tree holds then.
double SmootherCore::levenbergMarquardt(UpdateReport& rep, internal::EngineCounts& counts, double& tree_lambda) {
  Values previous = engine.allEstimates();
  double previous_cost = engine.cost();
  internal::LevenbergMarquardtPolicy policy;  // the batch solver's policy and defaults
  for (int it = 0; it < options.max_iterations; ++it) {
    const std::vector<int> all = engine.nonlinearSlots();
    if (all.empty()) break;
    internal::BayesTreeEngine snapshot = engine;
    internal::EngineCounts trial = counts;
    const double lambda = policy.lambda();
    try {
      engine.update(internal::EngineUpdate::relinearizing(all, lambda), trial);
    } catch (const NumericalError& e) {
      engine = std::move(snapshot);
      if (policy.undamped() || !policy.rejected()) {
        rep.note = std::string("iteration stopped: ") + e.what();
        break;
      }
      continue;
    }
    ++rep.iterations;
    rep.factors_checked += static_cast<int>(all.size());
    trial.variables_backsubstituted += engine.solveAll();
    const double cost = engine.cost();
    if (!policy.accept(cost, previous_cost)) {
      engine = std::move(snapshot);  // worse: undo, damp more
      if (policy.undamped() || !policy.rejected()) break;
      continue;
    }
    counts = trial;
    tree_lambda = lambda;
    Values now = engine.allEstimates();
    const double change = relChange(now, previous);
    previous = std::move(now);
    previous_cost = cost;
    policy.accepted();
    if (change <= options.convergence_tolerance && policy.converged()) break;
  }
  return previous_cost;
}

// The tree still holds Marquardt rows from its last kept step (the undamped
// finish was rejected, or the iteration stopped damped), which make every
// covariance read from it too small (~100× on the robust beacon test when
// λ₀ was 1e-4). Re-eliminate it undamped at the estimate reached: the
// estimate becomes that tree's solution, one Gauss–Newton step on
// (negligible where the iteration had converged). Returns the cost.
double SmootherCore::reEliminateUndamped(UpdateReport& rep, internal::EngineCounts& counts, double cost) {
  internal::BayesTreeEngine snapshot = engine;
  internal::EngineCounts trial = counts;
  try {
    engine.update(internal::EngineUpdate::relinearizing(engine.nonlinearSlots(), 0.0), trial);
    trial.variables_backsubstituted += engine.solveAll();
    counts = trial;
    ++rep.iterations;
    return engine.cost();
  } catch (const NumericalError& e) {
    engine = std::move(snapshot);
    rep.note = std::string("covariances keep the last damping (the undamped system did not factor: ") + e.what() + ")";
    return cost;
  }
}

// Newton polish: quadratic convergence where the iteration above crawls.
void SmootherCore::newtonPolishTree(UpdateReport& rep, internal::EngineCounts& counts, double cost) {
  internal::BayesTreeEngine snapshot = engine;
  internal::EngineCounts trial = counts;
  std::string failure;
  const internal::NewtonPolishResult polish = internal::newtonPolish(
      engine.allEstimates(), cost, options.newton_polish_steps,
      [&](internal::NewtonSystem& sys, const Values& x) { engine.addToNewton(sys, x); },
      [&](Values& next) {
        snapshot = engine;
        trial = counts;
        try {
          engine.setEstimates(next);
          engine.update(internal::EngineUpdate::relinearizing(engine.nonlinearSlots(), 0.0), trial);  // the tree there
        } catch (const NumericalError& e) {
          failure = e.what();
          return std::numeric_limits<double>::infinity();
        }
        trial.variables_backsubstituted += engine.solveAll();
        next = engine.allEstimates();  // the re-elimination moved on from the Newton point
        return engine.cost();
      },
      [&](bool keep) {
        if (!keep) {
          engine = std::move(snapshot);
          return;
        }
        counts = trial;
        ++rep.iterations;
      },
      [&](const Values& from, const Values& to, const Eigen::VectorXd&) {
        return relChange(to, from) <= options.convergence_tolerance;
      });
  if (polish.indefinite) rep.note = "Newton polish skipped: the Hessian is not positive definite here";
  else if (!failure.empty()) rep.note = "Newton polish stopped: " + failure;
}

// Relinearizes the factors `gather` puts in the slots buffer, gathered
// anew each round (the last round moved the estimates), until none is
// stale or a relinearization fails, at most `rounds` times.
template <class Gather>
void SmootherCore::relinearizeUntilSettled(int rounds, UpdateReport& rep, internal::EngineCounts& counts,
                                           Gather gather) {
  for (int round = 0; round < rounds; ++round) {
    gather(local_slots_);
    const int before = rep.iterations;
    relinearize(local_slots_, options.relinearize_threshold, rep, counts);
    if (rep.iterations == before) return;  // nothing was stale
  }
}

// Old factors all touch the constants: check them all, in one bounded pass,
// only when the constants moved enough to matter (in buffers: this runs
// after every update).
void SmootherCore::checkAllWhenTheConstantsMoved(UpdateReport& rep, internal::EngineCounts& counts) {
  Eigen::VectorXd& xb = constants_now_;
  engine.estimateInto(Key::constants(), xb);
  if (constants_at_last_check_.size() != xb.size()) {
    constants_at_last_check_ = xb;
    return;
  }
  if (static_cast<double>(added_since_pass_) <
      (options.full_pass_growth - 1) * static_cast<double>(held_at_last_pass_))
    return;
  // Grown enough for a pass (full_pass_growth); only then the constants' marginal.
  Eigen::VectorXd& sd = constants_sd_;
  engine.marginalSd(Key::constants(), sd);
  const double moved = ((xb - constants_at_last_check_).cwiseAbs().array() / sd.array()).maxCoeff();
  if (moved <= options.constants_check_sigmas) return;
  relinearizeUntilSettled(options.full_pass_rounds, rep, counts, [&](std::vector<int>& slots) {
    counts.variables_backsubstituted += engine.solveAll();
    slots = engine.nonlinearSlots();
  });
  rep.relinearization_pass = true;
  engine.estimateInto(Key::constants(), constants_at_last_check_);
  held_at_last_pass_ = static_cast<std::int64_t>(engine.numVariables());
  added_since_pass_ = 0;
}

UpdateReport SmootherCore::apply(const std::vector<FactorPtr>& new_factors, const Values& new_values,
                                 const std::vector<int>& remove_slots) {
  UpdateReport rep;
  rep.new_factors = static_cast<int>(new_factors.size());
  rep.new_variables = static_cast<int>(new_values.size());
  internal::EngineCounts& counts = counts_;
  counts.clear();
  internal::EngineUpdate u = internal::EngineUpdate::adding(new_factors, new_values);
  u.remove = remove_slots;
  engine.update(u, counts);  // may throw: nothing changed
  rep.iterations = 1;
  added_since_pass_ += static_cast<std::int64_t>(new_values.size());

  if (!options.relinearize) {
    // keep every linearization as added
  } else if (options.iterate_to_convergence) {
    iterateToConvergence(rep, counts);
    rep.relinearization_pass = true;
  } else {
    // Start-up nonlinearity: relinearize the factors of the top, which is
    // being re-eliminated anyway.
    relinearizeUntilSettled(options.max_local_iterations, rep, counts, [&](std::vector<int>& local) {
      internal::clearKeepingSmall(local);  // a whole-history top grew it
      for (const auto& k : counts.top)
        if (!k.isConstants()) engine.appendSlotsOf(k, local);
      std::sort(local.begin(), local.end());
      local.erase(std::unique(local.begin(), local.end()), local.end());
    });
    if (engine.hasVariable(Key::constants())) checkAllWhenTheConstantsMoved(rep, counts);
  }
  rep.cliques_reeliminated = counts.cliques_reeliminated;
  rep.orphans = counts.orphans;
  rep.factors_relinearized = counts.factors_relinearized;
  rep.variables_backsubstituted = counts.variables_backsubstituted;
  return rep;
}

// ---- Smoother (shared read API) -------------------------------------------------
Smoother::Smoother(std::unique_ptr<SmootherCore> core) : core_(std::move(core)) {}
Smoother::~Smoother() = default;
bool Smoother::contains(const Key& k) const { return core_->engine.hasVariable(k); }
Eigen::VectorXd Smoother::estimate(const Key& k) {
  if (!contains(k)) throw InvalidArgument("smoother: no variable " + k.toString() + " (never added, or marginalized)");
  core_->engine.solvePath(k);
  return core_->engine.estimate(k);
}
Values Smoother::calculateEstimate() {
  core_->engine.solveAll();
  return core_->engine.allEstimates();
}
Eigen::MatrixXd Smoother::jointMarginalCovariance(const std::vector<Key>& keys) const {
  return core_->engine.pathMarginalCovariance(keys);
}
const UpdateReport& Smoother::lastReport() const { return core_->last; }
std::size_t Smoother::numVariables() const { return core_->engine.numVariables(); }
std::size_t Smoother::numFactors() const { return core_->engine.numFactors(); }

// ---- IncrementalSmoother -------------------------------------------------------
IncrementalSmoother::IncrementalSmoother(SmootherOptions options, EliminationOrdering ordering)
    : Smoother(std::make_unique<SmootherCore>(options, toMode(ordering))), ordering_(ordering) {}
UpdateReport IncrementalSmoother::update(const std::vector<FactorPtr>& f, const Values& v) {
  return core_->update(f, v);
}

UpdateReport Smoother::replace(const std::vector<std::pair<Key, Key>>& remove_between,
                               const std::vector<FactorPtr>& f, const Values& v) {
  std::vector<int> slots;
  for (const auto& [a, b] : remove_between) {
    if (a.isConstants() || b.isConstants())
      throw InvalidArgument("Smoother::replace: name the factors to remove by two states, not x_b");
    const std::vector<int> between = core_->engine.slotsBetween(a, b);
    if (between.empty())
      throw InvalidArgument("Smoother::replace: no factor on both " + a.toString() + " and " + b.toString());
    slots.insert(slots.end(), between.begin(), between.end());
  }
  return core_->update(f, v, slots);
}
const SmootherOptions& IncrementalSmoother::options() const { return core_->options; }

// ---- FixedLagSmoother ----------------------------------------------------------
namespace {
FixedLagSmootherOptions fixedLag(FixedLagSmootherOptions o) {
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument(why);
  return o;
}
}  // namespace

FixedLagSmoother::FixedLagSmoother(FixedLagSmootherOptions options)
    : Smoother(nullptr), options_(fixedLag(std::move(options))) {
  core_ = std::make_unique<SmootherCore>(options_.smoother, internal::OrderingMode::TimeOrdered);
}

UpdateReport FixedLagSmoother::update(const std::vector<FactorPtr>& f, const Values& v) {
  std::int64_t newest = newest_, oldest = oldest_;
  for (const auto& kv : v)
    if (!kv.first.isConstants()) {
      newest = std::max(newest, kv.first.step);
      if (oldest_ < 0) oldest = oldest < 0 ? kv.first.step : std::min(oldest, kv.first.step);
    }
  const auto start = SmootherCore::Clock::now();  // the update and its marginalization, timed once
  UpdateReport rep = core_->apply(f, v);
  newest_ = newest;
  oldest_ = oldest;
  while (oldest_ >= 0 && oldest_ < newest_ - options_.window + 1) {
    // States inserted for late measurements next to it are eliminated before
    // it (their keys sort first): marginalized first, leaves first.
    for (const Key& k : core_->engine.below(Key::state(oldest_))) {
      if (k.isConstants() || k.step >= 0)
        throw NumericalError("FixedLagSmoother: " + k.toString() + " lies below " + Key::state(oldest_).toString() +
                             " in the Bayes tree (internal ordering error)");
      core_->engine.marginalizeLeaf(k);
      ++rep.variables_marginalized;
    }
    core_->engine.marginalizeLeaf(Key::state(oldest_));
    ++oldest_;
    ++rep.variables_marginalized;
  }
  return core_->finish(std::move(rep), start);
}

// ---- checkpoints ----------------------------------------------------------------
void SmootherCore::save(internal::ByteWriter& out) const {
  engine.save(out);
  internal::FieldWriter w{out};
  UpdateReport copy = last;
  internal::fields(w, copy);
  out.vec(constants_at_last_check_);
  out.i64(held_at_last_pass_);  // format 4
  out.i64(added_since_pass_);
}

void SmootherCore::load(internal::ByteReader& in, const Model& model) {
  internal::BayesTreeEngine e = engine;
  e.load(in, model);
  UpdateReport r;
  internal::FieldReader reader{in};
  internal::fields(reader, r);
  Eigen::VectorXd c = in.vec("constants at the last relinearization check");
  if (c.size() != 0 && c.size() != model.dims().nb) in.fail("constants at the last check have the wrong size");
  std::int64_t held = 0, added = 0;
  if (in.version() >= 4) {
    held = in.i64("variables held at the last full pass");
    added = in.i64("variables added since the last full pass");
    if (held < 0 || added < 0) in.fail("negative variable counts of the full-pass schedule");
  }
  engine = std::move(e);
  last = std::move(r);
  constants_at_last_check_ = std::move(c);
  held_at_last_pass_ = held, added_since_pass_ = added;
}

void Smoother::save(internal::ByteWriter& out) const { core_->save(out); }
void Smoother::load(internal::ByteReader& in, const Model& model) { core_->load(in, model); }

void FixedLagSmoother::save(internal::ByteWriter& out) const {
  Smoother::save(out);
  out.i64(oldest_);
  out.i64(newest_);
}

void FixedLagSmoother::load(internal::ByteReader& in, const Model& model) {
  // Read and check everything before changing anything.
  auto core = std::make_unique<SmootherCore>(*core_);
  core->load(in, model);
  const std::int64_t oldest = in.i64("fixed-lag oldest step"), newest = in.i64("fixed-lag newest step");
  const auto has = [&](std::int64_t k) { return core->engine.hasVariable(Key::state(k)); };
  if (oldest < -1 || newest < oldest || newest > (std::int64_t(1) << 53) || newest - oldest >= options_.window ||
      (oldest >= 0 && (!has(oldest) || !has(newest))))
    in.fail("fixed-lag window [" + std::to_string(oldest) + ", " + std::to_string(newest) +
            "] does not match its variables or window " + std::to_string(options_.window));
  core_ = std::move(core);
  oldest_ = oldest;
  newest_ = newest;
}

}  // namespace gssm
