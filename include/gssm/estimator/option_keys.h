#pragma once
// Every setting of the estimators' option groups, named once (docs/DESIGN.md
// §4): the INI reader ([ekf], [smoother], [batch]) and the Python options
// objects (EkfOptions, SmootherOptions, BatchOptions) both visit these
// lists, so a key exists in both or in neither, and Python's defaults are
// the C++ structs' own.
//
// A visitor has   template <class T> void operator()(const char* key, T& value)
// for T = bool, int, double, Eigen::VectorXd and Choice<E> (a named enum).
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
  v("constant_process_noise", o.constant_process_noise);
  v("joseph_form", o.joseph_form);
}

template <class Visitor>
void optionKeys(Visitor& v, SmootherOptions& o) {
  v("relinearize", o.relinearize);
  v("relinearize_threshold", o.relinearize_threshold);
  v("constants_check_sigmas", o.constants_check_sigmas);
  v("full_pass_growth", o.full_pass_growth);
  v("max_local_iterations", o.max_local_iterations);
  v("wildfire_threshold", o.wildfire_threshold);
  v("iterate_to_convergence", o.iterate_to_convergence);
  v("convergence_tolerance", o.convergence_tolerance);
  v("max_iterations", o.max_iterations);
  v("newton_polish_steps", o.newton_polish_steps);
}

template <class Visitor>
void optionKeys(Visitor& v, BatchSolverOptions& o) {
  Choice<BatchSolverOptions::Method> algorithm{o.method, &BatchSolverOptions::methodName,
                                               &BatchSolverOptions::methodNamed, "levenberg-marquardt or gauss-newton"};
  v("algorithm", algorithm);
  v("max_iterations", o.max_iterations);
  v("relative_cost_tolerance", o.relative_cost_tolerance);
  v("step_tolerance", o.step_tolerance);
  v("gradient_tolerance", o.gradient_tolerance);
  v("decrease_tolerance", o.decrease_tolerance);
  v("initial_lambda", o.initial_lambda);
  v("max_lambda", o.max_lambda);
  v("newton_polish_steps", o.newton_polish_steps);
}

/// Collects the keys (optionKeyNames).
struct OptionKeyNames {
  std::vector<std::string> keys;
  template <class T>
  void operator()(const char* key, T&) { keys.push_back(key); }
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
