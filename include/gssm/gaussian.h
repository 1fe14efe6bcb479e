#pragma once
// Gaussian noise models: whitening by the Cholesky factor of a covariance.
#include <Eigen/Core>
#include <string>

namespace gssm {

/// Checks that `m` is a finite, symmetric, positive-definite covariance of
/// size n×n; throws InvalidArgument/NumericalError mentioning `what`.
void requireCovariance(const Eigen::MatrixXd& m, Eigen::Index n, const std::string& what);
/// Throws InvalidArgument mentioning `what` if `v` has the wrong size or a
/// non-finite entry.
void requireVector(const Eigen::VectorXd& v, Eigen::Index n, const std::string& what);

/// A zero-mean Gaussian N(0, Σ), Σ = L Lᵀ. whiten(v) = L⁻¹ v, so that
/// ‖whiten(v)‖² is the squared Mahalanobis norm vᵀ Σ⁻¹ v.
class GaussianNoise {
 public:
  GaussianNoise() = default;
  /// Throws NumericalError (naming `what`) if Σ is not positive definite.
  explicit GaussianNoise(const Eigen::MatrixXd& covariance, const std::string& what = "covariance");

  Eigen::Index dim() const { return covariance_.rows(); }
  const Eigen::MatrixXd& covariance() const { return covariance_; }
  /// Lower-triangular Cholesky factor L.
  const Eigen::MatrixXd& sqrtCovariance() const { return L_; }

  /// L⁻¹ v, in place on a vector or on each column of a matrix.
  void whitenInPlace(Eigen::VectorXd& v) const;
  void whitenInPlace(Eigen::MatrixXd& m) const;
  Eigen::VectorXd whiten(const Eigen::VectorXd& v) const;

 private:
  Eigen::MatrixXd covariance_;
  Eigen::MatrixXd L_;
  bool diagonal_ = true;
};

/// A Gaussian density N(mean, covariance) on one variable.
struct Gaussian {
  Eigen::VectorXd mean;
  Eigen::MatrixXd covariance;
};

}  // namespace gssm
