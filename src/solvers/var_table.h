#pragma once
// Internal: the variables of the Bayes tree engine, by key. A run adds the
// states step after step and a fixed lag removes the oldest, so states live
// in an array indexed by step (a hash map spent ~170 bytes a step on nodes,
// buckets and an index map beside it: a tenth of a full-history run's
// memory); the constants apart; a state far from the others (a user's graph
// may skip steps) in a hash map, so no gap is ever filled.
#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <deque>
#include <stdexcept>
#include <unordered_map>

#include "gssm/core/key.h"
#include "solvers/small_list.h"

namespace gssm::internal {

/// One variable: x = anchor + δ (anchor and δ side by side, inline for a
/// scalar state), the clique it is the frontal variable of, its elimination
/// rank and, for a state, the factor slots on it.
class EngineVar {
 public:
  EngineVar() = default;
  /// anchor = x0, δ = 0.
  explicit EngineVar(const Eigen::VectorXd& x0) {
    values_.resize(2 * static_cast<std::size_t>(x0.size()), 0.0);
    anchor() = x0;
  }

  /// 0 for an empty entry (no variable).
  Eigen::Index dim() const { return static_cast<Eigen::Index>(values_.size() / 2); }
  Eigen::Map<Eigen::VectorXd> anchor() { return {values_.begin(), dim()}; }
  Eigen::Map<const Eigen::VectorXd> anchor() const { return {values_.begin(), dim()}; }
  Eigen::Map<Eigen::VectorXd> delta() { return {values_.begin() + dim(), dim()}; }
  Eigen::Map<const Eigen::VectorXd> delta() const { return {values_.begin() + dim(), dim()}; }
  /// anchor + δ.
  Eigen::VectorXd estimate() const { return anchor() + delta(); }

 private:
  SmallList<double, 2> values_;  // [anchor; δ]

 public:
  int clique = -1;
  std::int64_t rank = 0;  // elimination rank: larger = closer to the root
  SmallIntList slots;     // factor slots on this state (none kept for the constants)
};

class VarTable {
 public:
  EngineVar* find(const Key& k) { return const_cast<EngineVar*>(static_cast<const VarTable*>(this)->find(k)); }
  const EngineVar* find(const Key& k) const {
    if (k == Key::constants()) return constants_.dim() ? &constants_ : nullptr;
    if (!k.isConstants() && k.step >= first_ && k.step - first_ < static_cast<std::int64_t>(states_.size())) {
      const EngineVar& v = states_[static_cast<std::size_t>(k.step - first_)];
      if (v.dim()) return &v;
    }
    return far_.empty() ? nullptr : findFar(k);
  }
  bool contains(const Key& k) const { return find(k) != nullptr; }
  EngineVar& at(const Key& k) { return const_cast<EngineVar&>(static_cast<const VarTable*>(this)->at(k)); }
  const EngineVar& at(const Key& k) const {
    const EngineVar* v = find(k);
    if (!v) throw std::out_of_range("no engine variable " + k.toString());
    return *v;
  }
  std::size_t size() const { return size_; }

  /// Adds k, which must be absent, with a non-empty value.
  EngineVar& insert(const Key& k, EngineVar v) {
    if (contains(k) || v.dim() == 0) throw std::logic_error("VarTable: " + k.toString() + " present or empty");
    ++size_;
    if (k == Key::constants()) return constants_ = std::move(v);
    if (!k.isConstants()) {
      const auto n = static_cast<std::int64_t>(states_.size());
      const std::int64_t reach = std::max<std::int64_t>(kGap, n);  // gaps up to this are filled
      if (n == 0) {
        first_ = k.step;
        states_.emplace_back();
      } else if (k.step >= first_ + n && k.step - (first_ + n) <= reach) {
        states_.resize(static_cast<std::size_t>(k.step - first_ + 1));
      } else if (k.step < first_ && first_ - k.step <= reach) {
        for (std::int64_t s = first_; s > k.step; --s) states_.emplace_front();
        first_ = k.step;
      }
      if (k.step >= first_ && k.step - first_ < static_cast<std::int64_t>(states_.size()))
        return states_[static_cast<std::size_t>(k.step - first_)] = std::move(v);
    }
    return far_[k] = std::move(v);
  }

  /// Removes k if present (a state at either end of the array shrinks it).
  void erase(const Key& k) {
    EngineVar* v = find(k);
    if (!v) return;
    --size_;
    if (v == &constants_) {
      constants_ = EngineVar();
      return;
    }
    if (!far_.empty() && far_.erase(k)) return;
    *v = EngineVar();
    while (!states_.empty() && !states_.front().dim()) {
      states_.pop_front();
      ++first_;
    }
    while (!states_.empty() && !states_.back().dim()) states_.pop_back();
  }

  /// f(key, var) for every variable: states of the array by step, then the
  /// far ones, then the constants.
  template <class F>
  void forEach(F&& f) const {
    visit(*this, f);
  }
  template <class F>
  void forEach(F&& f) {
    visit(*this, f);
  }

 private:
  // Out of line: the inline lookup stays small enough to be inlined.
  __attribute__((noinline)) const EngineVar* findFar(const Key& k) const {
    const auto it = far_.find(k);
    return it == far_.end() ? nullptr : &it->second;
  }
  // forEach's walk for a const and a mutable table alike.
  template <class Table, class F>
  static void visit(Table& t, F& f) {
    for (std::size_t i = 0; i < t.states_.size(); ++i)
      if (t.states_[i].dim()) f(Key::state(t.first_ + static_cast<std::int64_t>(i)), t.states_[i]);
    for (auto& kv : t.far_) f(kv.first, kv.second);
    if (t.constants_.dim()) f(Key::constants(), t.constants_);
  }
  static constexpr std::int64_t kGap = 1024;
  std::deque<EngineVar> states_;  // step first_ + i; dim() == 0: no variable
  std::int64_t first_ = 0;
  std::unordered_map<Key, EngineVar, KeyHash> far_;
  EngineVar constants_;
  std::size_t size_ = 0;
};

}  // namespace gssm::internal
