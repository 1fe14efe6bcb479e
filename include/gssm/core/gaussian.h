#pragma once
// Gaussian noise models: whitening by the Cholesky factor of a covariance.
#include <Eigen/Core>
#include <atomic>
#include <string>

namespace gssm {

/// Checks that `m` is a finite, symmetric, positive-definite covariance of
/// size n×n; throws InvalidArgument/NumericalError mentioning `what`.
void requireCovariance(const Eigen::MatrixXd& m, Eigen::Index n, const std::string& what);
/// Throws InvalidArgument mentioning `what` if `v` has the wrong size or a
/// non-finite entry.
void requireVector(const Eigen::VectorXd& v, Eigen::Index n, const std::string& what);
/// What requireVector accepts; hot paths test this first and build their
/// message only when it fails.
inline bool validVector(const Eigen::VectorXd& v, Eigen::Index n) { return v.size() == n && v.allFinite(); }

/// A zero-mean Gaussian N(0, Σ), Σ = L Lᵀ. whiten(v) = L⁻¹ v, so that
/// ‖whiten(v)‖² is the squared Mahalanobis norm vᵀ Σ⁻¹ v.
/// Immutable; copies share Σ and L (every measurement factor of a run holds
/// the same R: one Cholesky factor, one word each instead of two matrices).
class GaussianNoise {
 public:
  GaussianNoise();
  GaussianNoise(const GaussianNoise& o) noexcept : data_(o.data_) { data_->refs.fetch_add(1, std::memory_order_relaxed); }
  GaussianNoise(GaussianNoise&& o) noexcept : GaussianNoise(o) {}  // a moved-from noise stays valid
  GaussianNoise& operator=(const GaussianNoise& o) noexcept {
    GaussianNoise copy(o);
    std::swap(data_, copy.data_);
    return *this;
  }
  ~GaussianNoise() { release(data_); }
  /// Throws NumericalError (naming `what`) if Σ is not positive definite.
  explicit GaussianNoise(const Eigen::MatrixXd& covariance, const std::string& what = "covariance");

  Eigen::Index dim() const { return data_->covariance.rows(); }
  const Eigen::MatrixXd& covariance() const { return data_->covariance; }
  /// Lower-triangular Cholesky factor L.
  const Eigen::MatrixXd& sqrtCovariance() const { return data_->L; }

  /// L⁻¹ v, in place on a vector or on each column of a matrix.
  void whitenInPlace(Eigen::VectorXd& v) const;
  void whitenInPlace(Eigen::MatrixXd& m) const;
  Eigen::VectorXd whiten(const Eigen::VectorXd& v) const;

 private:
  // Shared by reference count in the data itself: a full-history run holds
  // a noise model per factor, and a shared_ptr took two words.
  struct Data {
    Eigen::MatrixXd covariance, L;
    Eigen::VectorXd inverse_diagonal;  // 1 / L(i, i): whitening independent noise multiplies
    bool diagonal = true;
    mutable std::atomic<long> refs{1};
  };
  static void release(const Data* d) noexcept {
    if (d->refs.fetch_sub(1, std::memory_order_acq_rel) == 1) delete d;
  }
  const Data* data_;
};

/// A Gaussian density N(mean, covariance) on one variable.
struct Gaussian {
  Eigen::VectorXd mean;
  Eigen::MatrixXd covariance;
};

}  // namespace gssm
