#pragma once
// Every setting of the estimators' option groups, named once (docs/DESIGN.md
// §4): the INI reader ([ekf], [smoother], [batch]) and the Python options
// objects (EkfOptions, SmootherOptions, BatchOptions) both visit these
// lists, so a key exists in both or in neither, and Python's defaults are
// the C++ structs' own.
//
// A visitor has   template <class T> void operator()(const char* key, T& value, const char* doc)
// for T = bool, int, double, Eigen::VectorXd and Choice<E> (a named enum);
// `doc` is the key's one-line meaning (the manual's INI reference, Python's
// docstrings).
#include <optional>
#include <string>
#include <vector>

#include "gssm/solvers/batch_solver.h"
#include "gssm/solvers/ekf.h"
#include "gssm/solvers/smoothers.h"

namespace gssm {

/// An enum setting read and written by name ("levenberg-marquardt").
template <class E>
struct Choice {
  E& value;
  const char* (*name)(E);
  std::optional<E> (*named)(const std::string&);
  const char* expected;  ///< "levenberg-marquardt or gauss-newton"
};

template <class Visitor>
void optionKeys(Visitor& v, ExtendedKalmanFilterOptions& o) {
  v("constant_process_noise", o.constant_process_noise,
    "process noise variance per constant per nominal step (n_b numbers; empty: none): the EKF's constants as random walks");
  v("joseph_form", o.joseph_form, "Joseph-form covariance update (the same in exact arithmetic, numerically safer)");
}

template <class Visitor>
void optionKeys(Visitor& v, SmootherOptions& o) {
  v("relinearize", o.relinearize, "relinearize factors whose linearization error exceeds relinearize_threshold (false: keep each as added)");
  v("relinearize_threshold", o.relinearize_threshold, "whitened linearization error ‖r(x̂) − r_lin(x̂)‖ above which a factor is relinearized");
  v("constants_check_sigmas", o.constants_check_sigmas, "check every factor when the constants moved more than this many marginal σ since the last check");
  v("full_pass_growth", o.full_pass_growth, "> 1: a full relinearization pass only once the history grew by this factor since the last (1: whenever the constants moved)");
  v("full_pass_rounds", o.full_pass_rounds, "relinearize-and-re-eliminate rounds of a full pass, each until no factor is stale (1: one Gauss–Newton step)");
  v("max_local_iterations", o.max_local_iterations, "relinearize-and-re-eliminate rounds on the re-eliminated top per update");
  v("wildfire_threshold", o.wildfire_threshold, "back-substitution descends only while the change exceeds this (iSAM2's wildfire; default: never, lazy)");
  v("iterate_to_convergence", o.iterate_to_convergence, "iterate every update to convergence over all factors (O(n): equals the batch)");
  v("convergence_tolerance", o.convergence_tolerance, "iterate_to_convergence stops when no estimate changes by more than this, relative");
  v("max_iterations", o.max_iterations, "iterate_to_convergence: at most this many iterations per update");
  v("newton_polish_steps", o.newton_polish_steps, "iterate_to_convergence: full Newton steps after convergence (0: off)");
}

template <class Visitor>
void optionKeys(Visitor& v, BatchSolverOptions& o) {
  Choice<BatchSolverOptions::Method> algorithm{o.method, &BatchSolverOptions::methodName,
                                               &BatchSolverOptions::methodNamed, "levenberg-marquardt or gauss-newton"};
  v("algorithm", algorithm, "levenberg-marquardt or gauss-newton");
  v("max_iterations", o.max_iterations, "at most this many iterations");
  v("relative_cost_tolerance", o.relative_cost_tolerance, "stop when an accepted step lowers the cost by less than this fraction");
  v("step_tolerance", o.step_tolerance, "stop when ‖δ‖ ≤ tol·(‖x‖ + tol)");
  v("gradient_tolerance", o.gradient_tolerance, "stop when max |Jᵀr| ≤ tol");
  v("decrease_tolerance", o.decrease_tolerance, "stop when an undamped step's predicted decrease is at most this, in cost units (0: no such test)");
  v("initial_lambda", o.initial_lambda, "Levenberg–Marquardt damping λ₀, relative to diag(JᵀJ)");
  v("max_lambda", o.max_lambda, "largest damping before the solve gives up");
  v("newton_polish_steps", o.newton_polish_steps, "full Newton steps after convergence, for large residuals at the optimum (0: off)");
  v("covariance_by_qr", o.covariance_by_qr,
    "covariances from a QR of the Jacobian at the solution, not the normal equations (a stiff chain beside a weakly "
    "seen constant)");
  v("anderson_memory", o.anderson_memory,
    "Anderson acceleration of the undamped steps: each mixed with this many previous ones (0: off), kept only if "
    "it lowers the cost");
}

/// Collects the keys (optionKeyNames).
struct OptionKeyNames {
  std::vector<std::string> keys;
  template <class T>
  void operator()(const char* key, T&, const char*) { keys.push_back(key); }
};

/// The keys optionKeys visits for an options type, in order.
template <class Options>
std::vector<std::string> optionKeyNames() {
  OptionKeyNames names;
  Options o;
  optionKeys(names, o);
  return names.keys;
}

}  // namespace gssm
