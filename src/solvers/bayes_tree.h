#pragma once
// Internal: the incremental elimination engine behind IncrementalSmoother and
// FixedLagSmoother (iSAM2 class). A Bayes tree of single-frontal cliques, each
// holding a dense Gaussian conditional R δ_f + S δ_sep = d, obtained by QR
// elimination of the whitened linearized factors in δ coordinates
// (x = anchor + δ). Updates re-eliminate only the top of the tree that new or
// relinearized factors touch, and are transactional: on any exception the
// engine is left exactly as before.
//
// Each nonlinear factor keeps its own linearization (per-factor, not
// per-variable, relinearization: docs/DESIGN.md §6). Anchors never move, so
// relinearizing one factor changes only that factor's rows. What slots and
// cliques hold besides ids — keys and matrices — is one record each in the
// engine's RecordStore.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "gssm/factors/factors.h"
#include "solvers/slot_factor.h"
#include "solvers/record_store.h"
#include "solvers/small_list.h"
#include "solvers/var_table.h"

namespace gssm {
class Model;
}

namespace gssm::internal {

/// A linear factor's keys while it is built: a model factor has at most
/// three (x_c(k), x_c(k+1), x_b), held inline.
using KeyList = SmallList<Key, 3>;

class ByteWriter;
class ByteReader;
class NewtonSystem;

/// Keys read in place: a stored slot's or a clique's separator.
class KeySpan {
 public:
  KeySpan() = default;
  KeySpan(const Key* first, std::size_t n) : first_(first), n_(n) {}
  const Key* begin() const { return first_; }
  const Key* end() const { return first_ + n_; }
  std::size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  const Key& operator[](std::size_t i) const { return first_[i]; }
  const Key& front() const { return first_[0]; }
  std::vector<Key> toVector() const { return std::vector<Key>(begin(), end()); }

 private:
  const Key* first_ = nullptr;
  std::size_t n_ = 0;
};

/// Words of an upper-trapezoidal rows × cols matrix held by columns, column
/// j with its first min(j + 1, rows) entries (a clique's marginal [R_S | d_S]).
inline std::size_t packedWords(Eigen::Index rows, Eigen::Index cols) {
  const auto m = static_cast<std::size_t>(rows), n = static_cast<std::size_t>(cols);
  return n <= m ? n * (n + 1) / 2 : m * (m + 1) / 2 + (n - m) * m;
}

/// A whitened linear factor r(δ) = Σ_i A_i δ_{keys[i]} − b read where it is
/// held, [A_1 … A_n | b] by columns, block i as wide as keys[i]'s variable;
/// `packed`: upper trapezoidal, each column without its zeros below the
/// diagonal (packedWords).
struct LinearView {
  KeySpan keys_;
  const double* ab = nullptr;
  Eigen::Index rows_ = 0, cols_ = 0;
  bool packed = false;

  const KeySpan& keys() const { return keys_; }
  Eigen::Index rows() const { return rows_; }
  Eigen::Index cols() const { return cols_; }
  /// Column j's held entries, rows 0 … colLength(j) − 1 (the rest are zero).
  const double* col(Eigen::Index j) const { return ab + (packed ? packedWords(rows_, j) : static_cast<std::size_t>(j * rows_)); }
  Eigen::Index colLength(Eigen::Index j) const { return packed ? std::min(j + 1, rows_) : rows_; }
  /// [A | b] as a dense matrix.
  Eigen::MatrixXd dense() const {
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(rows_, cols_);
    for (Eigen::Index j = 0; j < cols_; ++j)
      m.col(j).head(colLength(j)) = Eigen::Map<const Eigen::VectorXd>(col(j), colLength(j));
    return m;
  }
  /// [A | b] in place (not packed).
  Eigen::Map<const Eigen::MatrixXd> Ab() const { return {ab, rows_, cols_}; }
  auto b() const { return Ab().col(cols_ - 1); }
  /// r = Σ_i A_i δ_i − b, with δ_i = delta(keys[i]) (whose sizes are the
  /// blocks' widths); `term` is scratch. Not packed.
  template <class Delta>
  void residual(Delta&& delta, Eigen::VectorXd& r, Eigen::VectorXd& term) const {
    r = -b();
    Eigen::Index c = 0;
    for (const auto& k : keys()) {
      const auto& d = delta(k);  // a vector or a map of one
      term.noalias() = Ab().middleCols(c, d.size()) * d;  // the product, then the sum
      r += term;
      c += d.size();
    }
  }
  /// The blocks A_i as separate matrices, block i dim(keys[i]) wide.
  template <class Dim>
  std::vector<Eigen::MatrixXd> blocks(Dim&& dim) const {
    const Eigen::MatrixXd m = dense();
    std::vector<Eigen::MatrixXd> out;
    Eigen::Index c = 0;
    for (const auto& k : keys()) {
      const Eigen::Index w = dim(k);
      out.emplace_back(m.middleCols(c, w));
      c += w;
    }
    return out;
  }
};

/// A linear factor being built (a linearization, an elimination's
/// marginal) or added: its own keys and matrix [A_1 … A_n | b]. The engine
/// holds what it keeps in its RecordStore instead.
struct LinearFactor {
  const KeyList& keys() const { return keys_; }
  /// Sets its keys, in the storage it has (a pooled factor's: no allocation).
  template <class Keys>
  void setKeys(const Keys& keys) {
    keys_.assign(keys.begin(), keys.end());
  }
  Eigen::MatrixXd Ab;
  Eigen::Index rows() const { return Ab.rows(); }
  auto b() const { return Ab.col(Ab.cols() - 1); }
  LinearView view() const { return {KeySpan(keys_.begin(), keys_.size()), Ab.data(), Ab.rows(), Ab.cols(), false}; }
  /// Lays the blocks A_i side by side in Ab with room for b after them
  /// (b's column is the caller's to fill); the inverse of blocks().
  void setBlocks(const std::vector<Eigen::MatrixXd>& A, Eigen::Index rows) {
    Eigen::Index width = 0;
    for (const auto& a : A) width += a.cols();
    Ab.resize(rows, width + 1);
    Eigen::Index col = 0;
    for (const auto& a : A) {
      Ab.middleCols(col, a.cols()) = a;
      col += a.cols();
    }
  }

 private:
  KeyList keys_;
};

/// A clique as an elimination makes it: the conditional [R S d] in one
/// matrix (R upper triangular d_f × d_f, S d_f × Σ d_sep, d d_f) and the
/// marginal its subtree passes to its parent, on the separator (its keys).
/// Kept in the engine's pool between updates for their storage.
struct EliminatedClique {
  Key frontal;
  Eigen::MatrixXd conditional;
  LinearFactor marginal;
  SmallList<int, 2> owned;  // factor slots consumed by this clique's elimination
};

/// A clique as the engine holds it: the frontal variable, the tree links, and
/// one record [separator keys | conditional [R S d] | marginal packed].
struct Clique {
  Key frontal;
  RecordStore::Ref record = 0;
  std::uint16_t nsep = 0, dv = 0, width = 0, mrows = 0;  // [R S d] is dv × (dv + width + 1); marginal mrows × (width + 1)
  int parent = -1;
  /// δ of the frontal is its back-substitution from the current tree (and so
  /// is every ancestor's): solvePath() need not redo it.
  bool solved = false;
  SmallList<int, 2> owned;     // factor slots consumed by this clique's elimination
  SmallList<int, 2> children;  // a chain's clique owns two factors and has one child: inline
  std::size_t conditionalOffset() const { return nsep; }
  std::size_t marginalOffset() const { return nsep + std::size_t{dv} * (dv + width + 1u); }
  std::size_t words() const { return marginalOffset() + packedWords(mrows, width + 1); }
};

// Where an input of the elimination comes from, so that commit() can give
// each consumed factor its slot.
struct InputSource {
  enum class Kind { Slot, NewFactor, NewLinear, Orphan };
  Kind kind;
  int index;  // slot, or index into the new factors / new linear factors; unused for Orphan
};

// A member that belongs to one engine object — buffers and pools, not
// state: a copy of the engine (a snapshot) gets a fresh, empty one.
template <class T>
struct NotCopied : T {
  NotCopied() = default;
  NotCopied(const NotCopied&) : T() {}
  NotCopied& operator=(const NotCopied&) { return *this; }
  NotCopied(NotCopied&&) noexcept = default;
  NotCopied& operator=(NotCopied&&) noexcept = default;
};

/// Per-update buffers keep their storage for the next update up to this
/// many entries; beyond (a relinearization of the whole history grew them)
/// they give their memory back.
constexpr std::size_t kKeepEntries = 256;
template <class V>
void clearKeepingSmall(V& v) {
  if (v.capacity() > kKeepEntries) V().swap(v);
  else v.clear();
}

// The lists one engine update fills (bayes_tree.cpp's UpdatePlan), kept by
// the engine so their capacity carries over.
struct UpdateLists {
  std::vector<SlotFactor> held_new;                 // the new factors as their slots will hold them
  std::vector<LinearFactor> linearized_new;         // of the new factors, same order
  std::vector<int> removed_order;                   // cliques of the top, leaf to root
  std::vector<int> orphans;                         // subtrees hanging below the top
  std::vector<Key> keys;                            // variables to eliminate
  std::vector<std::pair<LinearView, InputSource>> inputs;
  std::vector<EliminatedClique> fresh;              // one per ordering entry
  // The factor inputs each fresh clique consumed, as (clique, source) in
  // clique order (one list per update, not one per clique).
  std::vector<std::pair<std::size_t, InputSource>> fresh_owned;
  std::vector<int> fresh_id;
  std::vector<Key> ordering;                        // elimination order of the keys
  std::vector<int> new_slot_of, new_lin_slot_of;    // the slot each new factor got
  /// Empties every list (clearKeepingSmall).
  void clear() {
    clearKeepingSmall(held_new);
    clearKeepingSmall(linearized_new);
    clearKeepingSmall(removed_order);
    clearKeepingSmall(orphans);
    clearKeepingSmall(keys);
    clearKeepingSmall(inputs);
    clearKeepingSmall(fresh);
    clearKeepingSmall(fresh_owned);
    clearKeepingSmall(fresh_id);
    clearKeepingSmall(ordering);
    clearKeepingSmall(new_slot_of);
    clearKeepingSmall(new_lin_slot_of);
  }
};

enum class OrderingMode {
  TimeOrdered,        ///< states by step, constants last (oldest state always a leaf)
  ConstrainedColamd,  ///< CCOLAMD with constants last and the newest variables next to them
};

struct EngineCounts {
  std::vector<Key> top;  // variables re-eliminated by the last engine update
  int cliques_reeliminated = 0;
  int orphans = 0;
  int factors_relinearized = 0;
  int variables_backsubstituted = 0;
  /// Zeroes the counts, keeping top's storage unless a whole-history
  /// update grew it (a smoother reuses one per update).
  void clear() {
    clearKeepingSmall(top);
    cliques_reeliminated = orphans = factors_relinearized = variables_backsubstituted = 0;
  }
};

/// What one engine update adds and relinearizes; every part may be empty.
struct EngineUpdate {
  const Values* new_variables = nullptr;                 ///< initial values become their anchors
  const std::vector<FactorPtr>* new_factors = nullptr;   ///< nonlinear factors
  const std::vector<LinearFactor>* new_linear = nullptr; ///< fixed linear factors
  std::vector<int> relinearize;  ///< factor slots to relinearize at the current estimate
  /// Factor slots to remove: their variables' cliques and those above are
  /// re-eliminated without them (a factor replaced, e.g. a process factor
  /// split by a state inserted into the chain).
  std::vector<int> remove;
  /// λ > 0 adds Levenberg–Marquardt rows √λ·diag(‖A_v‖)(δ_v − δ̂_v) to every
  /// variable eliminated (the iterate-to-convergence mode).
  double damping = 0.0;

  static EngineUpdate adding(const std::vector<FactorPtr>& factors, const Values& variables) {
    EngineUpdate u;
    u.new_factors = &factors;
    u.new_variables = &variables;
    return u;
  }
  static EngineUpdate relinearizing(std::vector<int> slots, double damping = 0.0) {
    EngineUpdate u;
    u.relinearize = std::move(slots);
    u.damping = damping;
    return u;
  }
};

class BayesTreeEngine {
 public:
  explicit BayesTreeEngine(OrderingMode mode, double wildfire_threshold)
      : mode_(mode), wildfire_(wildfire_threshold) {}

  /// Re-eliminates the top of the tree that the update's factors touch and
  /// back-substitutes it, in phases: linearize the inputs, detach the top,
  /// eliminate it into new cliques (nothing modified until here), commit,
  /// back-substitute. Strong exception guarantee.
  void update(const EngineUpdate& u, EngineCounts& counts);


  /// Removes a variable whose clique is a leaf; its subtree's marginal on the
  /// separator becomes a fixed linear factor (exact marginalization).
  void marginalizeLeaf(const Key& key);

  bool hasVariable(const Key& k) const { return vars_.contains(k); }
  std::size_t numVariables() const { return vars_.size(); }
  std::size_t numFactors() const { return slots_alive_; }
  std::size_t numCliques() const { return cliques_alive_; }

  /// Current estimate anchor + δ (δ as of the last back-substitution that
  /// reached this variable; see solveAll()).
  Eigen::VectorXd estimate(const Key& k) const;
  /// estimate(k) into `out` (its storage reused).
  void estimateInto(const Key& k, Eigen::VectorXd& out) const;
  /// Sets δ so that the estimate of every variable in `x` is x (used by
  /// line searches; the next elimination must relinearize there).
  void setEstimates(const Values& x);
  /// anchor + δ of every variable.
  Values allEstimates() const;
  /// Back-substitutes the whole tree (δ of every variable up to date).
  int solveAll();
  /// Back-substitutes the path from the root to `k` only.
  void solvePath(const Key& k);

  /// Joint marginal covariance of keys that all lie on one root path (e.g. a
  /// state and the constants), from the conditionals on that path.
  Eigen::MatrixXd pathMarginalCovariance(const std::vector<Key>& keys) const;
  /// The marginal standard deviations of one variable, into `out`: the
  /// square roots of pathMarginalCovariance({k})'s diagonal, the same
  /// numbers (without its matrices when k's clique is the root).
  void marginalSd(const Key& k, Eigen::VectorXd& out) const;

  /// Whitened nonlinearity error ‖r(x̂) − r_lin(δ̂)‖ of a nonlinear slot at
  /// the current estimate; 0 for linear slots.
  double linearizationError(int slot) const;
  /// Slots of nonlinear factors (alive).
  std::vector<int> nonlinearSlots() const;
  /// Appends the alive nonlinear slots whose keys include the state k to
  /// `out` (every factor touches the constants: that is nonlinearSlots()).
  void appendSlotsOf(const Key& k, std::vector<int>& out) const;
  /// The frontal variables of the cliques below k's, leaves first (what must
  /// be marginalized before k is a leaf).
  std::vector<Key> below(const Key& k) const;
  /// The live factor slots on both a and b (none when either is absent).
  std::vector<int> slotsBetween(const Key& a, const Key& b) const;
  /// ½‖r‖² of every alive factor at the current estimate (nonlinear factors
  /// exactly, linear ones by their linear model).
  double cost() const;
  /// Adds every alive factor to a full Newton system at the current
  /// estimate `x` (= allEstimates()): nonlinear factors with their
  /// second-order terms, linear ones as they are.
  void addToNewton(NewtonSystem& sys, const Values& x) const;

  /// Checkpoint: the whole engine (variables, factor slots with their
  /// linearizations, cliques, free lists, counters), so a restored engine
  /// continues with the same bits. load() validates every index and
  /// dimension (throws CheckpointError) and replaces *this only on success.
  void save(ByteWriter& out) const;
  void load(ByteReader& in, const Model& model);
  /// Empty when the tree is consistent (indices in range, dimensions agree,
  /// parent/child links and ownership match, no cycles); else the first problem.
  std::string invariantViolation() const;

 private:
  using Var = EngineVar;
  /// A factor: the nonlinear one (none: a fixed linear factor) and its
  /// linearization, held as the record [keys | Ab] (rows × cols).
  struct Slot {
    SlotFactor nonlinear;
    RecordStore::Ref record = 0;
    std::uint16_t nkeys = 0, rows = 0, cols = 0;
    bool alive = false;
    int owner = -1;
    std::size_t words() const { return nkeys + std::size_t{rows} * cols; }
  };
  LinearView slotView(const Slot& s) const {
    return {KeySpan(records_.keys(s.record), s.nkeys), records_.doubles(s.record, s.nkeys), s.rows, s.cols, false};
  }
  KeySpan slotKeys(const Slot& s) const { return KeySpan(records_.keys(s.record), s.nkeys); }
  KeySpan separator(const Clique& c) const { return KeySpan(records_.keys(c.record), c.nsep); }
  /// [R S d], dv × (dv + width + 1).
  Eigen::Map<const Eigen::MatrixXd> conditional(const Clique& c) const {
    return {records_.doubles(c.record, c.conditionalOffset()), c.dv, c.dv + c.width + 1};
  }
  LinearView marginalView(const Clique& c) const {
    return {separator(c), records_.doubles(c.record, c.marginalOffset()), c.mrows, c.width + 1, true};
  }
  /// Holds `f` as slot s's keys and linearization (in its record if it has
  /// one of that size).
  void storeLinearization(Slot& s, const LinearView& f);
  /// Gives slot s's record back (the slot keeps no linearization).
  void releaseRecord(Slot& s);
  /// Makes `into` (a free clique: no record, no links) the stored form of a
  /// clique an elimination made; its parent and children are the caller's.
  void storeClique(const EliminatedClique& e, Clique& into);
  void releaseRecord(Clique& c);

  // invariantViolation()'s parts (bayes_tree_io.cpp).
  bool isLiveClique(int c) const;
  bool isLiveSlot(int s) const;
  Eigen::Index varDim(const Key& k) const;
  std::string linearViolation(const LinearView& f, const std::string& what) const;
  std::string variableViolation() const;
  std::string slotViolation() const;
  std::string cliqueViolation() const;
  std::string structureViolation() const;
  // load()'s steps (bayes_tree_io.cpp), each on a fresh engine.
  void loadVariables(ByteReader& in, const Model& model);
  void loadSlots(ByteReader& in, const Model& model);
  void loadCliques(ByteReader& in, const Model& model);
  static EliminatedClique readClique(ByteReader& in, const Model& model, const std::string& name);
  void loadSlotIndex(ByteReader& in);

  struct UpdatePlan;  // the work of one update before it is committed (bayes_tree.cpp)
  void linearizeInputs(UpdatePlan& plan) const;
  void detachTop(UpdatePlan& plan) const;
  void eliminateTop(UpdatePlan& plan) const;
  // eliminateTop's steps (bayes_tree.cpp).
  struct EliminationQueue;
  EliminationQueue queueInputs(UpdatePlan& plan) const;
  void reusePooledClique(EliminatedClique& cl, Eigen::Index dv, Eigen::Index sep_cols) const;
  void eliminateVariable(UpdatePlan& plan, EliminationQueue& q, std::size_t vi) const;
  const std::vector<Key>& separatorOf(const EliminationQueue& q, std::size_t vi) const;
  template <class ColumnTable>
  Eigen::Index stackFactors(UpdatePlan& plan, const EliminationQueue& q, std::size_t vi, const ColumnTable& colOf,
                            Eigen::Index ncols, Eigen::MatrixXd& M) const;
  [[noreturn]] static void throwRankDeficient(const Key& v, Eigen::Index component, const std::vector<Key>& sep);
  void commit(UpdatePlan& plan, EngineCounts& counts);
  // pathMarginalCovariance's two cases (bayes_tree.cpp).
  const Eigen::MatrixXd& rootInverse(const Clique& root) const;
  Eigen::MatrixXd rootCovariance(const Clique& root) const;
  Eigen::MatrixXd bayesNetCovariance(const std::vector<Key>& keys) const;
  // Paths up to this many columns are solved densely (UWB: 6 + 25).
  static constexpr Eigen::Index kDensePathColumns = 64;
  // Calls emit(i, j, v) for every entry of the path's conditionals [R S]
  // as one upper-triangular n × n matrix (each clique's rows at its frontal
  // variable's offset).
  template <class Offsets, class Emit>
  void forEachPathEntry(const std::vector<int>& path, const Offsets& off, Emit&& emit) const;
  void commitFactors(UpdatePlan& plan, EngineCounts& counts);
  /// Frees a slot: off its variables' lists, its record released.
  void killSlot(int s);
  void commitCliques(UpdatePlan& plan);
  void reattachOrphans(const UpdatePlan& plan);
  void backSubstituteTop(const UpdatePlan& plan, EngineCounts& counts);

  /// f on `keys` linearized at the current estimate (`extra`: values of
  /// variables being added).
  template <class Keys>
  LinearFactor linearize(const SlotFactor& f, const Model* model, const Keys& keys, const Values& extra) const;
  /// Points scratch_.x at the estimate of each of `keys` (anchor + δ, or
  /// extra's value of a variable being added); scratch_.factor_vars[i] is
  /// keys[i]'s variable, null if new.
  template <class Keys>
  void pointAt(const Keys& keys, const Values* extra) const;
  /// Where k's variable holds rotations (the model's blocks; none without a model).
  Factor::Rotations rotationsOf(const Key& k) const;
  /// anchor ⊕ δ of k's variable v into `out`.
  void estimateInto(const Key& k, const Var& v, Eigen::VectorXd& out) const;
  /// The elimination order of `keys` into `out`.
  void order(const std::vector<Key>& keys, const std::vector<std::pair<LinearView, InputSource>>& factors,
             const Values& new_vars, std::vector<Key>& out) const;
  void backSubstitute(int c);
  void forgetSolved();  // after any change of the tree or of a δ
  int allocClique();
  int allocSlot();
  /// Lists slot s under each of its states (Var::slots).
  void indexSlot(int s);

  OrderingMode mode_;
  double wildfire_;
  VarTable vars_;  // each state lists the factor slots on it
  // The model whose process and measurement factors the slots hold as their
  // numbers (SlotFactor): the first one added (another's kept as objects).
  const Model* model_ = nullptr;
  RecordStore records_;  // the slots' and cliques' keys and matrices
  std::vector<Clique> cliques_;
  std::vector<bool> clique_alive_;
  std::vector<int> free_cliques_;
  std::vector<int> solved_cliques_;  // those with `solved` set, to clear when the tree or a δ changes
  std::vector<Slot> slots_;
  std::vector<int> free_slots_;
  std::size_t slots_alive_ = 0, cliques_alive_ = 0;
  std::int64_t next_rank_ = 0;
  int root_ = -1;
  // Buffers reused by the per-update hot paths (linearize and
  // linearizationError for every new or candidate factor, backSubstitute
  // for every touched clique, eliminateTop, solvePath), so
  // they allocate once, not per call. Not state: never saved or compared.
  struct Scratch {
    std::vector<Eigen::VectorXd> points;        // a factor's states' estimates, by position
    Eigen::VectorXd constants_point;            // its constants' estimate
    std::vector<const Eigen::VectorXd*> x;      // their addresses (or a new variable's initial value)
    std::vector<const Var*> factor_vars;        // a factor's variables, null if new
    Eigen::VectorXd r, rlin, term;
    std::vector<double> product;  // backSubstitute's S·δ_sep, as long as the widest frontal
    // A factor's Jacobian blocks, copied into its Ab: one set per number of
    // keys (a process factor's 3 blocks, a measurement's 2), each keeping
    // its shapes (one set resized 3 → 2 → 3 reallocated a block per factor).
    std::array<std::vector<Eigen::MatrixXd>, 4> J;
    Eigen::MatrixXd stacked;  // a clique's [A | b] while it is triangularized
    std::vector<Eigen::Index> last_row;  // triangularize's: the last row each column's reflection reaches
    std::vector<Key> separator;
    std::vector<std::vector<std::size_t>> pending_of;  // eliminateTop's queue, per ordering entry
    std::vector<LinearView> pend;                      // eliminateTop's inputs, then the marginals it makes
    std::vector<std::optional<InputSource>> pend_source;  // where each came from (nullopt: made there)
    std::vector<double> before;                        // backSubstituteTop: an orphan's δ before
    std::vector<int> path;                             // solvePath's cliques, leaf to root; backSubstituteTop's stack
    std::vector<char> in_top;                          // detachTop's marks, by clique id (all 0 between calls)
  };
  mutable NotCopied<Scratch> scratch_;
  // Cliques an update made (once stored) and linearizations it made or
  // dropped, kept so the next elimination and linearization refill their
  // matrices and lists in place instead of allocating new ones (a fixed-lag
  // update makes the same few cliques and factors every step).
  struct CliquePool {
    static constexpr std::size_t kMax = 64;
    std::vector<EliminatedClique> spare;
    std::vector<LinearFactor> spare_linear;  // linearizations of dropped factors, refilled by linearize()
    /// Keeps what an update discards, up to kMax of each.
    void keep(EliminatedClique&& c) {
      if (spare.size() < kMax) spare.push_back(std::move(c));
    }
    void keep(LinearFactor&& f) {
      if (spare_linear.size() < kMax) spare_linear.push_back(std::move(f));
    }
  };
  mutable NotCopied<CliquePool> pool_;
  NotCopied<UpdateLists> lists_;
};

}  // namespace gssm::internal
