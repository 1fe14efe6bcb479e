#pragma once
// A GSSM model from callables, for users who do not want to write a class:
// fill f and h; Jacobians are optional. Without them, central differences
// are used (jacobianSource() says so); with them, `verify_jacobians` checks
// them against differences on the first calls and throws, naming the worst
// entry, if they disagree.
#include <functional>
#include <mutex>

#include "gssm/model/model.h"

namespace gssm::models {

struct ModelFunctions {
  std::string name = "user";
  /// x_c(k+1) = f(x_c(k), x_b, u_k, dt)
  std::function<Eigen::VectorXd(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                                const Eigen::VectorXd& u, double dt)> f;
  /// y = h(x_c, x_b)
  std::function<Eigen::VectorXd(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb)> h;
  /// Optional analytic Jacobians: fill J_f_xc, J_f_xb (resp. J_h_xc, J_h_xb).
  std::function<void(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u,
                     double dt, Eigen::MatrixXd& J_f_xc, Eigen::MatrixXd& J_f_xb)> jacobians_f;
  std::function<void(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd& J_h_xc,
                     Eigen::MatrixXd& J_h_xb)> jacobians_h;
  /// Check analytic Jacobians against central differences on the first
  /// `verify_calls` evaluations (relative tolerance `verify_tolerance`).
  bool verify_jacobians = false;
  int verify_calls = 20;
  double verify_tolerance = 1e-5;
};

class FunctionModel final : public Model {
 public:
  FunctionModel(ModelDims dims, ModelNames names, ModelNoise noise, ModelFunctions fns);

  std::string name() const override { return fns_.name; }
  /// "analytic", "analytic (verified on first calls)" or "central differences".
  std::string jacobianSource() const;

  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u,
                    double dt, Eigen::MatrixXd* J_f_xc = nullptr,
                    Eigen::MatrixXd* J_f_xb = nullptr) const override;
  using Model::h;  // h(channel, ...) for channel 0
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                    Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const override;

 private:
  void verify(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt) const;
  ModelFunctions fns_;
  mutable std::mutex verify_mutex_;
  mutable int verified_ = 0;
};

}  // namespace gssm::models
