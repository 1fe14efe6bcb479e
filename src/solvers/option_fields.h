#pragma once
// Internal: the checkpoint field lists of the solvers' option and report
// records, visited by internal::FieldWriter or FieldReader (core/byte_stream.h)
// so that writing and reading cannot drift. Records are visited through
// non-const references; writers visit a copy.
#include "core/byte_stream.h"
#include "gssm/solvers/ekf.h"
#include "gssm/solvers/smoothers.h"

namespace gssm::internal {

template <class Io>
void fields(Io& io, ExtendedKalmanFilterOptions& o) {
  io(o.constant_process_noise, "ekf constant_process_noise");
  io(o.joseph_form, "ekf joseph_form");
}

/// Without the ordering, which belongs to its owner (format v1 stores it
/// between the EKF options and these).
template <class Io>
void fields(Io& io, SmootherOptions& s) {
  io(s.relinearize, "smoother relinearize");
  io(s.relinearize_threshold, "smoother relinearize_threshold");
  io(s.constants_check_sigmas, "smoother constants_check_sigmas");
  if (io.version() >= 4) io(s.full_pass_growth, "smoother full_pass_growth");
  if (io.version() >= 6) io(s.full_pass_rounds, "smoother full_pass_rounds");
  io(s.max_local_iterations, "smoother max_local_iterations");
  io(s.wildfire_threshold, "smoother wildfire_threshold", true);  // ∞ = lazy
  io(s.iterate_to_convergence, "smoother iterate_to_convergence");
  io(s.convergence_tolerance, "smoother convergence_tolerance");
  io(s.max_iterations, "smoother max_iterations");
  io(s.newton_polish_steps, "smoother newton_polish_steps");
}

template <class Io>
void fields(Io& io, UpdateReport& r) {
  io(r.new_factors, "update report new_factors");
  io(r.new_variables, "update report new_variables");
  io(r.cliques_reeliminated, "update report cliques_reeliminated");
  io(r.orphans, "update report orphans");
  io(r.factors_checked, "update report factors_checked");
  io(r.factors_relinearized, "update report factors_relinearized");
  io(r.relinearization_pass, "update report relinearization_pass");
  io(r.iterations, "update report iterations");
  io(r.variables_backsubstituted, "update report variables_backsubstituted");
  io(r.variables_marginalized, "update report variables_marginalized");
  io(r.num_variables, "update report num_variables");
  io(r.num_factors, "update report num_factors");
  io(r.num_cliques, "update report num_cliques");
  io(r.seconds, "update report seconds");
  io(r.note, "update report note");
}

}  // namespace gssm::internal
