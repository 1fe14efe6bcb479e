#pragma once
// Internal: the nonlinear factor behind a factor slot of the Bayes tree
// engine. A model's process and measurement factors — all but a handful of
// a run's — are held as their numbers (noise, loss, Δt and input, or
// measurement and channel; the keys are the slot's linearization's, the
// model the engine's: every call names it) and evaluated by the same code as
// ProcessFactor and MeasurementFactor (factors/model_factors.h): a
// full-history run keeps two per step, and as objects each took ~170 bytes
// (the object, its key vector, its measurement vector); held so, 40 bytes.
// Any other factor, and another model's, is kept as it is.
#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "gssm/factors/factors.h"
#include "solvers/small_list.h"

namespace gssm::internal {

class SlotFactor {
 public:
  /// None: the slot holds a fixed linear factor.
  SlotFactor() {}
  /// A ProcessFactor or MeasurementFactor of `model` taken apart; any other
  /// factor kept.
  SlotFactor(const FactorPtr& f, const Model* model);
  /// The model of a ProcessFactor or MeasurementFactor; null for any other.
  static const Model* modelOf(const FactorPtr& f);
  SlotFactor(const SlotFactor& o) : SlotFactor() { copyFrom(o); }
  SlotFactor(SlotFactor&& o) noexcept : SlotFactor() { moveFrom(o); }
  SlotFactor& operator=(const SlotFactor& o) {
    if (this != &o) {
      reset();
      copyFrom(o);
    }
    return *this;
  }
  SlotFactor& operator=(SlotFactor&& o) noexcept {
    if (this != &o) {
      reset();
      moveFrom(o);
    }
    return *this;
  }
  ~SlotFactor() { reset(); }

  explicit operator bool() const { return kind_ != Kind::None; }
  /// Residual dimension (`model`: the one it was made with, in each call below).
  int dim(const Model* model) const;
  /// Whether `keys` are the factor's: an object's own, a process factor's
  /// x_c(k), x_c(k+1) (then x_b if the model has constants), a
  /// measurement's x_c(k) (then x_b).
  template <class Keys>
  bool fitsKeys(const Model* model, const Keys& keys) const {
    if (kind_ == Kind::Object) return object_->keys().size() == keys.size() &&
                                      std::equal(keys.begin(), keys.end(), object_->keys().begin());
    if (kind_ == Kind::None || keys.size() == 0) return false;
    // x_c(k), then for a process factor another state (x_c(k+1), or an
    // inserted one on either side), then x_b if there are constants.
    const std::size_t states = kind_ == Kind::Process ? 2 : 1;
    if (keys.size() != states + (model->dims().nb > 0 ? 1 : 0)) return false;
    std::size_t i = 0;
    for (const Key& k : keys) {
      if (k.isConstants() != (i >= states)) return false;
      ++i;
    }
    return states == 1 || *keys.begin() != *(keys.begin() + 1);
  }
  /// Its linearization is exact everywhere (Model::processIsAffine, an affine
  /// channel without a loss): no linearization check needed.
  bool affine(const Model* model) const {
    if (kind_ == Kind::Process) return model->processIsAffine();
    if (kind_ == Kind::Measurement)
      return loss_kind_ == static_cast<std::uint8_t>(RobustLoss::Kind::None) && model->measurementIsAffine(channel_);
    return false;
  }
  /// What Factor::linearizeRobustAt returns for the factor it was made from,
  /// with its variables' values in key order.
  double linearizeRobustAt(const Model* model, const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                           std::vector<Eigen::MatrixXd>* J) const;
  /// The factor as an object again, on `keys` (its slot's), for what needs
  /// one: curvature terms, checkpoints, messages.
  template <class Keys>
  FactorPtr toFactor(const Model* model, const Keys& keys) const {
    if (kind_ == Kind::Process && keys.size() >= 2) {  // between any two states (an inserted one)
      const Key from = *keys.begin(), to = *(keys.begin() + 1);
      if (from.step < 0 || to.step != from.step + 1) return toProcessBetween(model, from, to);
    }
    return toFactorAt(model, keys.size() > 0 ? keys.begin()->step : 0);
  }

 private:
  enum class Kind : std::uint8_t { None, Object, Process, Measurement };
  struct Step {
    double dt;
    Eigen::VectorXd u;  // empty without inputs: no heap block
  };
  struct Observation {
    SmallList<double, 1> y;  // a scalar measurement inline
    double loss_scale;
  };
  FactorPtr toFactorAt(const Model* model, std::int64_t step) const;  // a model factor's at its first state's step
  FactorPtr toProcessBetween(const Model* model, Key from, Key to) const;
  void reset();
  void copyFrom(const SlotFactor& o);
  void moveFrom(SlotFactor& o);
  RobustLoss loss() const { return {static_cast<RobustLoss::Kind>(loss_kind_), observation_.loss_scale}; }

  Kind kind_ = Kind::None;
  std::uint8_t loss_kind_ = 0;       // Measurement: the factor's loss (its scale in observation_)
  std::int32_t channel_ = 0;         // Measurement
  GaussianNoise noise_;              // Process, Measurement
  union {
    FactorPtr object_;               // Object
    Step step_;                      // Process
    Observation observation_;        // Measurement
  };
};

}  // namespace gssm::internal
