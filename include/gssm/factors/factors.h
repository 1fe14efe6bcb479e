#pragma once
// Factors of the GSSM graph (docs/DESIGN.md §1, eqs. 2–4). Each returns a whitened residual
// r = L⁻¹ e (Σ = L Lᵀ) and one Jacobian block per variable, so that the MAP
// estimate minimizes ½ Σ ‖r_i‖² over all factors.
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "gssm/core/gaussian.h"
#include "gssm/core/key.h"
#include "gssm/core/data.h"
#include "gssm/model/model.h"
#include "gssm/core/values.h"

namespace gssm {

class Factor {
 public:
  virtual ~Factor() = default;
  const std::vector<Key>& keys() const { return keys_; }
  /// Residual dimension.
  int dim() const { return dim_; }

  /// Whitened residual at `x`; when J is non-null it receives one block per
  /// key, J[i] of size dim() × dim(keys()[i]). Throws InvalidArgument naming
  /// a key that `x` lacks.
  void linearize(const Values& x, Eigen::VectorXd& r, std::vector<Eigen::MatrixXd>* J) const;
  /// The same with the variables' values given in keys() order (*x[i] is
  /// keys()[i]'s), for a solver that holds them by position: no lookups.
  virtual void linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                           std::vector<Eigen::MatrixXd>* J) const = 0;
  /// What the solvers minimize: linearize() with r and J scaled by √ρ'(s),
  /// s = ‖r‖², for a factor with a robust loss (iteratively reweighted least
  /// squares, core/robust_loss.h); returns the cost ½ρ(s).
  double linearizeRobust(const Values& x, Eigen::VectorXd& r, std::vector<Eigen::MatrixXd>* J) const;
  /// linearizeRobust() with the variables in keys() order, as linearizeAt().
  double linearizeRobustAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                           std::vector<Eigen::MatrixXd>* J) const;
  /// ½ρ(‖r(x)‖²) (½‖r(x)‖² without a robust loss).
  double cost(const Values& x) const;
  /// ρ'(‖r(x)‖²) at x: 1 without a loss; below 1 where a loss down-weights.
  double weight(const Values& x) const;
  const RobustLoss& loss() const { return loss_; }
  /// Human-readable description naming the variables ("range at x_c(12)").
  virtual std::string describe() const = 0;
  /// The columns of keys()[a]'s Jacobian block that can be nonzero,
  /// ascending; nullptr: any. A solver may skip the others (they are zero at
  /// every point).
  virtual const std::vector<int>* columnsOf(std::size_t /*a*/) const { return nullptr; }
  /// Where keys()[a] holds rotations (docs/DESIGN.md §12): the stacked
  /// first components of its rotation blocks and the stacked index its
  /// vector starts at; a solver moves it by ⊕ there. `blocks` null: none.
  struct Rotations {
    const std::vector<int>* blocks = nullptr;
    int offset = 0;
  };
  virtual Rotations rotationsOf(std::size_t /*a*/) const { return {}; }

 protected:
  Factor(std::vector<Key> keys, int dim, RobustLoss loss = {})
      : keys_(std::move(keys)), dim_(dim), loss_(loss) {}

 private:
  double robustify(Eigen::VectorXd& r, std::vector<Eigen::MatrixXd>* J) const;
  std::vector<Key> keys_;
  int dim_;
  RobustLoss loss_;
};

using FactorPtr = std::shared_ptr<const Factor>;

/// E[x] = mean with covariance Σ: r = L⁻¹ (x ⊖ mean), the listed angle
/// components wrapped to (−π, π], ⊖ on the listed rotation blocks (first
/// components; docs/DESIGN.md §12), − elsewhere.
class PriorFactor final : public Factor {
 public:
  PriorFactor(Key key, const Gaussian& prior, std::vector<int> angles = {}, std::vector<int> rotations = {});
  void linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                   std::vector<Eigen::MatrixXd>* J) const override;
  std::string describe() const override;
  const Eigen::VectorXd& mean() const { return mean_; }
  const GaussianNoise& noise() const { return noise_; }
  const std::vector<int>& angles() const { return angles_; }
  const std::vector<int>& rotations() const { return rotations_; }
  Rotations rotationsOf(std::size_t) const override { return {rotations_.empty() ? nullptr : &rotations_, 0}; }

 private:
  Eigen::VectorXd mean_;
  GaussianNoise noise_;
  std::vector<int> angles_;
  std::vector<int> rotations_;
};

/// x_c(k+1) = f(x_c(k), x_b, u_k, dt) + q:  r = L_Q⁻¹ (x_c(k+1) − f(...)),
/// angle states wrapped. The model must outlive the factor.
class ProcessFactor final : public Factor {
 public:
  ProcessFactor(const Model& model, std::int64_t k, const Eigen::VectorXd& u, double dt);
  /// With an explicit noise model (a solver that held the factor as its numbers).
  ProcessFactor(const Model& model, std::int64_t k, const Eigen::VectorXd& u, double dt, const GaussianNoise& noise);
  /// Between any two states (a state inserted into the chain for a late
  /// measurement: x_c(j) → x(t) → x_c(j+1)).
  ProcessFactor(const Model& model, Key from, Key to, const Eigen::VectorXd& u, double dt);
  ProcessFactor(const Model& model, Key from, Key to, const Eigen::VectorXd& u, double dt, const GaussianNoise& noise);
  void linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                   std::vector<Eigen::MatrixXd>* J) const override;
  std::string describe() const override;
  double dt() const { return dt_; }
  const Eigen::VectorXd& input() const { return u_; }
  const GaussianNoise& noise() const { return noise_; }
  const Model& model() const { return *model_; }
  Rotations rotationsOf(std::size_t a) const override;

 private:
  const Model* model_;
  Eigen::VectorXd u_;
  double dt_;
  GaussianNoise noise_;
};

/// y = h_c(x_c(k), x_b) + r on channel c:  r = L_R⁻¹ (h_c(...) − y), the
/// channel's angle components wrapped, with the channel's robust loss.
class MeasurementFactor final : public Factor {
 public:
  /// On the default channel with its noise.
  MeasurementFactor(const Model& model, std::int64_t k, const Eigen::VectorXd& y);
  /// On m.channel, with m.R when given (else the channel's R).
  MeasurementFactor(const Model& model, std::int64_t k, const Measurement& m);
  /// On `channel` with an explicit noise model (checkpoints), and the
  /// known values h reads when the channel reads any (Measurement::regressors).
  MeasurementFactor(const Model& model, std::int64_t k, const Eigen::VectorXd& y, int channel,
                    const GaussianNoise& noise, const Eigen::VectorXd& regressors = {});
  void linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                   std::vector<Eigen::MatrixXd>* J) const override;
  std::string describe() const override;
  /// On x_b: the channel's constants (MeasurementChannel::constants), if it
  /// names them.
  const std::vector<int>* columnsOf(std::size_t a) const override;
  const Eigen::VectorXd& measurement() const { return y_; }
  const Eigen::VectorXd& regressors() const { return regressors_; }
  int channel() const { return channel_; }
  const GaussianNoise& noise() const { return noise_; }
  const Model& model() const { return *model_; }
  Rotations rotationsOf(std::size_t a) const override;

 private:
  const Model* model_;
  Eigen::VectorXd y_;
  Eigen::VectorXd regressors_;
  int channel_;
  GaussianNoise noise_;
};

/// A dense Gaussian on several variables in whitened linear form
/// r = A (x ⊟ x̄) − b, where x̄ is a fixed linearization point. This is what
/// marginalization leaves behind (a Schur-complement prior on the separator).
class LinearGaussianFactor final : public Factor {
 public:
  LinearGaussianFactor(std::vector<Key> keys, std::vector<Eigen::MatrixXd> A, Eigen::VectorXd b,
                       Values linearization_point);
  void linearizeAt(const Eigen::VectorXd* const* x, Eigen::VectorXd& r,
                   std::vector<Eigen::MatrixXd>* J) const override;
  std::string describe() const override;
  const std::vector<Eigen::MatrixXd>& A() const { return A_; }
  const Eigen::VectorXd& b() const { return b_; }
  const Values& linearizationPoint() const { return x0_; }

 private:
  std::vector<Eigen::MatrixXd> A_;
  Eigen::VectorXd b_;
  Values x0_;
};

/// An ordered collection of factors.
class FactorGraph {
 public:
  void add(FactorPtr f) { factors_.push_back(std::move(f)); }
  /// Puts f in the place of factor i.
  void replace(std::size_t i, FactorPtr f) { factors_.at(i) = std::move(f); }
  std::size_t size() const { return factors_.size(); }
  const FactorPtr& operator[](std::size_t i) const { return factors_[i]; }
  auto begin() const { return factors_.begin(); }
  auto end() const { return factors_.end(); }
  /// ½ Σ ρ_i(‖r_i(x)‖²) (the robust cost; ½ Σ ‖r_i‖² without losses).
  double cost(const Values& x) const;

 private:
  std::vector<FactorPtr> factors_;
};

/// The variables of the stacked state [x_c(k); x_b] of `model` (x_b only if
/// the model has constants), e.g. for its joint marginal covariance.
inline std::vector<Key> stackedKeys(const Model& model, std::int64_t k) {
  if (model.dims().nb > 0) return {Key::state(k), Key::constants()};
  return {Key::state(k)};
}

/// Dimension of a variable of `model`.
inline int variableDim(const Model& model, const Key& k) {
  return k.isConstants() ? model.dims().nb : model.dims().nc;
}

}  // namespace gssm
