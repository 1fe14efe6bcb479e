#include "solvers/bayes_tree.h"

#include <Eigen/Householder>
#include <Eigen/QR>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <new>
#include <optional>
#include <ccolamd.h>
#include <sstream>
#include <type_traits>
#include <unordered_set>

#include "gssm/core/error.h"
#include "gssm/core/rotation_blocks.h"
#include "factors/model_factors.h"
#include "linear/dot.h"
#include "solvers/newton.h"

namespace gssm::internal {

namespace {
// J ← J·Jr(δ̂) on each rotation block's columns: the Jacobian of a factor
// in the chart x = anchor ⊕ δ of its variable at δ̂.
void chartJacobian(const std::vector<int>& blocks, int offset, const Eigen::Ref<const Eigen::VectorXd>& delta,
                   Eigen::MatrixXd& J) {
  if (hasRotationIn(blocks, delta.size(), offset))
    postmultiplyBlocks(J, blockRightJacobians(delta, blocks, offset), blocks, offset);
}
}  // namespace

// (A named type, not in an anonymous namespace: BayesTreeEngine::EliminationQueue
// holds two, and a unity source includes this file like a header.)
// Key → value table for the variables of one update: a linear scan over an
// inline array while small (appending a step touches 3-4 variables; no
// hashing, no allocation: three tables are built per clique), a hash map
// once a relinearization pass re-eliminates many. Hash maps built per
// update and per clique were a good part of the 26% of fixed-lag update
// time spent in malloc/free.
template <class T>
class KeyTable {
 public:
  KeyTable() {}  // user-provided: `KeyTable{}` must not zero the inline entries first
  void set(const Key& k, T v) {
    if (!big_.empty()) {
      big_[k] = v;
      return;
    }
    for (std::size_t i = 0; i < size_; ++i)
      if (small_.entry[i].key == k) {
        small_.entry[i].value = v;
        return;
      }
    if (size_ < kSmall) {
      new (&small_.entry[size_++]) Entry{k, v};
      return;
    }
    for (std::size_t i = 0; i < size_; ++i) big_.emplace(small_.entry[i].key, small_.entry[i].value);
    size_ = 0;
    big_[k] = v;
  }
  const T* find(const Key& k) const {
    if (!big_.empty()) {
      auto it = big_.find(k);
      return it == big_.end() ? nullptr : &it->second;
    }
    for (std::size_t i = 0; i < size_; ++i)
      if (small_.entry[i].key == k) return &small_.entry[i].value;
    return nullptr;
  }
  bool count(const Key& k) const { return find(k) != nullptr; }
  const T& at(const Key& k) const {
    const T* v = find(k);
    if (!v) throw std::out_of_range("KeyTable: " + k.toString());
    return *v;
  }

 private:
  static constexpr std::size_t kSmall = 16;
  struct Entry {
    Key key;
    T value;
  };
  static_assert(std::is_trivially_copyable_v<Entry> && std::is_trivially_destructible_v<Entry>);
  // Left uninitialized (entries [0, size_) are made as they are set):
  // zeroing 16 entries cost more than the lookups of a 3-variable update.
  union Inline {
    Inline() {}
    Entry entry[kSmall];
  } small_;
  std::size_t size_ = 0;
  std::unordered_map<Key, T, KeyHash> big_;
};

namespace {
// Householder triangularization of a clique's stacked system [A | b] in
// place: the strict lower triangle is left holding reflector data (the
// caller zeroes it). Eigen's unblocked algorithm (same reflectors: β = ∓‖x‖,
// v = [1; x_tail / (x₀ − β)], τ = (β − x₀)/β), written for the few-row,
// few-column systems of one clique, where Eigen's general kernels spent
// more on dispatch and workspace than on arithmetic (13% of a fixed-lag
// update; 3×4: 32 vs 633 ns, 16×17: 1.0 vs 4.8 µs, 80×81: 113 vs 94 µs).
void triangularize(Eigen::MatrixXd& M, std::vector<Eigen::Index>& last) {
  const Eigen::Index rows = M.rows(), cols = M.cols(), n = std::min(rows, cols);
  if (rows * cols > 48 * 49) {  // large cliques: Eigen's blocked, vectorized QR (faster from ~60 columns)
    Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(M);
    return;
  }
  // Rows below the last one whose first nonzero is at or left of column k
  // are still zero there and were never touched (the stacked marginals of
  // the children are triangular): the reflection for column k skips them.
  // Only exact zeros are skipped, so the result is bit for bit the same.
  last.assign(static_cast<std::size_t>(cols), -1);
  for (Eigen::Index i = 0; i < rows; ++i) {
    Eigen::Index lead = 0;
    while (lead < cols && M(i, lead) == 0.0) ++lead;
    if (lead < cols) last[static_cast<std::size_t>(lead)] = i;
  }
  for (Eigen::Index k = 1; k < cols; ++k)
    last[static_cast<std::size_t>(k)] = std::max(last[static_cast<std::size_t>(k)], last[static_cast<std::size_t>(k - 1)]);
  for (Eigen::Index k = 0; k < n; ++k) {
    double* x = &M(k, k);
    const Eigen::Index m = std::max<Eigen::Index>(last[static_cast<std::size_t>(k)] + 1 - k, 1);
    const double tail = dot4(x + 1, x + 1, m - 1);  // four partial sums: the chain of one sum was the clique's bottleneck
    if (tail <= std::numeric_limits<double>::min()) continue;  // already triangular here: τ = 0
    const double c0 = x[0];
    double beta = std::sqrt(c0 * c0 + tail);
    if (c0 >= 0) beta = -beta;
    const double scale = 1.0 / (c0 - beta);
    for (Eigen::Index i = 1; i < m; ++i) x[i] *= scale;
    const double tau = (beta - c0) / beta;
    x[0] = beta;
    for (Eigen::Index j = k + 1; j < cols; ++j) {  // (I − τ v vᵀ) applied to each later column
      double* y = &M(k, j);
      const double w = dot4(x + 1, y + 1, m - 1) + y[0];
      y[0] -= tau * w;
      for (Eigen::Index i = 1; i < m; ++i) y[i] -= (tau * x[i]) * w;
    }
  }
}
}  // namespace

int BayesTreeEngine::allocClique() {
  ++cliques_alive_;
  if (!free_cliques_.empty()) {
    const int c = free_cliques_.back();
    free_cliques_.pop_back();
    clique_alive_[static_cast<std::size_t>(c)] = true;
    return c;
  }
  cliques_.emplace_back();
  clique_alive_.push_back(true);
  return static_cast<int>(cliques_.size()) - 1;
}

void BayesTreeEngine::indexSlot(int s) {
  for (const auto& k : slotKeys(slots_[static_cast<std::size_t>(s)]))
    if (!k.isConstants()) vars_.at(k).slots.push_back(s);
}

namespace {
// A record's sizes are 16-bit: checked before an update commits.
constexpr Eigen::Index kMaxRecordDim = std::numeric_limits<std::uint16_t>::max();
std::uint16_t narrow16(Eigen::Index n) {
  if (n < 0 || n > kMaxRecordDim) throw std::logic_error("engine record size out of range");
  return static_cast<std::uint16_t>(n);
}
// Throws if f's keys or [A | b] are larger than a slot's record holds;
// `what` names it (called only then: a description costs more than an update).
template <class What>
void checkHoldable(const LinearFactor& f, What&& what) {
  if (static_cast<Eigen::Index>(f.keys().size()) > kMaxRecordDim || f.Ab.rows() > kMaxRecordDim ||
      f.Ab.cols() > kMaxRecordDim)
    throw InvalidArgument(what() + " has " + std::to_string(f.keys().size()) + " variables and " +
                          std::to_string(f.Ab.rows()) + " x " + std::to_string(f.Ab.cols()) +
                          " [A | b]; the engine holds at most " + std::to_string(kMaxRecordDim) + " of each");
}

// n doubles from `from` to `to`, inline (std::copy_n calls memmove: a call
// per column of a few entries, 1% of a fixed-lag update).
inline double* copyDoubles(const double* from, Eigen::Index n, double* to) {
  for (Eigen::Index i = 0; i < n; ++i) to[i] = from[i];
  return to + n;
}
template <class Keys>
void copyKeys(const Keys& keys, Key* to) {
  for (const Key& k : keys) *to++ = k;
}
}  // namespace

void BayesTreeEngine::releaseRecord(Slot& s) {
  records_.release(s.record, s.words());
  s.nkeys = s.rows = s.cols = 0;
  s.record = 0;
}

void BayesTreeEngine::storeLinearization(Slot& s, const LinearView& f) {
  const std::size_t words = f.keys().size() + static_cast<std::size_t>(f.rows() * f.cols());
  if (words != s.words()) {
    releaseRecord(s);
    s.record = records_.allocate(words);
  }
  s.nkeys = narrow16(static_cast<Eigen::Index>(f.keys().size()));
  s.rows = narrow16(f.rows());
  s.cols = narrow16(f.cols());
  copyKeys(f.keys(), records_.keys(s.record));
  double* ab = records_.doubles(s.record, s.nkeys);
  if (!f.packed) {
    copyDoubles(f.ab, f.rows() * f.cols(), ab);
    return;
  }
  for (Eigen::Index j = 0; j < f.cols(); ++j) {  // a packed view's zeros written out
    double* to = copyDoubles(f.col(j), f.colLength(j), ab + j * f.rows());
    std::fill(to, ab + (j + 1) * f.rows(), 0.0);
  }
}

void BayesTreeEngine::storeClique(const EliminatedClique& e, Clique& c) {
  c.frontal = e.frontal;
  c.solved = false;
  const KeyList& sep = e.marginal.keys();
  c.nsep = narrow16(static_cast<Eigen::Index>(sep.size()));
  c.dv = narrow16(e.conditional.rows());
  c.width = narrow16(e.conditional.cols() - e.conditional.rows() - 1);
  c.mrows = narrow16(e.marginal.rows());
  c.record = records_.allocate(c.words());
  copyKeys(sep, records_.keys(c.record));
  copyDoubles(e.conditional.data(), e.conditional.size(), records_.doubles(c.record, c.conditionalOffset()));
  // The marginal [R_S | d_S] is upper trapezoidal: each column down to the diagonal.
  double* m = records_.doubles(c.record, c.marginalOffset());
  for (Eigen::Index j = 0; j <= c.width; ++j) {
    const Eigen::Index n = std::min<Eigen::Index>(j + 1, c.mrows);
    m = copyDoubles(e.marginal.Ab.data() + j * c.mrows, n, m);
  }
  c.owned = e.owned;
}

void BayesTreeEngine::releaseRecord(Clique& c) {
  records_.release(c.record, c.words());
  c.record = 0;
  c.nsep = c.dv = c.width = c.mrows = 0;
  c.parent = -1;
  c.owned.clear();
  c.children.clear();
}

int BayesTreeEngine::allocSlot() {
  ++slots_alive_;
  if (!free_slots_.empty()) {
    const int s = free_slots_.back();
    free_slots_.pop_back();
    return s;
  }
  slots_.emplace_back();
  return static_cast<int>(slots_.size()) - 1;
}

Factor::Rotations BayesTreeEngine::rotationsOf(const Key& k) const {
  return model_ ? rotationsOfVariable(*model_, k.isConstants()) : Factor::Rotations{};
}

void BayesTreeEngine::estimateInto(const Key& k, const Var& v, Eigen::VectorXd& out) const {
  const Factor::Rotations r = rotationsOf(k);
  if (!r.blocks) {
    out = v.anchor() + v.delta();
    return;
  }
  out = v.anchor();  // anchor ⊕ δ (docs/DESIGN.md §12)
  retractBlocks(out, v.delta(), *r.blocks, r.offset);
}

void BayesTreeEngine::estimateInto(const Key& k, Eigen::VectorXd& out) const {
  const Var* v = vars_.find(k);
  if (!v) throw InvalidArgument("no variable " + k.toString() + " in the smoother");
  estimateInto(k, *v, out);
}

Eigen::VectorXd BayesTreeEngine::estimate(const Key& k) const {
  const Var* v = vars_.find(k);
  if (!v) throw InvalidArgument("no variable " + k.toString() + " in the smoother");
  Eigen::VectorXd out;
  estimateInto(k, *v, out);
  return out;
}

template <class Keys>
void BayesTreeEngine::pointAt(const Keys& keys, const Values* extra) const {
  std::vector<Eigen::VectorXd>& points = scratch_.points;
  std::vector<const Eigen::VectorXd*>& x = scratch_.x;
  std::vector<const Var*>& known = scratch_.factor_vars;
  if (points.size() < keys.size()) points.resize(keys.size());  // before any address is taken
  x.clear();
  known.clear();
  std::size_t i = 0;
  for (const auto& k : keys) {
    const Var* v = vars_.find(k);
    known.push_back(v);
    if (v) {
      // The constants in a buffer of their own: a position holds a state in
      // one factor and x_b in the next (process, then measurement), and one
      // buffer resized between their sizes reallocated every time.
      Eigen::VectorXd& p = k.isConstants() ? scratch_.constants_point : points[i];
      estimateInto(k, *v, p);
      x.push_back(&p);
    } else {
      x.push_back(&extra->at(k));
    }
    ++i;
  }
}

// Linearizes f at the current estimate: r(x) ≈ r(x̂) + J (δ − δ̂), i.e.
// A = J, b = J δ̂ − r(x̂). `extra` holds initial values of variables being added.
template <class Keys>
LinearFactor BayesTreeEngine::linearize(const SlotFactor& f, const Model* model, const Keys& keys,
                                        const Values& extra) const {
  pointAt(keys, &extra);
  const std::vector<const Var*>& known = scratch_.factor_vars;  // null: a new variable (δ̂ = 0)
  LinearFactor lf;
  if (!pool_.spare_linear.empty()) {  // its vectors and matrices get overwritten (same shapes: no allocation)
    lf = std::move(pool_.spare_linear.back());
    pool_.spare_linear.pop_back();
  }
  lf.setKeys(keys);
  Eigen::VectorXd& r = scratch_.r;
  std::vector<Eigen::MatrixXd>& J = scratch_.J[std::min<std::size_t>(keys.size(), scratch_.J.size() - 1)];
  f.linearizeRobustAt(model, scratch_.x.data(), r, &J);  // robust factors reweighted at each linearization
  bool finite = r.allFinite();
  for (const auto& a : J) finite = finite && a.allFinite();
  if (!finite)
    throw NumericalError("factor '" + f.toFactor(model, keys)->describe() +
                         "' has a non-finite residual or Jacobian at the current estimate");
  // On a rotation block δ is a chart at the anchor: x = anchor ⊕ δ, so
  // ∂r/∂δ = J·Jr(δ̂) there (docs/DESIGN.md §12).
  std::size_t i = 0;
  for (const auto& k : keys) {
    const Factor::Rotations rot = rotationsOf(k);
    if (known[i] && rot.blocks) chartJacobian(*rot.blocks, rot.offset, known[i]->delta(), J[i]);
    ++i;
  }
  lf.setBlocks(J, r.size());
  auto b = lf.Ab.col(lf.Ab.cols() - 1);
  b = -r;
  for (std::size_t j = 0; j < known.size(); ++j)
    if (known[j]) b += J[j] * known[j]->delta();
  return lf;
}

void BayesTreeEngine::order(const std::vector<Key>& keys, const std::vector<std::pair<LinearView, InputSource>>& factors,
                            const Values& new_vars, std::vector<Key>& out) const {
  out.assign(keys.begin(), keys.end());
  if (mode_ == OrderingMode::TimeOrdered || keys.size() <= 2) {
    std::sort(out.begin(), out.end());  // Key order: states by step, constants last
    return;
  }
  // CCOLAMD on the factor × variable incidence, with constraint groups:
  // 0 = older variables, 1 = the newest variables, 2 = constants (root).
  auto group = [&](const Key& k) { return k.isConstants() ? 2 : (new_vars.contains(k) ? 1 : 0); };
  // One variable per group (a chain's usual top: the last state, the new
  // one, the constants) leaves CCOLAMD no choice: the groups' order is the
  // ordering, without its ~4k instructions of set-up per update.
  int per_group[3] = {0, 0, 0};
  for (const auto& k : keys) ++per_group[group(k)];
  if (per_group[0] <= 1 && per_group[1] <= 1 && per_group[2] <= 1) {
    std::sort(out.begin(), out.end(), [&](const Key& a, const Key& b) { return group(a) < group(b); });
    return;
  }
  std::unordered_map<Key, int, KeyHash> col;
  for (std::size_t i = 0; i < keys.size(); ++i) col[keys[i]] = static_cast<int>(i);
  std::vector<std::vector<int>> rows_of_col(keys.size());
  int nrow = 0;
  for (const auto& f : factors) {
    bool any = false;
    for (const auto& k : f.first.keys()) {
      auto it = col.find(k);
      if (it != col.end()) {
        rows_of_col[static_cast<std::size_t>(it->second)].push_back(nrow);
        any = true;
      }
    }
    if (any) ++nrow;
  }
  const int ncol = static_cast<int>(keys.size());
  std::vector<int> p(static_cast<std::size_t>(ncol) + 1, 0), A;
  for (int j = 0; j < ncol; ++j) {
    p[static_cast<std::size_t>(j) + 1] = p[static_cast<std::size_t>(j)] +
                                         static_cast<int>(rows_of_col[static_cast<std::size_t>(j)].size());
    for (int r : rows_of_col[static_cast<std::size_t>(j)]) A.push_back(r);
  }
  const std::size_t alen = ccolamd_recommended(static_cast<int>(A.size()), nrow, ncol);
  A.resize(std::max<std::size_t>(alen, A.size()));
  std::vector<int> cmember(static_cast<std::size_t>(ncol));
  for (int j = 0; j < ncol; ++j) cmember[static_cast<std::size_t>(j)] = group(keys[static_cast<std::size_t>(j)]);
  double knobs[CCOLAMD_KNOBS];
  int stats[CCOLAMD_STATS];
  ccolamd_set_defaults(knobs);
  if (!ccolamd(nrow, ncol, static_cast<int>(A.size()), A.data(), p.data(), knobs, stats,
               cmember.data())) {
    std::sort(out.begin(), out.end());  // CCOLAMD failed: fall back to time order
    return;
  }
  for (int i = 0; i < ncol; ++i) out[static_cast<std::size_t>(i)] = keys[static_cast<std::size_t>(p[static_cast<std::size_t>(i)])];
}

struct BayesTreeEngine::UpdatePlan {
  UpdatePlan(const EngineUpdate& u, UpdateLists& l)
      : update(u),
        new_variables(u.new_variables ? *u.new_variables : none),
        new_factors(u.new_factors ? *u.new_factors : no_factors),
        new_linear(u.new_linear ? *u.new_linear : no_linear),
        held_new(l.held_new),
        linearized_new(l.linearized_new),
        removed_order(l.removed_order),
        orphans(l.orphans),
        keys(l.keys),
        inputs(l.inputs),
        ordering(l.ordering),
        new_slot_of(l.new_slot_of),
        new_lin_slot_of(l.new_lin_slot_of),
        fresh(l.fresh),
        fresh_owned(l.fresh_owned),
        fresh_id(l.fresh_id) {
    l.clear();
  }
  const EngineUpdate& update;
  const Values none{};
  const std::vector<FactorPtr> no_factors{};
  const std::vector<LinearFactor> no_linear{};
  const Values& new_variables;
  const std::vector<FactorPtr>& new_factors;
  const std::vector<LinearFactor>& new_linear;
  const Model* model = nullptr;  // the engine's, or the first model factor's (commit() keeps it)
  std::unordered_map<int, LinearFactor> relinearized;  // by slot (linearizeInputs)
  // The rest lives in the engine's UpdateLists, emptied here, so that its
  // vectors keep their capacity from update to update.
  std::vector<SlotFactor>& held_new;
  std::vector<LinearFactor>& linearized_new;
  std::vector<int>& removed_order;
  std::vector<int>& orphans;
  std::vector<Key>& keys;
  std::vector<std::pair<LinearView, InputSource>>& inputs;
  std::vector<Key>& ordering;
  std::vector<int>& new_slot_of;
  std::vector<int>& new_lin_slot_of;
  std::vector<EliminatedClique>& fresh;
  std::vector<std::pair<std::size_t, InputSource>>& fresh_owned;
  std::vector<int>& fresh_id;
};

void BayesTreeEngine::update(const EngineUpdate& u, EngineCounts& counts) {
  UpdatePlan plan(u, lists_);
  plan.model = model_;
  linearizeInputs(plan);  // validates; nothing modified until commit()
  detachTop(plan);
  eliminateTop(plan);
  commit(plan, counts);
  backSubstituteTop(plan, counts);
}

// Phase 1: validate the new variables and factors, linearize the new
// factors and the slots to relinearize at the current estimate.
void BayesTreeEngine::linearizeInputs(UpdatePlan& p) const {
  for (const auto& kv : p.new_variables) {
    if (vars_.contains(kv.first))
      throw InvalidArgument("variable " + kv.first.toString() + " already exists");
    if (!kv.second.allFinite())
      throw InvalidArgument("initial value of " + kv.first.toString() + " is not finite");
    if (kv.second.size() == 0) throw InvalidArgument("initial value of " + kv.first.toString() + " is empty");
  }
  auto known = [&](const Key& k) { return vars_.contains(k) || p.new_variables.contains(k); };
  for (const auto& f : p.new_factors) {
    for (const auto& k : f->keys())
      if (!known(k))
        throw InvalidArgument("factor '" + f->describe() + "' uses " + k.toString() +
                              ", which is neither in the smoother nor added with it");
    if (!p.model) p.model = SlotFactor::modelOf(f);  // the engine's from the first model factor on
    p.held_new.emplace_back(f, p.model);
    p.linearized_new.push_back(linearize(p.held_new.back(), p.model, f->keys(), p.new_variables));
    checkHoldable(p.linearized_new.back(), [&] { return "factor '" + f->describe() + "'"; });
  }
  for (const auto& lf : p.new_linear) {
    for (const auto& k : lf.keys())
      if (!known(k)) throw InvalidArgument("linear factor uses unknown variable " + k.toString());
    checkHoldable(lf, [] { return std::string("a linear factor"); });
  }
  for (int s : p.update.remove)
    if (s < 0 || static_cast<std::size_t>(s) >= slots_.size() || !slots_[static_cast<std::size_t>(s)].alive)
      throw InvalidArgument("remove: factor slot " + std::to_string(s) + " is not a live factor");
  for (int s : p.update.relinearize) {
    const Slot& slot = slots_.at(static_cast<std::size_t>(s));
    if (slot.alive && slot.nonlinear)
      p.relinearized[s] = linearize(slot.nonlinear, p.model, slotKeys(slot), p.new_variables);
  }
}

// Phase 2: the top of the tree to re-eliminate — every clique on the path
// from a touched variable to the root — and what it consumes: the factors
// its cliques owned (relinearized where asked), the new factors, and the
// marginals of the orphaned subtrees below it.
void BayesTreeEngine::detachTop(UpdatePlan& p) const {
  // Cliques in the top, marked by id (a reused buffer, cleared on the way out).
  std::vector<char>& removed = scratch_.in_top;
  if (removed.size() < cliques_.size()) removed.resize(cliques_.size(), 0);
  auto markUp = [&](const Key& k) {
    const Var* v = vars_.find(k);
    if (!v) return;
    for (int c = v->clique; c >= 0 && !removed[static_cast<std::size_t>(c)];
         c = cliques_[static_cast<std::size_t>(c)].parent) {
      removed[static_cast<std::size_t>(c)] = 1;
      p.removed_order.push_back(c);
    }
  };
  for (const auto& lf : p.linearized_new)
    for (const auto& k : lf.keys()) markUp(k);
  for (const auto& lf : p.new_linear)
    for (const auto& k : lf.keys()) markUp(k);
  for (const auto& kv : p.relinearized)
    for (const auto& k : kv.second.keys()) markUp(k);
  for (int s : p.update.remove)
    for (const auto& k : slotKeys(slots_[static_cast<std::size_t>(s)])) markUp(k);
  auto removed_slot = [&](int s) {
    return std::find(p.update.remove.begin(), p.update.remove.end(), s) != p.update.remove.end();
  };

  using Kind = InputSource::Kind;
  for (int c : p.removed_order) {
    const Clique& cl = cliques_[static_cast<std::size_t>(c)];
    p.keys.push_back(cl.frontal);
    for (int s : cl.owned) {
      if (removed_slot(s)) continue;
      auto it = p.relinearized.find(s);
      p.inputs.push_back({it != p.relinearized.end() ? it->second.view() : slotView(slots_[static_cast<std::size_t>(s)]),
                          {Kind::Slot, s}});
    }
    for (int ch : cl.children)
      if (!removed[static_cast<std::size_t>(ch)]) p.orphans.push_back(ch);
  }
  for (const auto& kv : p.new_variables) p.keys.push_back(kv.first);
  for (std::size_t i = 0; i < p.linearized_new.size(); ++i)
    p.inputs.push_back({p.linearized_new[i].view(), {Kind::NewFactor, static_cast<int>(i)}});
  for (std::size_t i = 0; i < p.new_linear.size(); ++i)
    p.inputs.push_back({p.new_linear[i].view(), {Kind::NewLinear, static_cast<int>(i)}});
  for (int o : p.orphans) p.inputs.push_back({marginalView(cliques_[static_cast<std::size_t>(o)]), {Kind::Orphan, o}});
  for (int c : p.removed_order) removed[static_cast<std::size_t>(c)] = 0;
}

// The factors waiting to be eliminated: each at the first of its variables
// in the ordering; the marginal a clique leaves on its separator joins them.
struct BayesTreeEngine::EliminationQueue {
  const std::vector<Key>& ordering;
  KeyTable<std::size_t> pos;      // a variable's place in the ordering
  KeyTable<Eigen::Index> dims;    // its dimension
  std::vector<std::vector<std::size_t>>& pending_of;
  std::vector<LinearView>& pend;
  std::vector<std::optional<InputSource>>& pend_source;  // nullopt: a marginal made here

  void add(const LinearView& f, std::optional<InputSource> source) {
    const std::size_t id = pend.size();
    pend.push_back(f);
    pend_source.push_back(source);
    std::size_t first = ordering.size();
    for (const auto& k : f.keys()) first = std::min(first, pos.at(k));
    if (first < ordering.size()) pending_of[first].push_back(id);
  }
};

// Phase 3: order the top's variables and eliminate them one at a time into
// new cliques (still nothing modified). Dense elimination of one variable
// at a time (the paper's window system A_w X_w = b_w, solved by QR clique by
// clique): stack the factors [A | b] with v first, triangularize, split R
// into the conditional on v and the marginal factor on its separator.
void BayesTreeEngine::eliminateTop(UpdatePlan& p) const {
  order(p.keys, p.inputs, p.new_variables, p.ordering);
  EliminationQueue q = queueInputs(p);
  p.fresh.assign(p.ordering.size(), EliminatedClique{});  // empty: no allocation
  p.fresh_owned.clear();
  for (std::size_t vi = 0; vi < p.ordering.size(); ++vi) eliminateVariable(p, q, vi);
}

// The queue of the update's inputs, each at its first variable.
BayesTreeEngine::EliminationQueue BayesTreeEngine::queueInputs(UpdatePlan& p) const {
  const std::vector<Key>& ordering = p.ordering;
  EliminationQueue q{ordering, {}, {}, scratch_.pending_of, scratch_.pend, scratch_.pend_source};
  for (std::size_t i = 0; i < ordering.size(); ++i) q.pos.set(ordering[i], i);
  for (const auto& k : ordering) {
    const Var* var = vars_.find(k);
    q.dims.set(k, var ? var->dim() : p.new_variables.at(k).size());
  }
  // After a whole-history update, its storage goes (`= {}` would keep the
  // capacity: the initializer-list assignment; 24 bytes a variable).
  if (ordering.size() <= kKeepEntries && q.pending_of.size() > kKeepEntries)
    std::vector<std::vector<std::size_t>>().swap(q.pending_of);
  if (q.pending_of.size() < ordering.size()) q.pending_of.resize(ordering.size());
  for (std::size_t i = 0; i < ordering.size(); ++i) q.pending_of[i].clear();
  clearKeepingSmall(q.pend);
  clearKeepingSmall(q.pend_source);
  for (const auto& in : p.inputs) {
    bool empty = true;
    for (const auto& k : in.first.keys()) empty = empty && !q.pos.count(k);
    if (empty) continue;  // cannot happen for a consistent tree
    q.add(in.first, in.second.kind == InputSource::Kind::Orphan ? std::nullopt : std::optional<InputSource>(in.second));
  }
  return q;
}

// A pooled clique of the same shape (one an earlier update made), if any,
// whose storage the new one then overwrites without allocating.
void BayesTreeEngine::reusePooledClique(EliminatedClique& cl, Eigen::Index dv, Eigen::Index sep_cols) const {
  auto& spare = pool_.spare;
  for (std::size_t i = spare.size(); i-- > 0;) {
    const EliminatedClique& c = spare[i];
    if (c.conditional.rows() != dv || c.conditional.cols() != dv + sep_cols + 1) continue;
    cl = std::move(spare[i]);
    spare[i] = std::move(spare.back());
    spare.pop_back();
    cl.owned.clear();
    return;
  }
}

// Eliminates ordering[vi]: its clique's conditional [R S d] and the marginal
// factor it leaves on its separator (queued for a later variable).
void BayesTreeEngine::eliminateVariable(UpdatePlan& p, EliminationQueue& q, std::size_t vi) const {
  const Key& v = p.ordering[vi];
  EliminatedClique& cl = p.fresh[vi];
  const std::vector<Key>& sep = separatorOf(q, vi);
  const Eigen::Index dv = q.dims.at(v);
  KeyTable<Eigen::Index> colOf;  // each variable's first column: v, then the separator
  Eigen::Index ncols = dv;
  colOf.set(v, 0);
  for (const auto& k : sep) {
    colOf.set(k, ncols);
    ncols += q.dims.at(k);
  }
  if (ncols - dv > kMaxRecordDim)
    throw InvalidArgument("eliminating " + v.toString() + " makes a clique " + std::to_string(ncols) +
                          " wide; the engine holds at most " + std::to_string(kMaxRecordDim));
  reusePooledClique(cl, dv, ncols - dv);
  cl.frontal = v;
  Eigen::MatrixXd& M = scratch_.stacked;
  const Eigen::Index rows = stackFactors(p, q, vi, colOf, ncols, M);
  if (rows < dv) {
    std::ostringstream os;
    os << "cannot determine " << v.toString() << (v.isConstants() ? " (constants)" : " (a time-series state)")
       << ": the factors on it have " << rows << " rows for " << dv
       << " unknowns (unobserved; add a prior or a measurement of it)";
    throw NumericalError(os.str());
  }
  const double scale = std::max(1e-300, M.leftCols(dv).cwiseAbs().maxCoeff());
  // In place: M becomes R (upper triangle) and the Householder vectors.
  triangularize(M, scratch_.last_row);
  const Eigen::Index rk = std::min(rows, ncols + 1);
  M.topRows(rk).triangularView<Eigen::StrictlyLower>().setZero();
  const auto Rfull = M.topRows(rk);
  for (Eigen::Index i = 0; i < dv; ++i)
    if (!(std::abs(Rfull(i, i)) > 1e-10 * scale)) throwRankDeficient(v, i, sep);
  cl.conditional = Rfull.topRows(dv);  // [R S d]
  // The remaining rows are the marginal factor on the separator, whose
  // columns follow v's in separator order: [A | b] as they stand.
  LinearFactor& m = cl.marginal;
  const Eigen::Index mrows = std::max<Eigen::Index>(0, std::min(rk, ncols) - dv);
  m.Ab = Rfull.block(dv, dv, mrows, ncols - dv + 1);
  m.setKeys(sep);
  if (!sep.empty() && mrows > 0) q.add(m.view(), std::nullopt);
}

// The variables the factors waiting at ordering[vi] share with it, in
// elimination order (scratch_.separator).
const std::vector<Key>& BayesTreeEngine::separatorOf(const EliminationQueue& q, std::size_t vi) const {
  const Key& v = q.ordering[vi];
  std::vector<Key>& sep = scratch_.separator;
  sep.clear();
  for (std::size_t id : q.pending_of[vi])
    for (const auto& k : q.pend[id].keys())
      if (k != v && std::find(sep.begin(), sep.end(), k) == sep.end()) sep.push_back(k);
  std::sort(sep.begin(), sep.end(), [&](const Key& a, const Key& b) { return q.pos.at(a) < q.pos.at(b); });
  if (static_cast<Eigen::Index>(sep.size()) > kMaxRecordDim || q.dims.at(v) > kMaxRecordDim)
    throw InvalidArgument("eliminating " + v.toString() + " makes a clique on " + std::to_string(sep.size()) +
                          " variables; the engine holds at most " + std::to_string(kMaxRecordDim));
  return sep;
}

// M = the factors waiting at ordering[vi], stacked as [A | b] in the
// clique's columns, and under LM damping Marquardt rows on v; its row count.
template <class ColumnTable>
Eigen::Index BayesTreeEngine::stackFactors(UpdatePlan& p, const EliminationQueue& q, std::size_t vi,
                                           const ColumnTable& colOf, Eigen::Index ncols, Eigen::MatrixXd& M) const {
  const Key& v = q.ordering[vi];
  const Eigen::Index dv = q.dims.at(v);
  Eigen::Index rows = 0;
  for (std::size_t id : q.pending_of[vi]) rows += q.pend[id].rows();
  const double damping = p.update.damping;
  const Eigen::Index damp_rows = damping > 0 ? dv : 0;
  M.setZero(rows + damp_rows, ncols + 1);
  Eigen::Index r0 = 0;
  for (std::size_t id : q.pending_of[vi]) {
    const LinearView& f = q.pend[id];
    if (q.pend_source[id]) p.fresh_owned.emplace_back(vi, *q.pend_source[id]);
    if (f.rows() == 0) continue;  // an empty marginal: nothing to stack (and M(r0, ·) would be past its end)
    // Column by column (a packed marginal holds none of its zeros; M's are set).
    auto copyCol = [&](Eigen::Index from, Eigen::Index to) { copyDoubles(f.col(from), f.colLength(from), &M(r0, to)); };
    Eigen::Index col = 0;
    for (const auto& k : f.keys()) {
      const Eigen::Index w = q.dims.at(k), to = colOf.at(k);
      for (Eigen::Index j = 0; j < w; ++j) copyCol(col + j, to + j);
      col += w;
    }
    copyCol(col, ncols);
    r0 += f.rows();
  }
  if (damp_rows == 0) return rows;
  // Marquardt rows pull δ_v toward its current value: √λ·D (δ_v − δ̂_v) = 0.
  const Var* var = vars_.find(v);
  const Eigen::VectorXd dhat = var ? Eigen::VectorXd(var->delta()) : Eigen::VectorXd(Eigen::VectorXd::Zero(dv));
  for (Eigen::Index i = 0; i < dv; ++i) {
    const double w = std::sqrt(damping) * std::max(M.col(i).head(rows).norm(), 1e-12);
    M(rows + i, i) = w;
    M(rows + i, ncols) = w * dhat[i];
  }
  return rows + damp_rows;
}

[[noreturn]] void BayesTreeEngine::throwRankDeficient(const Key& v, Eigen::Index component,
                                                      const std::vector<Key>& sep) {
  std::ostringstream os;
  os << "the information on " << v.toString() << (v.isConstants() ? " (constants)" : " (a time-series state)")
     << " component " << component << " is zero or rank-deficient given the variables eliminated after it";
  if (!sep.empty()) {
    os << " (";
    for (std::size_t j = 0; j < sep.size(); ++j) os << (j ? ", " : "") << sep[j].toString();
    os << ")";
  }
  os << ": the data do not determine it (e.g. a range at x = h = 0, a constant nothing "
        "observes); add a prior or check the model";
  throw NumericalError(os.str());
}

// Phase 4: replace the top by the new cliques, give new factors their
// slots, and re-attach the orphans below the lowest of their separator's
// cliques. Nothing here throws short of memory.
void BayesTreeEngine::commit(UpdatePlan& p, EngineCounts& counts) {
  forgetSolved();
  model_ = p.model;
  for (int s : p.update.remove) killSlot(s);
  commitFactors(p, counts);
  commitCliques(p);
  reattachOrphans(p);
  counts.cliques_reeliminated += static_cast<int>(p.ordering.size());
  counts.top.assign(p.ordering.begin(), p.ordering.end());
  counts.orphans += static_cast<int>(p.orphans.size());
}

// The relinearized factors' new linearizations, the top's cliques released,
// the new variables, and a slot for each new factor.
void BayesTreeEngine::commitFactors(UpdatePlan& p, EngineCounts& counts) {
  for (auto& kv : p.relinearized) {
    storeLinearization(slots_[static_cast<std::size_t>(kv.first)], kv.second.view());  // same size: in place
    pool_.keep(std::move(kv.second));
    ++counts.factors_relinearized;
  }
  for (int c : p.removed_order) {
    clique_alive_[static_cast<std::size_t>(c)] = false;
    releaseRecord(cliques_[static_cast<std::size_t>(c)]);
    free_cliques_.push_back(c);
    --cliques_alive_;
  }
  for (const auto& kv : p.new_variables) {
    vars_.insert(kv.first, Var(kv.second));
  }
  std::vector<int>& new_slot_of = p.new_slot_of;
  std::vector<int>& new_lin_slot_of = p.new_lin_slot_of;
  new_slot_of.assign(p.linearized_new.size(), -1);
  new_lin_slot_of.assign(p.new_linear.size(), -1);
  auto addSlot = [&](SlotFactor&& f, const LinearFactor& lf) {
    const int s = allocSlot();
    Slot& slot = slots_[static_cast<std::size_t>(s)];
    slot.nonlinear = std::move(f);
    storeLinearization(slot, lf.view());
    slot.alive = true;
    indexSlot(s);
    return s;
  };
  for (std::size_t i = 0; i < p.linearized_new.size(); ++i) {
    new_slot_of[i] = addSlot(std::move(p.held_new[i]), p.linearized_new[i]);
    pool_.keep(std::move(p.linearized_new[i]));
  }
  for (std::size_t i = 0; i < p.new_linear.size(); ++i) new_lin_slot_of[i] = addSlot(SlotFactor(), p.new_linear[i]);
}

// The eliminated cliques stored, each owning the factors it consumed, and
// linked to their parents (the clique of their separator's first variable).
void BayesTreeEngine::commitCliques(UpdatePlan& p) {
  const std::vector<Key>& ordering = p.ordering;
  p.fresh_id.resize(ordering.size());
  auto owned = p.fresh_owned.begin();
  for (std::size_t vi = 0; vi < ordering.size(); ++vi) {
    const int c = allocClique();
    p.fresh_id[vi] = c;
    for (; owned != p.fresh_owned.end() && owned->first == vi; ++owned) {
      const InputSource& src = owned->second;
      using Kind = InputSource::Kind;
      const int s = src.kind == Kind::Slot        ? src.index
                    : src.kind == Kind::NewFactor ? p.new_slot_of[static_cast<std::size_t>(src.index)]
                                                  : p.new_lin_slot_of[static_cast<std::size_t>(src.index)];
      p.fresh[vi].owned.push_back(s);
      slots_[static_cast<std::size_t>(s)].owner = c;
    }
    Var& var = vars_.at(ordering[vi]);
    var.clique = c;
    var.rank = next_rank_++;
  }
  for (std::size_t vi = 0; vi < ordering.size(); ++vi) {
    EliminatedClique& fresh = p.fresh[vi];
    Clique& cl = cliques_[static_cast<std::size_t>(p.fresh_id[vi])];  // a free one: no record, no links
    storeClique(fresh, cl);
    cl.parent = fresh.marginal.keys().empty() ? -1 : vars_.at(fresh.marginal.keys().front()).clique;
    pool_.keep(std::move(fresh));
  }
  root_ = -1;
  for (std::size_t vi = 0; vi < ordering.size(); ++vi) {
    const int c = p.fresh_id[vi];
    const int parent = cliques_[static_cast<std::size_t>(c)].parent;
    if (parent >= 0) cliques_[static_cast<std::size_t>(parent)].children.push_back(c);
    else root_ = c;
  }
}

// Each orphan under the lowest clique of its separator's variables.
void BayesTreeEngine::reattachOrphans(const UpdatePlan& p) {
  for (int o : p.orphans) {
    Clique& oc = cliques_[static_cast<std::size_t>(o)];
    int best = -1;
    std::int64_t best_rank = 0;
    for (const auto& k : separator(oc)) {
      const Var& v = vars_.at(k);
      if (best < 0 || v.rank < best_rank) {
        best = v.clique;
        best_rank = v.rank;
      }
    }
    oc.parent = best;
    cliques_[static_cast<std::size_t>(best)].children.push_back(o);
  }
  if (root_ < 0)
    for (std::size_t c = 0; c < cliques_.size(); ++c)
      if (clique_alive_[c] && cliques_[c].parent < 0) root_ = static_cast<int>(c);
}

// Phase 5: back-substitution of the new top, then wildfire into orphans
// while a separator variable moved more than the threshold.
void BayesTreeEngine::backSubstituteTop(const UpdatePlan& p, EngineCounts& counts) {
  for (std::size_t vi = p.ordering.size(); vi-- > 0;) {
    backSubstitute(p.fresh_id[vi]);
    ++counts.variables_backsubstituted;
  }
  std::vector<int>& stack = scratch_.path;
  stack.assign(p.orphans.begin(), p.orphans.end());
  std::vector<double>& old = scratch_.before;  // δ before, to see how far it moved
  while (!stack.empty()) {
    const int c = stack.back();
    stack.pop_back();
    Var& v = vars_.at(cliques_[static_cast<std::size_t>(c)].frontal);
    old.assign(v.delta().data(), v.delta().data() + v.dim());
    backSubstitute(c);
    ++counts.variables_backsubstituted;
    if ((v.delta() - Eigen::Map<const Eigen::VectorXd>(old.data(), v.dim())).lpNorm<Eigen::Infinity>() > wildfire_)
      for (int ch : cliques_[static_cast<std::size_t>(c)].children) stack.push_back(ch);
  }
  clearKeepingSmall(stack);  // a wildfire through the whole history grew it
}

void BayesTreeEngine::forgetSolved() {
  for (int c : solved_cliques_) cliques_[static_cast<std::size_t>(c)].solved = false;
  clearKeepingSmall(solved_cliques_);
}

void BayesTreeEngine::backSubstitute(int c) {
  Clique& cl = cliques_[static_cast<std::size_t>(c)];
  if (!cl.solved) {
    cl.solved = true;
    solved_cliques_.push_back(c);
  }
  const auto C = conditional(cl);  // [R S d]
  // Solved in the frontal's own δ (its size: no allocation), the products
  // in a buffer that only grows (a scratch vector resized between a state's
  // and the constants' sizes reallocated at every clique).
  Eigen::Map<Eigen::VectorXd> rhs = vars_.at(cl.frontal).delta();
  const Eigen::Index n = cl.dv;
  rhs = C.col(C.cols() - 1);
  std::vector<double>& buffer = scratch_.product;
  if (buffer.size() < static_cast<std::size_t>(n)) buffer.resize(static_cast<std::size_t>(n));
  Eigen::Map<Eigen::VectorXd> term(buffer.data(), n);
  const auto S = C.middleCols(n, cl.width);
  Eigen::Index col = 0;
  for (const auto& k : separator(cl)) {
    const auto ds = vars_.at(k).delta();
    term.noalias() = S.middleCols(col, ds.size()) * ds;  // the product, then the difference
    rhs -= term;
    col += ds.size();
  }
  if (n <= 8) {
    // R δ = rhs by columns, last first, as Eigen's solver does within its
    // 8-column panel (the same arithmetic), without its general-size
    // dispatch on a block: a fixed-lag update back-substitutes ~11 cliques.
    const double* R = C.data();  // column-major, R(i, j) = R[i + j·n]
    for (Eigen::Index j = n - 1; j >= 0; --j) {
      if (rhs[j] == 0) continue;  // as Eigen: 0 / R(j, j) stays +0
      rhs[j] /= R[j + j * n];
      for (Eigen::Index i = 0; i < j; ++i) rhs[i] -= rhs[j] * R[i + j * n];
    }
  } else {
    C.leftCols(n).triangularView<Eigen::Upper>().solveInPlace(rhs);
  }
}

void BayesTreeEngine::setEstimates(const Values& x) {
  forgetSolved();
  Eigen::VectorXd d;
  for (const auto& kv : x) {
    Var& v = vars_.at(kv.first);
    const Factor::Rotations r = rotationsOf(kv.first);
    if (r.blocks) {  // δ = x ⊖ anchor
      localBlocks(kv.second, v.anchor(), d, *r.blocks, r.offset);
      v.delta() = d;
    } else {
      v.delta() = kv.second - v.anchor();
    }
  }
}

Values BayesTreeEngine::allEstimates() const {
  Values out;
  out.reserve(vars_.size());
  vars_.forEach([&](const Key& k, const Var&) { out.insert(k, estimate(k)); });
  return out;
}

int BayesTreeEngine::solveAll() {
  // The tree can be a forest (e.g. x_c(0) and x_b before any measurement).
  std::vector<int> stack;
  for (std::size_t c = 0; c < cliques_.size(); ++c)
    if (clique_alive_[c] && cliques_[c].parent < 0) stack.push_back(static_cast<int>(c));
  int n = 0;
  while (!stack.empty()) {
    const int c = stack.back();
    stack.pop_back();
    backSubstitute(c);
    ++n;
    for (int ch : cliques_[static_cast<std::size_t>(c)].children) stack.push_back(ch);
  }
  return n;
}

void BayesTreeEngine::solvePath(const Key& k) {
  std::vector<int>& path = scratch_.path;
  path.clear();
  for (int c = vars_.at(k).clique; c >= 0; c = cliques_[static_cast<std::size_t>(c)].parent) path.push_back(c);
  // Root first; a clique solved since the last change has solved ancestors,
  // so the path's solved part is its top and is skipped (the same numbers).
  for (auto it = path.rbegin(); it != path.rend(); ++it)
    if (!cliques_[static_cast<std::size_t>(*it)].solved) backSubstitute(*it);
  clearKeepingSmall(path);  // an old state's path grew it to the history's length
}

Eigen::MatrixXd BayesTreeEngine::pathMarginalCovariance(const std::vector<Key>& keys) const {
  for (const auto& k : keys)
    if (!vars_.contains(k)) throw InvalidArgument("no variable " + k.toString() + " in the smoother");
  const int root_of_one = keys.size() == 1 ? vars_.at(keys[0]).clique : -1;
  Eigen::MatrixXd S = root_of_one >= 0 && cliques_[static_cast<std::size_t>(root_of_one)].parent < 0
                          ? rootCovariance(cliques_[static_cast<std::size_t>(root_of_one)])
                          : bayesNetCovariance(keys);
  // Of δ in the anchor's chart; on a rotation block the tangent at the
  // estimate anchor ⊕ δ̂ moves by Jr(δ̂)·dδ: Σ ← Jr Σ Jrᵀ there (§12).
  Eigen::Index at = 0;
  for (const auto& k : keys) {
    const Var& v = vars_.at(k);
    const Factor::Rotations rot = rotationsOf(k);
    if (rot.blocks && hasRotationIn(*rot.blocks, v.dim(), rot.offset)) {  // on those 3 rows and columns alone
      const std::vector<Eigen::Matrix3d> Jr = blockRightJacobians(v.delta(), *rot.blocks, rot.offset);
      Eigen::MatrixXd part = S.middleRows(at, v.dim());  // rows: Jr·, then columns: ·Jrᵀ = (Jr·)ᵀ
      premultiplyBlocks(part, Jr, *rot.blocks, rot.offset);
      S.middleRows(at, v.dim()) = part;
      part = S.middleCols(at, v.dim()).transpose();
      premultiplyBlocks(part, Jr, *rot.blocks, rot.offset);
      S.middleCols(at, v.dim()) = part.transpose();
    }
    at += v.dim();
  }
  return S;
}

namespace {
// Y (lower triangular) with Yᵀ = R⁻¹ of an upper-triangular R, by forward
// substitution column by column (RᵀY = I): n³/6 products, none with a zero.
template <class Upper>
void inverseTransposeOfUpper(const Upper& R, Eigen::MatrixXd& Y) {
  const Eigen::Index n = R.rows();
  Y.setIdentity(n, n);
  for (Eigen::Index c = 0; c < n; ++c)
    for (Eigen::Index i = c; i < n; ++i) {
      double v = Y(i, c);
      for (Eigen::Index k = c; k < i; ++k) v -= R(k, i) * Y(k, c);
      Y(i, c) = v / R(i, i);
    }
}

// Σ = YᵀY of a lower-triangular Y: each entry's products summed in one
// order, k upward from max(i, j), so Σ is symmetric as computed (entry
// (j, i) would sum the same products in the same order; it is copied).
Eigen::MatrixXd gramOfLower(const Eigen::MatrixXd& Y) {
  const Eigen::Index n = Y.rows();
  Eigen::MatrixXd S(n, n);
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i <= j; ++i) {
      double v = 0;
      for (Eigen::Index k = j; k < n; ++k) v += Y(k, i) * Y(k, j);
      S(i, j) = S(j, i) = v;
    }
  return S;
}
}  // namespace

// Y with Yᵀ = R⁻¹ of the root clique's conditional, in scratch_.stacked.
const Eigen::MatrixXd& BayesTreeEngine::rootInverse(const Clique& root) const {
  inverseTransposeOfUpper(conditional(root).leftCols(root.dv), scratch_.stacked);
  return scratch_.stacked;
}

void BayesTreeEngine::marginalSd(const Key& k, Eigen::VectorXd& out) const {
  const Var* v = vars_.find(k);
  if (!v) throw InvalidArgument("no variable " + k.toString() + " in the smoother");
  const Clique& c = cliques_[static_cast<std::size_t>(v->clique)];
  if (c.parent >= 0 || rotationsOf(k).blocks) {
    out = pathMarginalCovariance({k}).diagonal().cwiseSqrt();
    return;
  }
  // rootCovariance's diagonal, Σ(i, i) = Σ_k≥i Y(k, i)², by its loops (the same bits).
  const Eigen::MatrixXd& Y = rootInverse(c);
  const Eigen::Index n = Y.rows();
  out.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    double s = 0;
    for (Eigen::Index j = i; j < n; ++j) s += Y(j, i) * Y(j, i);
    out[i] = std::sqrt(s);
  }
}

// One clique, the root (the constants, checked after every update): Σ =
// R⁻¹R⁻ᵀ of its own conditional, densely, without assembling a sparse
// system (8k instructions per fixed-lag update before) or even listing the
// path. Σ = YᵀY (rootInverse) is symmetric as computed (entry (i, j) and
// (j, i) sum the same products).
Eigen::MatrixXd BayesTreeEngine::rootCovariance(const Clique& root) const { return gramOfLower(rootInverse(root)); }

// The union of the requested keys' root paths is closed under parents, so
// its conditionals form a Bayes net on its frontal variables (every
// separator lies above): Σ = (RᵀR)⁻¹ with R block upper triangular in
// elimination order.
Eigen::MatrixXd BayesTreeEngine::bayesNetCovariance(const std::vector<Key>& keys) const {
  std::unordered_set<int> on_path;
  std::vector<int> path;
  for (const auto& k : keys)
    for (int c = vars_.at(k).clique; c >= 0 && on_path.insert(c).second; c = cliques_[static_cast<std::size_t>(c)].parent)
      path.push_back(c);
  std::sort(path.begin(), path.end(), [&](int a, int b) {
    return vars_.at(cliques_[static_cast<std::size_t>(a)].frontal).rank <
           vars_.at(cliques_[static_cast<std::size_t>(b)].frontal).rank;
  });
  std::unordered_map<Key, Eigen::Index, KeyHash> off;
  Eigen::Index n = 0;
  for (int c : path) {
    const Key& f = cliques_[static_cast<std::size_t>(c)].frontal;
    off[f] = n;
    n += vars_.at(f).dim();
  }
  Eigen::Index m = 0;
  bool whole_path = true;  // the keys are the path's variables in its order: E = I
  for (const auto& k : keys) {
    whole_path = whole_path && off.at(k) == m;
    m += vars_.at(k).dim();
  }
  whole_path = whole_path && m == n;
  // Σ = R⁻¹ R⁻ᵀ, so Σ_req = Yᵀ Y with Y = R⁻ᵀ E. A short path (a newest
  // state and the constants: 31 columns, asked for after every update)
  // densely: assembling a sparse R took 3× the solves' time. For the whole
  // path in its order (that newest state and the constants) E = I and Y is
  // triangular: n³/3 products instead of n³ (the drive's 43 columns: ~3×
  // faster; the same to rounding), and no E is formed.
  const auto denseR = [&] {
    Eigen::MatrixXd R = Eigen::MatrixXd::Zero(n, n);
    forEachPathEntry(path, off, [&](Eigen::Index i, Eigen::Index j, double v) { R(i, j) = v; });
    return R;
  };
  Eigen::MatrixXd Y;
  if (n <= kDensePathColumns && whole_path) {
    inverseTransposeOfUpper(denseR(), Y);
    return gramOfLower(Y);
  }
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, m);
  Eigen::Index c = 0;
  for (const auto& k : keys)
    for (Eigen::Index j = 0; j < vars_.at(k).dim(); ++j) E(off.at(k) + j, c++) = 1.0;
  if (n <= kDensePathColumns) {
    Y = denseR().transpose().triangularView<Eigen::Lower>().solve(E);
  } else {
    std::vector<Eigen::Triplet<double>> trip;
    forEachPathEntry(path, off, [&](Eigen::Index i, Eigen::Index j, double v) { trip.emplace_back(i, j, v); });
    Eigen::SparseMatrix<double> R(n, n);
    R.setFromTriplets(trip.begin(), trip.end());
    Y = Eigen::SparseMatrix<double>(R.transpose()).triangularView<Eigen::Lower>().solve(E);
  }
  const Eigen::MatrixXd S = Y.transpose() * Y;
  return 0.5 * (S + S.transpose());
}

template <class Offsets, class Emit>
void BayesTreeEngine::forEachPathEntry(const std::vector<int>& path, const Offsets& off, Emit&& emit) const {
  for (int c : path) {
    const Clique& cl = cliques_[static_cast<std::size_t>(c)];
    const Eigen::Index r0 = off.at(cl.frontal);
    const auto C = conditional(cl);
    const auto R = C.leftCols(cl.dv);
    const auto S = C.middleCols(cl.dv, cl.width);
    for (Eigen::Index i = 0; i < R.rows(); ++i)
      for (Eigen::Index j = i; j < R.cols(); ++j) emit(r0 + i, r0 + j, R(i, j));
    Eigen::Index col = 0;
    for (const auto& k : separator(cl)) {
      const Eigen::Index dk = vars_.at(k).dim();
      const Eigen::Index c0 = off.at(k);
      for (Eigen::Index i = 0; i < S.rows(); ++i)
        for (Eigen::Index j = 0; j < dk; ++j) emit(r0 + i, c0 + j, S(i, col + j));
      col += dk;
    }
  }
}

double BayesTreeEngine::linearizationError(int slot) const {
  const Slot& s = slots_.at(static_cast<std::size_t>(slot));
  if (!s.nonlinear || s.nonlinear.affine(model_)) return 0.0;  // exact: its error is rounding
  Scratch& e = scratch_;
  const LinearView f = slotView(s);
  pointAt(f.keys(), nullptr);  // x̂ = anchor + δ̂
  std::size_t i = 0;
  f.residual([&](const Key&) { return e.factor_vars[i++]->delta(); }, e.rlin, e.term);  // r_lin(δ̂)
  s.nonlinear.linearizeRobustAt(model_, e.x.data(), e.r, nullptr);  // a moved weight is a linearization error too
  return (e.r - e.rlin).norm();
}

std::vector<int> BayesTreeEngine::nonlinearSlots() const {
  std::vector<int> out;
  for (std::size_t i = 0; i < slots_.size(); ++i)
    if (slots_[i].alive && slots_[i].nonlinear) out.push_back(static_cast<int>(i));
  return out;
}

void BayesTreeEngine::appendSlotsOf(const Key& k, std::vector<int>& out) const {
  const Var* v = vars_.find(k);
  if (!v) return;
  for (int s : v->slots)
    if (slots_[static_cast<std::size_t>(s)].alive && slots_[static_cast<std::size_t>(s)].nonlinear) out.push_back(s);
}

double BayesTreeEngine::cost() const {
  double c = 0;
  Eigen::VectorXd r, term;
  auto deltaOf = [&](const Key& k) { return vars_.at(k).delta(); };
  for (const auto& s : slots_) {
    if (!s.alive) continue;
    if (s.nonlinear) {
      pointAt(slotKeys(s), nullptr);
      c += s.nonlinear.linearizeRobustAt(model_, scratch_.x.data(), r, nullptr);  // ½ρ(‖r‖²)
    } else {
      slotView(s).residual(deltaOf, r, term);
      c += 0.5 * r.squaredNorm();
    }
  }
  return c;
}

void BayesTreeEngine::addToNewton(NewtonSystem& sys, const Values& x) const {
  Eigen::VectorXd r, term;
  std::vector<Eigen::MatrixXd> J;
  auto deltaOf = [&](const Key& k) { return vars_.at(k).delta(); };
  auto dimOf = [&](const Key& k) { return vars_.at(k).dim(); };
  for (const auto& s : slots_) {
    if (!s.alive) continue;
    if (s.nonlinear) {
      const FactorPtr f = s.nonlinear.toFactor(model_, slotKeys(s));
      f->linearizeRobust(x, r, &J);
      const Eigen::MatrixXd C = residualCurvature(*f, x, r);
      sys.add(f->keys(), r, J, &C);
    } else {  // r = Σ A δ − b in δ coordinates: J = A, no curvature
      const LinearView f = slotView(s);
      f.residual(deltaOf, r, term);
      sys.add(f.keys().toVector(), r, f.blocks(dimOf), nullptr);
    }
  }
}

void BayesTreeEngine::killSlot(int s) {
  Slot& slot = slots_[static_cast<std::size_t>(s)];
  for (const auto& k : slotKeys(slot)) {
    if (k.isConstants()) continue;
    Var* on = vars_.find(k);
    if (!on) continue;
    auto& v = on->slots;
    v.erase(std::remove(v.begin(), v.end(), s), v.end());
  }
  releaseRecord(slot);
  slot = Slot{};
  free_slots_.push_back(s);
  --slots_alive_;
}

std::vector<Key> BayesTreeEngine::below(const Key& k) const {
  std::vector<Key> out;
  const Var* v = vars_.find(k);
  if (!v) return out;
  // Post-order over the subtree under k's clique (an explicit stack: a long
  // subtree must not recurse deeply).
  std::vector<std::pair<int, bool>> stack;
  for (int ch : cliques_[static_cast<std::size_t>(v->clique)].children) stack.emplace_back(ch, false);
  while (!stack.empty()) {
    auto [c, expanded] = stack.back();
    stack.pop_back();
    if (expanded) {
      out.push_back(cliques_[static_cast<std::size_t>(c)].frontal);
      continue;
    }
    stack.emplace_back(c, true);
    for (int ch : cliques_[static_cast<std::size_t>(c)].children) stack.emplace_back(ch, false);
  }
  return out;
}

std::vector<int> BayesTreeEngine::slotsBetween(const Key& a, const Key& b) const {
  std::vector<int> out;
  const Var* va = vars_.find(a);
  if (!va || !vars_.contains(b)) return out;
  for (int s : va->slots) {
    const auto keys = slotKeys(slots_[static_cast<std::size_t>(s)]);
    if (slots_[static_cast<std::size_t>(s)].alive && std::find(keys.begin(), keys.end(), b) != keys.end())
      out.push_back(s);
  }
  return out;
}

void BayesTreeEngine::marginalizeLeaf(const Key& key) {
  const Var* var = vars_.find(key);
  if (!var) throw InvalidArgument("marginalize: no variable " + key.toString());
  const int c = var->clique;
  Clique& cl = cliques_[static_cast<std::size_t>(c)];
  if (!cl.children.empty())
    throw NumericalError("marginalize: " + key.toString() +
                         " is not a leaf of the Bayes tree (internal ordering error)");
  const int parent = cl.parent;
  // Drop the factors this clique consumed; they are summarized by its marginal.
  for (int s : cl.owned) killSlot(s);
  // Its marginal on the separator becomes a fixed linear prior (first-estimate
  // Jacobians), owned by the parent, which consumed it when it was eliminated.
  if (parent >= 0 && cl.mrows > 0) {
    const int s = allocSlot();
    Slot& slot = slots_[static_cast<std::size_t>(s)];
    storeLinearization(slot, marginalView(cl));  // unpacked: a slot's linearization is dense
    slot.owner = parent;
    slot.alive = true;
    indexSlot(s);
    cliques_[static_cast<std::size_t>(parent)].owned.push_back(s);
  }
  if (parent >= 0) {
    auto& ch = cliques_[static_cast<std::size_t>(parent)].children;
    ch.erase(std::remove(ch.begin(), ch.end(), c), ch.end());
  } else {
    root_ = -1;
  }
  releaseRecord(cliques_[static_cast<std::size_t>(c)]);
  clique_alive_[static_cast<std::size_t>(c)] = false;
  free_cliques_.push_back(c);
  --cliques_alive_;
  vars_.erase(key);
}

}  // namespace gssm::internal
