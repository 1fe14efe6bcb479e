#include "solvers/slot_factor.h"

#include <new>
#include <type_traits>
#include <typeinfo>

#include "factors/model_factors.h"

namespace gssm::internal {

namespace {
// f as a T (a final class: its exact type is the only match), by one type
// comparison instead of dynamic_cast's walk of the hierarchy (two per new
// factor of every update).
template <class T>
const T* exactly(const Factor* f) {
  static_assert(std::is_final_v<T>);
  return f && typeid(*f) == typeid(T) ? static_cast<const T*>(f) : nullptr;
}
}  // namespace

const Model* SlotFactor::modelOf(const FactorPtr& f) {
  if (const auto* p = exactly<ProcessFactor>(f.get())) return &p->model();
  if (const auto* m = exactly<MeasurementFactor>(f.get())) return &m->model();
  return nullptr;
}

SlotFactor::SlotFactor(const FactorPtr& f, const Model* model) : SlotFactor() {
  if (!f) return;
  const auto* p = exactly<ProcessFactor>(f.get());
  const auto* m = p ? nullptr : exactly<MeasurementFactor>(f.get());
  if (p && &p->model() == model) {
    noise_ = p->noise();
    new (&step_) Step{p->dt(), p->input()};
    kind_ = Kind::Process;
  } else if (m && &m->model() == model && m->regressors().size() == 0) {  // else: kept whole
    noise_ = m->noise();
    channel_ = m->channel();
    loss_kind_ = static_cast<std::uint8_t>(m->loss().kind);
    new (&observation_) Observation{{}, m->loss().scale};
    observation_.y.assign(m->measurement().data(), m->measurement().data() + m->measurement().size());
    kind_ = Kind::Measurement;
  } else {
    new (&object_) FactorPtr(f);
    kind_ = Kind::Object;
  }
}

void SlotFactor::reset() {
  switch (kind_) {
    case Kind::None: break;
    case Kind::Object: object_.~FactorPtr(); break;
    case Kind::Process: step_.~Step(); break;
    case Kind::Measurement: observation_.~Observation(); break;
  }
  kind_ = Kind::None;
}

void SlotFactor::copyFrom(const SlotFactor& o) {
  loss_kind_ = o.loss_kind_;
  channel_ = o.channel_;
  noise_ = o.noise_;
  switch (o.kind_) {
    case Kind::None: break;
    case Kind::Object: new (&object_) FactorPtr(o.object_); break;
    case Kind::Process: new (&step_) Step(o.step_); break;
    case Kind::Measurement: new (&observation_) Observation(o.observation_); break;
  }
  kind_ = o.kind_;
}

void SlotFactor::moveFrom(SlotFactor& o) {
  loss_kind_ = o.loss_kind_;
  channel_ = o.channel_;
  noise_ = std::move(o.noise_);
  switch (o.kind_) {
    case Kind::None: break;
    case Kind::Object: new (&object_) FactorPtr(std::move(o.object_)); break;
    case Kind::Process: new (&step_) Step(std::move(o.step_)); break;
    case Kind::Measurement: new (&observation_) Observation(std::move(o.observation_)); break;
  }
  kind_ = o.kind_;
  o.reset();
}

int SlotFactor::dim(const Model* model) const {
  switch (kind_) {
    case Kind::None: return 0;
    case Kind::Object: return object_->dim();
    case Kind::Process: return model->dims().nc;
    case Kind::Measurement: return model->channel(channel_).dim();
  }
  return 0;
}

double SlotFactor::linearizeRobustAt(const Model* model, const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                                     std::vector<Eigen::MatrixXd>* J) const {
  switch (kind_) {
    case Kind::None: break;
    case Kind::Object: return object_->linearizeRobustAt(x, r, J);
    case Kind::Process:
      processResidual(*model, step_.u, step_.dt, noise_, x, r, J);
      return robustify(RobustLoss{}, r, J);  // a process factor has no loss
    case Kind::Measurement: {
      const auto& y_ = observation_.y;
      const Eigen::Map<const Eigen::VectorXd> y(y_.begin(), static_cast<Eigen::Index>(y_.size()));
      measurementResidual(*model, channel_, y, noise_, x, r, J);
      return robustify(loss(), r, J);
    }
  }
  r.resize(0);
  return 0.0;
}

FactorPtr SlotFactor::toProcessBetween(const Model* model, Key from, Key to) const {
  return std::make_shared<ProcessFactor>(*model, from, to, step_.u, step_.dt, noise_);
}

FactorPtr SlotFactor::toFactorAt(const Model* model, std::int64_t step) const {
  switch (kind_) {
    case Kind::None: break;
    case Kind::Object: return object_;
    case Kind::Process: return std::make_shared<ProcessFactor>(*model, step, step_.u, step_.dt, noise_);
    case Kind::Measurement: {
      const auto& y_ = observation_.y;
      const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(y_.begin(), static_cast<Eigen::Index>(y_.size()));
      return std::make_shared<MeasurementFactor>(*model, step, y, channel_, noise_);
    }
  }
  return nullptr;
}

}  // namespace gssm::internal
