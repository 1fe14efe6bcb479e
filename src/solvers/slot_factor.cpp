#include "solvers/slot_factor.h"

#include "factors/model_factors.h"

namespace gssm::internal {

SlotFactor::SlotFactor(const FactorPtr& f) {
  if (!f) return;
  if (const auto* p = dynamic_cast<const ProcessFactor*>(f.get())) {
    kind_ = Kind::Process;
    model_ = &p->model();
    noise_ = p->noise();
    u_ = p->input();
    const double dt = p->dt();
    numbers_.assign(&dt, &dt + 1);
  } else if (const auto* m = dynamic_cast<const MeasurementFactor*>(f.get())) {
    kind_ = Kind::Measurement;
    model_ = &m->model();
    noise_ = m->noise();
    channel_ = m->channel();
    loss_ = m->loss();
    numbers_.assign(m->measurement().data(), m->measurement().data() + m->measurement().size());
  } else {
    kind_ = Kind::Object;
    object_ = f;
  }
}

int SlotFactor::dim() const {
  switch (kind_) {
    case Kind::None: return 0;
    case Kind::Object: return object_->dim();
    case Kind::Process: return model_->dims().nc;
    case Kind::Measurement: return model_->channel(channel_).dim();
  }
  return 0;
}

double SlotFactor::linearizeRobustAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                                     std::vector<Eigen::MatrixXd>* J) const {
  switch (kind_) {
    case Kind::None: break;
    case Kind::Object: return object_->linearizeRobustAt(x, r, J);
    case Kind::Process:
      processResidual(*model_, u_, numbers_[0], noise_, x, r, J);
      return robustify(loss_, r, J);
    case Kind::Measurement: {
      const Eigen::Map<const Eigen::VectorXd> y(numbers_.begin(), static_cast<Eigen::Index>(numbers_.size()));
      measurementResidual(*model_, channel_, y, noise_, x, r, J);
      return robustify(loss_, r, J);
    }
  }
  r.resize(0);
  return 0.0;
}

FactorPtr SlotFactor::toFactor(const std::vector<Key>& keys) const {
  switch (kind_) {
    case Kind::None: break;
    case Kind::Object: return object_;
    case Kind::Process: return std::make_shared<ProcessFactor>(*model_, keys.at(0).step, u_, numbers_[0], noise_);
    case Kind::Measurement: {
      const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(numbers_.begin(), static_cast<Eigen::Index>(numbers_.size()));
      return std::make_shared<MeasurementFactor>(*model_, keys.at(0).step, y, channel_, noise_);
    }
  }
  return nullptr;
}

}  // namespace gssm::internal
