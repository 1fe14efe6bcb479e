#pragma once
// Values: the current estimate of every variable in a graph.
//
// Stored as one vector of (key, value) entries sorted by Key (states by step,
// constants last), so iteration is in elimination order and a lookup of
// x_c(k) in a run of consecutive steps is one index computation: a
// million-step batch solve looks up three values per factor per iteration,
// and a balanced tree's cache misses were 16% of its time. Appending the
// next step (or anything just before the constants) is O(1); inserting or
// erasing in the middle moves the entries after it.
#include <Eigen/Core>
#include <utility>
#include <vector>

#include "gssm/core/key.h"

namespace gssm {

class Values {
 public:
  using Entry = std::pair<Key, Eigen::VectorXd>;

  bool contains(const Key& k) const { return find(k) != npos; }
  /// Throws InvalidArgument naming the key when it is absent.
  const Eigen::VectorXd& at(const Key& k) const;
  Eigen::VectorXd& at(const Key& k);
  void insert(const Key& k, const Eigen::VectorXd& v);  ///< throws if present
  void insert(const Key& k, Eigen::VectorXd&& v);       ///< the same, taking v's storage
  void insertOrAssign(const Key& k, const Eigen::VectorXd& v);
  void erase(const Key& k);
  std::size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  void reserve(std::size_t n) { entries_.reserve(n); }
  /// Position of k in iteration order (throws InvalidArgument if absent).
  std::size_t indexOf(const Key& k) const;
  /// Total dimension of all variables.
  Eigen::Index dim() const;
  /// Entries in Key order. Through the non-const iterators change values
  /// only, never keys.
  auto begin() const { return entries_.cbegin(); }
  auto end() const { return entries_.cend(); }
  auto begin() { return entries_.begin(); }
  auto end() { return entries_.end(); }

 private:
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);
  std::size_t find(const Key& k) const;
  std::size_t lowerBound(const Key& k) const;
  std::vector<Entry> entries_;
};

}  // namespace gssm
