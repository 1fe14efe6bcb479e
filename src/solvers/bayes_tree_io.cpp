// Checkpoint of the Bayes tree engine: everything it holds, dead slots and
// cliques as empty placeholders (their indices stay free), so allocation
// after a restore picks the same indices as the uninterrupted run.
#include <algorithm>
#include <limits>
#include <unordered_set>

#include "core/byte_stream.h"
#include "factors/factor_io.h"
#include "solvers/bayes_tree.h"

namespace gssm::internal {

// A linear factor as its keys, its blocks A_i one by one and b (the format
// from before the blocks were held side by side: old checkpoints still load).
namespace {
template <class Dim>
void writeLinear(ByteWriter& out, const LinearView& f, Dim&& dim) {
  out.keys(f.keys().toVector());
  const std::vector<Eigen::MatrixXd> blocks = f.blocks(dim);
  out.u64(blocks.size());
  for (const auto& a : blocks) out.mat(a);
  out.vec(f.cols() > 0 ? Eigen::VectorXd(f.dense().col(f.cols() - 1)) : Eigen::VectorXd());
}
LinearFactor readLinear(ByteReader& in, const Model& model, const std::string& what) {
  LinearFactor f;
  f.setKeys(in.keys(what + " keys"));
  const KeyList& keys = f.keys();
  const std::size_t n = in.count(what + " blocks", 16);
  if (n != keys.size())
    in.fail(what + ": " + std::to_string(n) + " blocks for " + std::to_string(keys.size()) + " keys");
  std::vector<Eigen::MatrixXd> blocks(n);
  for (std::size_t i = 0; i < n; ++i) blocks[i] = in.mat(what + " block " + std::to_string(i));
  const Eigen::VectorXd b = in.vec(what + " b");
  for (std::size_t i = 0; i < n; ++i)
    if (blocks[i].rows() != b.size() || blocks[i].cols() != variableDim(model, keys[i]))
      in.fail(what + ": block for " + keys[i].toString() + " is " + std::to_string(blocks[i].rows()) + " x " +
              std::to_string(blocks[i].cols()) + ", expected " + std::to_string(b.size()) + " x " +
              std::to_string(variableDim(model, keys[i])));
  f.setBlocks(blocks, b.size());
  f.Ab.col(f.Ab.cols() - 1) = b;
  constexpr Eigen::Index kMax = std::numeric_limits<std::uint16_t>::max();  // an engine record's sizes
  if (static_cast<Eigen::Index>(keys.size()) > kMax || f.Ab.rows() > kMax || f.Ab.cols() > kMax)
    in.fail(what + ": more than " + std::to_string(kMax) + " keys, rows or columns");
  return f;
}
}  // namespace

void BayesTreeEngine::save(ByteWriter& out) const {
  out.u8(static_cast<std::uint8_t>(mode_));
  out.f64(wildfire_);
  out.u64(vars_.size());
  // In key order, so the same state always gives the same bytes.
  std::vector<Key> keys;
  vars_.forEach([&](const Key& k, const Var&) { keys.push_back(k); });
  std::sort(keys.begin(), keys.end());
  for (const auto& k : keys) {
    const Var& v = vars_.at(k);
    out.key(k);
    out.vec(v.anchor());
    out.vec(v.delta());
    out.i32(v.clique);
    out.i64(v.rank);
  }
  auto dimOf = [&](const Key& k) { return vars_.at(k).dim(); };
  out.u64(slots_.size());
  for (const auto& s : slots_) {
    out.boolean(s.alive);
    if (!s.alive) continue;
    out.boolean(static_cast<bool>(s.nonlinear));
    if (s.nonlinear) writeFactor(out, *s.nonlinear.toFactor(model_, slotKeys(s)));
    writeLinear(out, slotView(s), dimOf);
    out.i32(s.owner);
  }
  out.ints(free_slots_);
  out.u64(cliques_.size());
  for (std::size_t c = 0; c < cliques_.size(); ++c) {
    out.boolean(clique_alive_[c]);
    if (!clique_alive_[c]) continue;
    const Clique& cl = cliques_[c];
    out.key(cl.frontal);
    out.keys(separator(cl).toVector());
    const auto C = conditional(cl);
    out.mat(C.leftCols(cl.dv));
    out.mat(C.middleCols(cl.dv, cl.width));
    out.vec(C.col(C.cols() - 1));
    writeLinear(out, marginalView(cl), dimOf);
    out.ints(cl.owned.toVector());
    out.i32(cl.parent);
    out.ints(cl.children.toVector());
  }
  out.ints(free_cliques_);
  // The slot index: the states with factors on them, in key order.
  std::vector<Key> indexed;
  for (const auto& k : keys)
    if (!k.isConstants() && !vars_.at(k).slots.empty()) indexed.push_back(k);
  out.u64(indexed.size());
  for (const auto& k : indexed) {
    out.key(k);
    out.ints(vars_.at(k).slots.toVector());
  }
  out.i64(next_rank_);
  out.i32(root_);
}

void BayesTreeEngine::load(ByteReader& in, const Model& model) {
  BayesTreeEngine e(mode_, wildfire_);
  e.model_ = &model;  // the factors read refer to it
  const std::uint8_t mode = in.u8("engine ordering mode");
  if (mode != static_cast<std::uint8_t>(mode_))
    in.fail("engine ordering mode " + std::to_string(mode) + " differs from the estimator options'");
  const double wildfire = in.f64("engine wildfire threshold", true);
  if (!(wildfire == wildfire_)) in.fail("engine wildfire threshold differs from the estimator options'");
  e.loadVariables(in, model);
  e.loadSlots(in, model);
  e.free_slots_ = in.ints("engine free slots");
  e.loadCliques(in, model);
  e.free_cliques_ = in.ints("engine free cliques");
  e.loadSlotIndex(in);
  e.next_rank_ = in.i64("engine next rank");
  e.root_ = in.i32("engine root");
  const std::string bad = e.invariantViolation();
  if (!bad.empty()) in.fail("inconsistent Bayes tree: " + bad);
  *this = std::move(e);
}

void BayesTreeEngine::loadVariables(ByteReader& in, const Model& model) {
  BayesTreeEngine& e = *this;
  const std::size_t nvars = in.count("engine variables", 9 + 16 + 12);
  for (std::size_t i = 0; i < nvars; ++i) {
    const Key k = in.key("engine variable key");
    const std::string name = "variable " + k.toString();
    if (e.vars_.contains(k)) in.fail(name + " appears twice");
    const Eigen::VectorXd anchor = in.vec(name + " anchor");
    const Eigen::VectorXd delta = in.vec(name + " delta");
    if (anchor.size() == 0) in.fail(name + " is empty (the model has no such variable)");
    if (anchor.size() != variableDim(model, k) || delta.size() != anchor.size())
      in.fail(name + " has size " + std::to_string(anchor.size()) + " but the model's is " +
              std::to_string(variableDim(model, k)));
    Var v(anchor);
    v.delta() = delta;
    v.clique = in.i32((name + " clique").c_str());
    v.rank = in.i64((name + " rank").c_str());
    e.vars_.insert(k, std::move(v));
  }
}

void BayesTreeEngine::loadSlots(ByteReader& in, const Model& model) {
  BayesTreeEngine& e = *this;
  e.slots_.resize(in.count("engine factor slots", 1));
  for (std::size_t s = 0; s < e.slots_.size(); ++s) {
    const std::string name = "factor slot " + std::to_string(s);
    Slot& slot = e.slots_[s];
    slot.alive = in.boolean((name + " alive").c_str());
    if (!slot.alive) continue;
    ++e.slots_alive_;
    FactorPtr factor;
    if (in.boolean((name + " has a nonlinear factor").c_str())) factor = readFactor(in, model, name);
    const LinearFactor linear = readLinear(in, model, name + " linearization");
    // A live slot's factor is on some variable (found by the checkpoint fuzzer:
    // an empty one left the slot without a record).
    if (linear.keys().empty()) in.fail(name + ": its linearization is on no variable");
    if (factor) {  // the slot holds it as a running engine does (a model's factor as its numbers)
      if (linear.keys() != factor->keys()) in.fail(name + ": its linearization does not match its factor");
      slot.nonlinear = SlotFactor(factor, &model);
    }
    e.storeLinearization(slot, linear.view());
    slot.owner = in.i32((name + " owner").c_str());
  }
}

void BayesTreeEngine::loadCliques(ByteReader& in, const Model& model) {
  BayesTreeEngine& e = *this;
  e.cliques_.resize(in.count("engine cliques", 1));
  e.clique_alive_.assign(e.cliques_.size(), false);
  for (std::size_t c = 0; c < e.cliques_.size(); ++c) {
    const std::string name = "clique " + std::to_string(c);
    if (!in.boolean((name + " alive").c_str())) continue;
    e.clique_alive_[c] = true;
    ++e.cliques_alive_;
    const EliminatedClique el = readClique(in, model, name);
    Clique& cl = e.cliques_[c];
    e.storeClique(el, cl);
    const std::vector<int> owned = in.ints(name + " owned slots");
    cl.owned.assign(owned.begin(), owned.end());
    cl.parent = in.i32((name + " parent").c_str());
    const std::vector<int> children = in.ints(name + " children");
    cl.children.assign(children.begin(), children.end());
  }
}

// A clique's conditional [R S d] and its marginal, checked as far as they
// go alone (the tree as a whole: invariantViolation).
EliminatedClique BayesTreeEngine::readClique(ByteReader& in, const Model& model, const std::string& name) {
  EliminatedClique el;
  el.frontal = in.key(name + " frontal");
  const std::vector<Key> separator = in.keys(name + " separator");
  const Eigen::MatrixXd R = in.mat(name + " R");
  const Eigen::MatrixXd S = in.mat(name + " S");
  const Eigen::VectorXd d = in.vec(name + " d");
  if (R.rows() != R.cols() || S.rows() != R.rows() || d.size() != R.rows())
    in.fail(name + ": its conditional's R, S and d do not fit together");
  el.conditional.resize(R.rows(), R.cols() + S.cols() + 1);
  el.conditional << R, S, d;
  el.marginal = readLinear(in, model, name + " marginal");
  if (el.marginal.keys() != separator) {
    // The separator is held once, as the marginal's keys; an empty marginal
    // (a checkpoint may hold one) is an empty factor on the separator.
    if (!el.marginal.keys().empty()) in.fail(name + ": its marginal is not on its separator");
    Eigen::Index width = 0;
    for (const auto& k : separator) width += variableDim(model, k);
    el.marginal.setKeys(separator);
    el.marginal.Ab.resize(0, width + 1);
  }
  // Held packed, as an elimination leaves it: upper trapezoidal.
  const Eigen::MatrixXd& m = el.marginal.Ab;
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = j + 1; i < m.rows(); ++i)
      if (m(i, j) != 0) in.fail(name + ": its marginal is not upper triangular");
  constexpr Eigen::Index kMax = std::numeric_limits<std::uint16_t>::max();
  if (R.rows() > kMax || S.cols() > kMax || static_cast<Eigen::Index>(separator.size()) > kMax)
    in.fail(name + ": its conditional is larger than the engine holds");
  if (m.cols() != S.cols() + 1) in.fail(name + ": its marginal and its conditional's S differ in width");
  return el;
}

void BayesTreeEngine::loadSlotIndex(ByteReader& in) {
  BayesTreeEngine& e = *this;
  const std::size_t nindexed = in.count("engine slot index", 9 + 8);
  std::unordered_set<Key, KeyHash> indexed;
  for (std::size_t i = 0; i < nindexed; ++i) {
    const Key k = in.key("slot index key");
    Var* v = k.isConstants() ? nullptr : e.vars_.find(k);
    if (!v || indexed.count(k)) in.fail("slot index: " + k.toString() + " is not a state variable or appears twice");
    indexed.insert(k);
    const std::vector<int> slots = in.ints("slots of " + k.toString());
    v->slots.assign(slots.begin(), slots.end());
  }
}

bool BayesTreeEngine::isLiveClique(int c) const {
  return c >= 0 && c < static_cast<int>(cliques_.size()) && clique_alive_[static_cast<std::size_t>(c)];
}
bool BayesTreeEngine::isLiveSlot(int s) const {
  return s >= 0 && s < static_cast<int>(slots_.size()) && slots_[static_cast<std::size_t>(s)].alive;
}
// A variable's dimension, −1 if there is no such variable.
Eigen::Index BayesTreeEngine::varDim(const Key& k) const {
  const Var* v = vars_.find(k);
  return v ? v->dim() : -1;
}
std::string BayesTreeEngine::linearViolation(const LinearView& f, const std::string& what) const {
  Eigen::Index width = 0;
  for (const auto& k : f.keys()) {
    if (varDim(k) < 0) return what + " uses " + k.toString() + ", which is not a variable";
    width += varDim(k);
  }
  if (f.cols() != width + 1) return what + ": its blocks are not as wide as its variables";
  return "";
}

std::string BayesTreeEngine::invariantViolation() const {
  if (clique_alive_.size() != cliques_.size()) return "clique flags and cliques differ in number";
  // In this order, each part relying on the ones before (indices in range).
  std::string bad = variableViolation();
  if (bad.empty()) bad = slotViolation();
  if (bad.empty()) bad = cliqueViolation();
  if (bad.empty()) bad = structureViolation();
  return bad;
}

// Each variable points to a live clique of which it is the frontal variable.
std::string BayesTreeEngine::variableViolation() const {
  const auto ns = static_cast<int>(slots_.size());
  std::string problem;
  vars_.forEach([&](const Key& k, const Var& v) {
    if (!problem.empty()) return;
    if (!isLiveClique(v.clique)) problem = k.toString() + " points to no live clique";
    else if (cliques_[static_cast<std::size_t>(v.clique)].frontal != k)
      problem = k.toString() + "'s clique has another frontal variable";
    else if (v.rank < 0 || v.rank >= next_rank_) problem = k.toString() + " has an elimination rank out of range";
    else
      for (int s : v.slots)
        if (s < 0 || s >= ns) problem = "slot index of " + k.toString() + " is out of range";
  });
  return problem;
}

// Each live slot's record, linearization and owner; the free list.
std::string BayesTreeEngine::slotViolation() const {
  const auto ns = static_cast<int>(slots_.size());
  std::size_t alive_slots = 0;
  for (int s = 0; s < ns; ++s) {
    const Slot& slot = slots_[static_cast<std::size_t>(s)];
    if (!slot.alive) continue;
    ++alive_slots;
    const std::string what = "factor slot " + std::to_string(s);
    if (slot.record + slot.words() > records_.wordsUsed()) return what + ": its record is out of range";
    const std::string lin = linearViolation(slotView(slot), what);
    if (!lin.empty()) return lin;
    if (slot.nonlinear && (!slot.nonlinear.fitsKeys(model_, slotKeys(slot)) || slot.nonlinear.dim(model_) != slot.rows))
      return what + ": its linearization does not match its factor";
    if (!isLiveClique(slot.owner)) return what + " is owned by no live clique";
    const auto& owned = cliques_[static_cast<std::size_t>(slot.owner)].owned;
    if (std::find(owned.begin(), owned.end(), s) == owned.end()) return what + ": its owner does not list it";
  }
  std::unordered_set<int> free_seen;
  for (int s : free_slots_)
    if (s < 0 || s >= ns || slots_[static_cast<std::size_t>(s)].alive || !free_seen.insert(s).second)
      return "free slot " + std::to_string(s) + " is out of range, alive or listed twice";
  if (free_seen.size() + alive_slots != slots_.size()) return "a dead factor slot is not on the free list";
  if (alive_slots != slots_alive_) return "live counts disagree";
  return "";
}

// Each live clique: frontal, record, separator, sizes, owned slots, links.
std::string BayesTreeEngine::cliqueViolation() const {
  const auto nc = static_cast<int>(cliques_.size());
  for (int c = 0; c < nc; ++c) {
    if (!clique_alive_[static_cast<std::size_t>(c)]) continue;
    const Clique& cl = cliques_[static_cast<std::size_t>(c)];
    const std::string what = "clique " + std::to_string(c);
    const Eigen::Index df = varDim(cl.frontal);
    if (df < 0 || vars_.at(cl.frontal).clique != c) return what + ": its frontal variable does not point back to it";
    if (cl.record + cl.words() > records_.wordsUsed()) return what + ": its record is out of range";
    Eigen::Index dsep = 0;
    for (const auto& k : separator(cl)) {
      if (varDim(k) < 0 || k == cl.frontal) return what + ": separator variable " + k.toString() + " is invalid";
      dsep += varDim(k);
    }
    if (cl.dv != df || cl.width != dsep) return what + ": conditional has the wrong size";
    const std::string lin = linearViolation(marginalView(cl), what + " marginal");
    if (!lin.empty()) return lin;
    for (int s : cl.owned)
      if (!isLiveSlot(s) || slots_[static_cast<std::size_t>(s)].owner != c)
        return what + " owns slot " + std::to_string(s) + " that is not its own";
    if (cl.parent != -1) {
      if (!isLiveClique(cl.parent)) return what + ": parent is not a live clique";
      const auto& ch = cliques_[static_cast<std::size_t>(cl.parent)].children;
      if (std::count(ch.begin(), ch.end(), c) != 1) return what + ": its parent does not list it once";
      if (cl.nsep == 0) return what + " has a parent but no separator";
    } else if (cl.nsep != 0) {
      return what + " has a separator but no parent";
    }
    for (int ch : cl.children)
      if (!isLiveClique(ch) || cliques_[static_cast<std::size_t>(ch)].parent != c)
        return what + ": child " + std::to_string(ch) + " does not point back";
  }
  return "";
}

// No cycles, the free cliques, the counts and the root.
std::string BayesTreeEngine::structureViolation() const {
  const auto nc = static_cast<int>(cliques_.size());
  std::size_t alive_cliques = 0;
  // Every parent is checked (cliqueViolation): each chain reaches a root within nc steps.
  for (int c = 0; c < nc; ++c) {
    if (!clique_alive_[static_cast<std::size_t>(c)]) continue;
    ++alive_cliques;
    int steps = 0;
    for (int p = cliques_[static_cast<std::size_t>(c)].parent; p >= 0; p = cliques_[static_cast<std::size_t>(p)].parent)
      if (++steps > nc) return "clique " + std::to_string(c) + ": its parent chain has a cycle";
  }
  std::unordered_set<int> free_seen;
  for (int c : free_cliques_)
    if (c < 0 || c >= nc || clique_alive_[static_cast<std::size_t>(c)] || !free_seen.insert(c).second)
      return "free clique " + std::to_string(c) + " is out of range, alive or listed twice";
  if (free_seen.size() + alive_cliques != cliques_.size()) return "a dead clique is not on the free list";
  if (alive_cliques != cliques_alive_) return "live counts disagree";
  if (alive_cliques != vars_.size()) return "cliques and variables differ in number";
  if (root_ != -1 && (!isLiveClique(root_) || cliques_[static_cast<std::size_t>(root_)].parent != -1))
    return "the root is not a live parentless clique";
  return "";
}

}  // namespace gssm::internal
