#pragma once
// Values: the current estimate of every variable in a graph.
#include <Eigen/Core>
#include <map>

#include "gssm/key.h"

namespace gssm {

class Values {
 public:
  bool contains(const Key& k) const { return map_.count(k) != 0; }
  /// Throws InvalidArgument naming the key when it is absent.
  const Eigen::VectorXd& at(const Key& k) const;
  Eigen::VectorXd& at(const Key& k);
  void insert(const Key& k, const Eigen::VectorXd& v);  ///< throws if present
  void insertOrAssign(const Key& k, const Eigen::VectorXd& v) { map_[k] = v; }
  void erase(const Key& k) { map_.erase(k); }
  std::size_t size() const { return map_.size(); }
  bool empty() const { return map_.empty(); }
  /// Total dimension of all variables.
  Eigen::Index dim() const;

  auto begin() const { return map_.begin(); }
  auto end() const { return map_.end(); }
  auto begin() { return map_.begin(); }
  auto end() { return map_.end(); }

 private:
  std::map<Key, Eigen::VectorXd> map_;
};

}  // namespace gssm
