#pragma once
// Nelder–Mead minimization (Lagarias et al., SIAM J. Optim. 9(1), 1998:
// reflection 1, expansion 2, contraction ½, shrink ½) for the few noise
// parameters of learning, whose likelihood is evaluated by a filter pass
// and has no cheap gradient. A value of +∞ marks a point outside the domain.
#include <Eigen/Core>
#include <functional>
#include <vector>

namespace gssm::internal {

struct NelderMeadResult {
  Eigen::VectorXd x;
  double value = 0;
  int evaluations = 0;
  int iterations = 0;
  bool converged = false;  ///< the simplex collapsed before the budget ran out
};

/// Minimizes f from x0 with an initial simplex of x0 + step·e_i. Stops when
/// the simplex's values span less than ftol·(1 + |best|) and its points lie
/// within xtol of the best, or after max_evaluations. `iteration` is called
/// with the best value after each iteration.
NelderMeadResult nelderMead(const std::function<double(const Eigen::VectorXd&)>& f, const Eigen::VectorXd& x0,
                            double step, int max_evaluations, double ftol, double xtol,
                            const std::function<void(double)>& iteration = {});

}  // namespace gssm::internal
