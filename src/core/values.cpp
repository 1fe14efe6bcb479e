#include "gssm/values.h"

#include "gssm/error.h"

namespace gssm {

const Eigen::VectorXd& Values::at(const Key& k) const {
  auto it = map_.find(k);
  if (it == map_.end()) throw InvalidArgument("Values: no value for variable " + k.toString());
  return it->second;
}

Eigen::VectorXd& Values::at(const Key& k) {
  auto it = map_.find(k);
  if (it == map_.end()) throw InvalidArgument("Values: no value for variable " + k.toString());
  return it->second;
}

void Values::insert(const Key& k, const Eigen::VectorXd& v) {
  if (!map_.emplace(k, v).second)
    throw InvalidArgument("Values: variable " + k.toString() + " already has a value");
}

Eigen::Index Values::dim() const {
  Eigen::Index n = 0;
  for (const auto& kv : map_) n += kv.second.size();
  return n;
}

}  // namespace gssm
