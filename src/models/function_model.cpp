#include "gssm/models/function_model.h"

#include "gssm/core/error.h"
#include "model/central_differences.h"

namespace gssm::models {

using internal::centralDifferences;

FunctionModel::FunctionModel(ModelDims dims, ModelNames names, ModelNoise noise, ModelFunctions fns)
    : Model(dims, std::move(names), std::move(noise)), fns_(std::move(fns)) {
  if (!fns_.f || !fns_.h) throw InvalidArgument("FunctionModel '" + fns_.name + "': f and h are required");
  if (fns_.verify_jacobians && !fns_.jacobians_f && !fns_.jacobians_h)
    throw InvalidArgument("FunctionModel '" + fns_.name +
                          "': verify_jacobians is set but no analytic Jacobians are given");
}

std::string FunctionModel::jacobianSource() const {
  const bool f = static_cast<bool>(fns_.jacobians_f), h = static_cast<bool>(fns_.jacobians_h);
  std::string s = f && h ? "analytic" : (f || h ? (f ? "analytic f, central differences for h"
                                                     : "central differences for f, analytic h")
                                                : "central differences");
  if (fns_.verify_jacobians) s += " (verified against differences on the first calls)";
  return s;
}

void FunctionModel::verify(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u,
                           double dt) const {
  {
    std::lock_guard<std::mutex> lock(verify_mutex_);
    if (verified_ >= fns_.verify_calls) return;
    ++verified_;
  }
  const auto d = dims();
  auto compare = [&](const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric, const char* what) {
    if (analytic.rows() != numeric.rows() || analytic.cols() != numeric.cols())
      throw InvalidArgument("model '" + fns_.name + "': " + what + " has size " + std::to_string(analytic.rows()) +
                            "x" + std::to_string(analytic.cols()) + ", expected " +
                            std::to_string(numeric.rows()) + "x" + std::to_string(numeric.cols()));
    for (Eigen::Index i = 0; i < numeric.rows(); ++i)
      for (Eigen::Index j = 0; j < numeric.cols(); ++j) {
        const double err = std::abs(analytic(i, j) - numeric(i, j)) / std::max(1.0, std::abs(numeric(i, j)));
        if (err > fns_.verify_tolerance)
          throw NumericalError("model '" + fns_.name + "': analytic " + what + "(" + std::to_string(i) + "," +
                               std::to_string(j) + ") = " + std::to_string(analytic(i, j)) +
                               " but central differences give " + std::to_string(numeric(i, j)));
      }
  };
  if (fns_.jacobians_f) {
    Eigen::MatrixXd a, b;
    fns_.jacobians_f(xc, xb, u, dt, a, b);
    compare(a, centralDifferences([&](const Eigen::VectorXd& v) { return fns_.f(v, xb, u, dt); }, xc, d.nc), "J_f_xc");
    compare(b, centralDifferences([&](const Eigen::VectorXd& v) { return fns_.f(xc, v, u, dt); }, xb, d.nc), "J_f_xb");
  }
  if (fns_.jacobians_h) {
    Eigen::MatrixXd a, b;
    fns_.jacobians_h(xc, xb, a, b);
    compare(a, centralDifferences([&](const Eigen::VectorXd& v) { return fns_.h(v, xb); }, xc, d.ny), "J_h_xc");
    compare(b, centralDifferences([&](const Eigen::VectorXd& v) { return fns_.h(xc, v); }, xb, d.ny), "J_h_xb");
  }
}

Eigen::VectorXd FunctionModel::f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u,
                                 double dt, Eigen::MatrixXd* J_f_xc, Eigen::MatrixXd* J_f_xb) const {
  if (J_f_xc || J_f_xb) {
    Eigen::MatrixXd a, b;
    if (fns_.jacobians_f) {
      fns_.jacobians_f(xc, xb, u, dt, a, b);
      if (fns_.verify_jacobians) verify(xc, xb, u, dt);
    } else {
      const auto d = dims();
      a = centralDifferences([&](const Eigen::VectorXd& v) { return fns_.f(v, xb, u, dt); }, xc, d.nc);
      b = centralDifferences([&](const Eigen::VectorXd& v) { return fns_.f(xc, v, u, dt); }, xb, d.nc);
    }
    if (J_f_xc) *J_f_xc = std::move(a);
    if (J_f_xb) *J_f_xb = std::move(b);
  }
  return fns_.f(xc, xb, u, dt);
}

Eigen::VectorXd FunctionModel::h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                                 Eigen::MatrixXd* J_h_xb) const {
  if (J_h_xc || J_h_xb) {
    Eigen::MatrixXd a, b;
    if (fns_.jacobians_h) {
      fns_.jacobians_h(xc, xb, a, b);
      if (fns_.verify_jacobians) verify(xc, xb, Eigen::VectorXd::Zero(dims().nu), nominalStep());
    } else {
      const auto d = dims();
      a = centralDifferences([&](const Eigen::VectorXd& v) { return fns_.h(v, xb); }, xc, d.ny);
      b = centralDifferences([&](const Eigen::VectorXd& v) { return fns_.h(xc, v); }, xb, d.ny);
    }
    if (J_h_xc) *J_h_xc = std::move(a);
    if (J_h_xb) *J_h_xb = std::move(b);
  }
  return fns_.h(xc, xb);
}

}  // namespace gssm::models
