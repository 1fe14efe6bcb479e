#pragma once
// Internal: the nonlinear factor behind a factor slot of the Bayes tree
// engine. A model's process and measurement factors — all but a handful of
// a run's — are held as their numbers (model, noise, Δt and input, or
// measurement and channel; the keys are the slot's linearization's) and
// evaluated by the same code as ProcessFactor and MeasurementFactor
// (factors/model_factors.h): a full-history run keeps two per step, and as
// objects each took ~170 bytes (the object, its key vector, its
// measurement vector). Any other factor is kept as it is.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "gssm/factors/factors.h"
#include "solvers/small_list.h"

namespace gssm::internal {

class SlotFactor {
 public:
  /// None: the slot holds a fixed linear factor.
  SlotFactor() = default;
  /// A ProcessFactor or MeasurementFactor taken apart; any other factor kept.
  explicit SlotFactor(const FactorPtr& f);

  explicit operator bool() const { return kind_ != Kind::None; }
  /// Residual dimension.
  int dim() const;
  /// What Factor::linearizeRobustAt returns for the factor it was made from,
  /// with its variables' values in key order.
  double linearizeRobustAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                           std::vector<Eigen::MatrixXd>* J) const;
  /// The factor as an object again, on `keys` (its slot's), for what needs
  /// one: curvature terms, checkpoints, messages.
  FactorPtr toFactor(const std::vector<Key>& keys) const;
  template <class Keys>
  FactorPtr toFactor(const Keys& keys) const {
    return toFactor(std::vector<Key>(keys.begin(), keys.end()));
  }

 private:
  enum class Kind : std::uint8_t { None, Object, Process, Measurement };
  Kind kind_ = Kind::None;
  std::int32_t channel_ = 0;         // Measurement
  const Model* model_ = nullptr;     // Process, Measurement
  FactorPtr object_;                 // Object
  GaussianNoise noise_;              // Process, Measurement
  Eigen::VectorXd u_;                // Process (empty without inputs: no heap block)
  SmallList<double, 2> numbers_;     // Process: Δt; Measurement: y
  RobustLoss loss_;                  // as the factor had it (Process: none)
};

}  // namespace gssm::internal
