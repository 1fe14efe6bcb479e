#include "solvers/anderson.h"

#include <Eigen/QR>

namespace gssm::internal {

void AndersonMixing::reset() {
  dF_.clear();
  dX_.clear();
  has_pending_ = has_last_ = false;
}

bool AndersonMixing::mix(const Eigen::VectorXd& f, const Eigen::VectorXd& w, Eigen::VectorXd& step) {
  step = f;
  if (memory_ <= 0) return false;
  if (has_last_) {  // the step from the last point was kept: one more difference
    dF_.push_back(f - f_last_);
    dX_.push_back(taken_last_);
    if (static_cast<int>(dF_.size()) > memory_) {
      dF_.erase(dF_.begin());
      dX_.erase(dX_.begin());
    }
    has_last_ = false;
  }
  f_pending_ = f;
  has_pending_ = true;
  if (dF_.empty()) return false;
  const auto k = static_cast<Eigen::Index>(dF_.size());
  const Eigen::ArrayXd sqrt_w = w.array().max(0.0).sqrt();
  Eigen::MatrixXd A(f.size(), k);
  for (Eigen::Index i = 0; i < k; ++i) A.col(i) = (sqrt_w * dF_[static_cast<std::size_t>(i)].array()).matrix();
  // Rank-revealing: two differences along one direction (the slow one, once
  // the others died out) give that direction one coefficient, not two huge
  // ones of opposite sign.
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  qr.setThreshold(1e-10);
  const Eigen::VectorXd gamma = qr.solve((sqrt_w * f.array()).matrix());
  if (!gamma.allFinite()) return false;
  for (Eigen::Index i = 0; i < k; ++i) {
    const auto j = static_cast<std::size_t>(i);
    step -= gamma[i] * (dX_[j] + dF_[j]);
  }
  return true;
}

void AndersonMixing::accepted(const Eigen::VectorXd& taken) {
  if (!has_pending_) return;
  f_last_.swap(f_pending_);
  taken_last_ = taken;
  has_pending_ = false;
  has_last_ = true;
}

}  // namespace gssm::internal
