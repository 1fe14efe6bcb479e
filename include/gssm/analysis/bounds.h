#pragma once
// Analysis tools (issue 8): what the data can tell about a scenario,
// independently of any estimator.
//
// * The posterior Cramér–Rao bound: the inverse of the information matrix of
//   the whole problem (priors, process and measurement factors) evaluated at
//   the TRUE states; for the filtering problem with the data up to step k,
//   for the smoothing problem with all data. Bound on the error covariance
//   of [x_c(k); x_b] of any unbiased estimator (attained on linear models).
// * Identifiability of the constants: the information the data (not the
//   prior) carry about x_b once the time series is eliminated.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "gssm/core/data.h"
#include "gssm/model/model.h"
#include "gssm/model/simulation.h"

namespace gssm {

struct CramerRaoBound {
  std::vector<double> times;                 ///< measurement times
  std::vector<Eigen::MatrixXd> filtering;    ///< bound on cov [x_c(k); x_b] given data up to t_k
  std::vector<Eigen::MatrixXd> smoothing;    ///< same, given all data
};

/// The bound along a simulated run (its true states and its measurements).
/// `stride` > 1 computes the filtering bound only every stride-th
/// measurement (each costs a sparse factorization of the problem so far).
CramerRaoBound posteriorCramerRao(const Model& model, const SimulatedRun& run, int stride = 1);

struct ConstantsIdentifiability {
  Eigen::VectorXd eigenvalues;   ///< of the data information on x_b (ascending)
  Eigen::MatrixXd directions;    ///< matching unit eigenvectors (columns)
  int rank = 0;                  ///< eigenvalues above tolerance·largest
  double condition = 0;          ///< largest / smallest (inf when rank deficient)
  std::string weakest;           ///< e.g. "0.707·b1 − 0.707·b2 (information 3.2e-15)"
  bool determined(double tolerance = 1e-9) const;
};

/// Data information about the constants = (posterior covariance of x_b)⁻¹ −
/// (prior covariance)⁻¹, decomposed; `posterior_constants` is the x_b block
/// of a bound (or of an estimator's covariance).
ConstantsIdentifiability constantsIdentifiability(const Model& model,
                                                  const Eigen::MatrixXd& posterior_constants,
                                                  double tolerance = 1e-9);

}  // namespace gssm
