#pragma once
// The paper's 2-D radar example (docs/DESIGN.md §2 in the gssm repository): horizontal distance x is a
// time series; horizontal velocity xdot and altitude h are constants.
//   x(k+1) = x(k) + xdot·T + q,   range = sqrt(x² + h²) + r
#include "gssm/model/model.h"

namespace gssm::models {

class Radar2D final : public Model {
 public:
  /// Defaults are the paper's settings.
  struct Params {
    double T = 0.05;
    double q = 0.005 * 0.005;  ///< process noise variance on x per step
    double r = 9.0;            ///< range noise variance
    double prior_x = -100, prior_xdot = 200, prior_h = 2000;
    double prior_var_x = 49, prior_var_xdot = 49, prior_var_h = 49;
  };

  Radar2D() : Radar2D(Params{}) {}
  explicit Radar2D(const Params& p);
  /// Any step, noise and (full-covariance) priors, e.g. from a config file.
  explicit Radar2D(const ModelNoise& noise);

  std::string name() const override { return "radar_2d"; }
  bool processIsAffine() const override { return true; }  // x + ẋ·dt

  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                    const Eigen::VectorXd& u, double dt, Eigen::MatrixXd* J_f_xc = nullptr,
                    Eigen::MatrixXd* J_f_xb = nullptr) const override;
  using Model::h;  // h(channel, ...) for channel 0
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                    Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const override;
  void hInto(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::VectorXd& out,
             Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const override;
};

}  // namespace gssm::models
