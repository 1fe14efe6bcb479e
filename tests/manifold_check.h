#pragma once
// Analytic Jacobians on manifolds against central differences (manif's
// tester idea): J_f_x = ∂(f(x ⊕ δ) ⊖ f(x))/∂δ at δ = 0, the ⊕ of x's space
// and the ⊖ of f's. One helper for every function of rotations and vectors.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "gssm/core/so3.h"

namespace gssm::testing {

/// How to move in a space (x ⊕ δ) and how far apart two points are (a ⊖ b).
template <class T>
struct Space {
  std::function<T(const T&, const Eigen::VectorXd&)> plus;
  std::function<Eigen::VectorXd(const T&, const T&)> minus;
  int dim;
};

inline Space<so3::Matrix3> rotations() {
  return {[](const so3::Matrix3& R, const Eigen::VectorXd& d) { return so3::plus(R, so3::Vector3(d)); },
          [](const so3::Matrix3& a, const so3::Matrix3& b) { return Eigen::VectorXd(so3::minus(a, b)); }, 3};
}
inline Space<so3::Vector3> vectors3() {
  return {[](const so3::Vector3& v, const Eigen::VectorXd& d) { return so3::Vector3(v + d); },
          [](const so3::Vector3& a, const so3::Vector3& b) { return Eigen::VectorXd(a - b); }, 3};
}

/// J = ∂(f(x ⊕ δ) ⊖ f(x))/∂δ by central differences of step eps.
template <class X, class Y>
Eigen::MatrixXd numericJacobian(const std::function<Y(const X&)>& f, const X& x, const Space<X>& in,
                                const Space<Y>& out, double eps = 1e-6) {
  const Y y = f(x);
  Eigen::MatrixXd J(out.dim, in.dim);
  for (int j = 0; j < in.dim; ++j) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(in.dim);
    d[j] = eps;
    const Eigen::VectorXd up = out.minus(f(in.plus(x, d)), y), down = out.minus(f(in.plus(x, -d)), y);
    J.col(j) = (up - down) / (2 * eps);
  }
  return J;
}

/// Expects the analytic J_f_x to equal the central differences within tol
/// (relative to max(1, |entry|)), naming the function and the point.
template <class X, class Y>
void expectJacobian(const std::string& what, const std::function<Y(const X&)>& f, const X& x,
                    const Eigen::MatrixXd& analytic, const Space<X>& in, const Space<Y>& out, double tol = 1e-6) {
  const Eigen::MatrixXd numeric = numericJacobian(f, x, in, out);
  ASSERT_EQ(analytic.rows(), numeric.rows()) << what;
  ASSERT_EQ(analytic.cols(), numeric.cols()) << what;
  const Eigen::MatrixXd scale = numeric.cwiseAbs().cwiseMax(1.0);
  const double err = ((analytic - numeric).cwiseAbs().cwiseQuotient(scale)).maxCoeff();
  EXPECT_LE(err, tol) << what << ": analytic\n" << analytic << "\nnumeric\n" << numeric;
}

}  // namespace gssm::testing
