#include "gssm/core/values.h"

#include <algorithm>

#include "gssm/core/error.h"

namespace gssm {

std::size_t Values::lowerBound(const Key& k) const {
  return static_cast<std::size_t>(
      std::lower_bound(entries_.begin(), entries_.end(), k,
                       [](const Entry& e, const Key& key) { return e.first < key; }) -
      entries_.begin());
}

std::size_t Values::find(const Key& k) const {
  if (entries_.empty()) return npos;
  // Fast paths: the constants are last; consecutive steps sit at step − first step.
  if (k.isConstants()) return entries_.back().first == k ? entries_.size() - 1 : npos;
  const Key& first = entries_.front().first;
  if (!first.isConstants() && k.step >= first.step) {
    const auto guess = static_cast<std::uint64_t>(k.step - first.step);
    if (guess < entries_.size() && entries_[guess].first == k) return static_cast<std::size_t>(guess);
  }
  const std::size_t i = lowerBound(k);
  return i < entries_.size() && entries_[i].first == k ? i : npos;
}

const Eigen::VectorXd& Values::at(const Key& k) const {
  const std::size_t i = find(k);
  if (i == npos) throw InvalidArgument("Values: no value for variable " + k.toString());
  return entries_[i].second;
}

std::size_t Values::indexOf(const Key& k) const {
  const std::size_t i = find(k);
  if (i == npos) throw InvalidArgument("Values: no value for variable " + k.toString());
  return i;
}

Eigen::VectorXd& Values::at(const Key& k) {
  const std::size_t i = find(k);
  if (i == npos) throw InvalidArgument("Values: no value for variable " + k.toString());
  return entries_[i].second;
}

void Values::insert(const Key& k, const Eigen::VectorXd& v) { insert(k, Eigen::VectorXd(v)); }

void Values::insert(const Key& k, Eigen::VectorXd&& v) {
  // Common cases first: appending the next step, or a step before the constants.
  if (entries_.empty() || entries_.back().first < k) {
    entries_.emplace_back(k, std::move(v));
    return;
  }
  const std::size_t i = lowerBound(k);
  if (entries_[i].first == k)
    throw InvalidArgument("Values: variable " + k.toString() + " already has a value");
  entries_.insert(entries_.begin() + static_cast<std::ptrdiff_t>(i), Entry(k, std::move(v)));
}

void Values::insertOrAssign(const Key& k, const Eigen::VectorXd& v) {
  const std::size_t i = find(k);
  if (i != npos) entries_[i].second = v;
  else insert(k, v);
}

void Values::erase(const Key& k) {
  const std::size_t i = find(k);
  if (i != npos) entries_.erase(entries_.begin() + static_cast<std::ptrdiff_t>(i));
}

Eigen::Index Values::dim() const {
  Eigen::Index n = 0;
  for (const auto& kv : entries_) n += kv.second.size();
  return n;
}

}  // namespace gssm
