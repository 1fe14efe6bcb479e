#pragma once
// A model defined outside the library, through the public registration API
// only (docs/DESIGN.md §3, "Adding a model"): its proof that a model is
// declared once. A position drifting at a constant rate, measured with a
// constant offset:
//   x(k+1) = x(k) + drift·dt + q,   y = x + offset + r
// x_c = [x], x_b = [drift, offset].
#include "gssm/model/model.h"

namespace gssm::testing {

class Drift1D final : public Model {
 public:
  struct Params {
    double T = 0.5;
    double q = 0.01;        ///< process noise variance per second
    double r = 0.25;        ///< measurement noise variance
    double start = 0;       ///< prior mean of x(0)
    double start_sd = 1.0;  ///< prior σ of x(0)
    double drift_sd = 1.0;  ///< prior σ of the drift (mean 0)
    double offset_sd = 0.5; ///< prior σ of the offset (mean 0)
  };
  explicit Drift1D(const Params& p);
  std::string name() const override { return "drift_1d"; }
  const Params& params() const { return p_; }

  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                    Eigen::MatrixXd* J_f_xc = nullptr, Eigen::MatrixXd* J_f_xb = nullptr) const override;
  using Model::h;
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc = nullptr,
                    Eigen::MatrixXd* J_h_xb = nullptr) const override;

 private:
  Params p_;
};

}  // namespace gssm::testing
