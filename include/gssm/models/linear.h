#pragma once
// A linear GSSM built from continuous-time matrices (docs/DESIGN.md §1, eq. 1):
//   d/dt x_c = A_c x_c + A_b x_b + B u,   y = C_c x_c + C_b x_b
// discretized with F_c = I + A_c T, F_b = A_b T, B_k = B T (Euler, the
// paper's choice) or exactly with the matrix exponential of the augmented
// system [[A_c, A_b, B], [0, 0, 0], [0, 0, 0]]·T.
#include "gssm/model/model.h"

namespace gssm::models {

/// A further sensor of a linear system: y = C_c x_c + C_b x_b + r, r ~ N(0, R).
struct LinearChannel {
  std::string name;
  Eigen::MatrixXd C_c, C_b, R;
  std::vector<std::string> components;  ///< optional: left empty, `<name>_1`.. are used
};

struct LinearSystem {
  Eigen::MatrixXd A_c, A_b, B, C_c, C_b;  ///< C_c, C_b: the default channel "y"
  ModelNoise noise;  ///< T, Q (per nominal step), R (of the default channel), priors
  ModelNames names;  ///< optional: left empty, names x1.., b1.., u1.., y1.. are used
  std::vector<LinearChannel> channels;  ///< further sensors (channels 1, 2, ...)
};

enum class Discretization { Euler, Exact };

class LinearModel final : public Model {
 public:
  explicit LinearModel(LinearSystem sys, Discretization d = Discretization::Euler);

  std::string name() const override { return "linear"; }
  bool processIsAffine() const override { return true; }
  bool measurementIsAffine(int) const override { return true; }
  const LinearSystem& system() const { return sys_; }
  Discretization discretization() const { return disc_; }

  /// Discrete matrices of a step dt: F_c, F_b, B_k.
  void discreteMatrices(double dt, Eigen::MatrixXd& F_c, Eigen::MatrixXd& F_b,
                        Eigen::MatrixXd& B_k) const;

  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                    const Eigen::VectorXd& u, double dt, Eigen::MatrixXd* J_f_xc = nullptr,
                    Eigen::MatrixXd* J_f_xb = nullptr) const override;
  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                    Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const override;
  Eigen::VectorXd h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                    Eigen::MatrixXd* J_h_xc = nullptr, Eigen::MatrixXd* J_h_xb = nullptr) const override;
  /// C = [C_c, C_b] of a channel (0: the default).
  void outputMatrices(int channel, Eigen::MatrixXd& C_c, Eigen::MatrixXd& C_b) const;

 private:
  LinearSystem sys_;
  Discretization disc_;
  Eigen::MatrixXd Fc_T_, Fb_T_, Bk_T_;  // cached for the nominal step
};

}  // namespace gssm::models
