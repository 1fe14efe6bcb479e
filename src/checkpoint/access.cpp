#include "checkpoint/access.h"

#include "solvers/smoother_core.h"

namespace gssm::internal {

void CheckpointAccess::writeOptions(ByteWriter& out, const EstimatorOptions& o) {
  out.str(o.method);
  out.i32(o.window);
  out.vec(o.ekf.constant_process_noise);
  out.boolean(o.ekf.joseph_form);
  const SmootherOptions& s = o.smoother;
  out.u8(static_cast<std::uint8_t>(s.ordering));
  out.boolean(s.relinearize);
  out.f64(s.relinearize_threshold);
  out.f64(s.constants_check_sigmas);
  out.i32(s.max_local_iterations);
  out.f64(s.wildfire_threshold);
  out.boolean(s.iterate_to_convergence);
  out.f64(s.convergence_tolerance);
  out.i32(s.max_iterations);
  out.i32(s.newton_polish_steps);
  out.f64(o.t0);
  out.boolean(o.compute_nis);
}

EstimatorOptions CheckpointAccess::readOptions(ByteReader& in) {
  EstimatorOptions o;
  o.method = in.str("estimator method");
  o.window = in.i32("window");
  o.ekf.constant_process_noise = in.vec("ekf constant_process_noise");
  o.ekf.joseph_form = in.boolean("ekf joseph_form");
  SmootherOptions& s = o.smoother;
  const std::uint8_t ordering = in.u8("smoother ordering");
  if (ordering > 1) in.fail("unknown smoother ordering " + std::to_string(ordering));
  s.ordering = static_cast<EliminationOrdering>(ordering);
  s.relinearize = in.boolean("smoother relinearize");
  s.relinearize_threshold = in.f64("smoother relinearize_threshold");
  s.constants_check_sigmas = in.f64("smoother constants_check_sigmas");
  s.max_local_iterations = in.i32("smoother max_local_iterations");
  s.wildfire_threshold = in.f64("smoother wildfire_threshold", true);
  s.iterate_to_convergence = in.boolean("smoother iterate_to_convergence");
  s.convergence_tolerance = in.f64("smoother convergence_tolerance");
  s.max_iterations = in.i32("smoother max_iterations");
  s.newton_polish_steps = in.i32("smoother newton_polish_steps");
  o.t0 = in.f64("t0");
  o.compute_nis = in.boolean("compute_nis");
  return o;
}

void CheckpointAccess::writeUpdateReport(ByteWriter& out, const UpdateReport& r) {
  for (int v : {r.new_factors, r.new_variables, r.cliques_reeliminated, r.orphans, r.factors_checked,
                r.factors_relinearized, r.iterations, r.variables_backsubstituted, r.variables_marginalized})
    out.i32(v);
  out.boolean(r.relinearization_pass);
  out.u64(r.num_variables);
  out.u64(r.num_factors);
  out.u64(r.num_cliques);
  out.f64(r.seconds);
  out.str(r.note);
}

UpdateReport CheckpointAccess::readUpdateReport(ByteReader& in) {
  UpdateReport r;
  for (int* v : {&r.new_factors, &r.new_variables, &r.cliques_reeliminated, &r.orphans, &r.factors_checked,
                 &r.factors_relinearized, &r.iterations, &r.variables_backsubstituted,
                 &r.variables_marginalized})
    *v = in.i32("update report count");
  r.relinearization_pass = in.boolean("update report relinearization_pass");
  r.num_variables = in.u64("update report num_variables");
  r.num_factors = in.u64("update report num_factors");
  r.num_cliques = in.u64("update report num_cliques");
  r.seconds = in.f64("update report seconds");
  r.note = in.str("update report note");
  return r;
}

void CheckpointAccess::saveEstimator(const Estimator& e, ByteWriter& out) {
  out.f64(e.t_);
  out.i64(e.k_);
  out.vec(e.input_);
  const EstimatorReport& r = e.report();  // formats a pending detail line
  out.i64(r.steps);
  out.f64(r.seconds);
  out.i32(r.iterations);
  writeUpdateReport(out, r.smoother);
  out.str(r.detail);
  out.f64(r.nis);
  e.saveState(out);
}

void CheckpointAccess::loadEstimator(Estimator& e, ByteReader& in) {
  const double t = in.f64("estimator time");
  const std::int64_t k = in.i64("estimator step");
  if (k < 0 || k > (std::int64_t(1) << 53)) in.fail("step counter " + std::to_string(k) + " out of range");
  Eigen::VectorXd input = in.vec("input in force");
  if (input.size() != 0 && input.size() != e.model_.dims().nu)
    in.fail("input in force has size " + std::to_string(input.size()) + ", the model's inputs " +
            std::to_string(e.model_.dims().nu));
  EstimatorReport r;
  r.method = e.report_.method;
  r.steps = in.i64("report steps");
  r.seconds = in.f64("report seconds");
  r.iterations = in.i32("report iterations");
  r.smoother = readUpdateReport(in);
  r.detail = in.str("report detail");
  r.nis = in.f64("report nis", true);
  // The base state first: the method's loadState checks itself against it.
  e.t_ = t;
  e.k_ = k;
  e.input_ = std::move(input);
  e.report_ = std::move(r);
  e.loadState(in);
}

void CheckpointAccess::saveSmoother(const Smoother& s, ByteWriter& out) {
  s.core_->save(out);
  if (const auto* f = dynamic_cast<const FixedLagSmoother*>(&s)) {
    out.i64(f->oldest_);
    out.i64(f->newest_);
  }
}

void CheckpointAccess::loadSmoother(Smoother& s, ByteReader& in, const Model& model) {
  s.core_->load(in, model);
  if (auto* f = dynamic_cast<FixedLagSmoother*>(&s)) {
    const std::int64_t oldest = in.i64("fixed-lag oldest step"), newest = in.i64("fixed-lag newest step");
    if (oldest < -1 || newest < oldest || newest > (std::int64_t(1) << 53) || newest - oldest >= f->options_.window ||
        (oldest >= 0 && (!s.contains(Key::state(oldest)) || !s.contains(Key::state(newest)))))
      in.fail("fixed-lag window [" + std::to_string(oldest) + ", " + std::to_string(newest) +
              "] does not match its variables or window " + std::to_string(f->options_.window));
    f->oldest_ = oldest;
    f->newest_ = newest;
  }
}

void CheckpointAccess::saveEkf(const ExtendedKalmanFilter& f, ByteWriter& out) {
  out.f64(f.t_);
  out.vec(f.z_);
  out.mat(f.P_);
  out.f64(f.nis_);
}

void CheckpointAccess::loadEkf(ExtendedKalmanFilter& f, ByteReader& in) {
  const double t = in.f64("EKF time");
  Eigen::VectorXd z = in.vec("EKF mean");
  Eigen::MatrixXd P = in.mat("EKF covariance");
  const double nis = in.f64("EKF NIS", true);
  const Eigen::Index n = f.model_->dims().nc + f.model_->dims().nb;
  if (z.size() != n || P.rows() != n || P.cols() != n)
    in.fail("EKF state has size " + std::to_string(z.size()) + " (covariance " + std::to_string(P.rows()) +
            " x " + std::to_string(P.cols()) + "), the model's stacked state " + std::to_string(n));
  f.t_ = t;
  f.z_ = std::move(z);
  f.P_ = std::move(P);
  f.nis_ = nis;
}

}  // namespace gssm::internal

namespace gssm {

void SmootherCore::save(internal::ByteWriter& out) const {
  engine.save(out);
  internal::CheckpointAccess::writeUpdateReport(out, last);
  out.vec(constants_at_last_check_);
}

void SmootherCore::load(internal::ByteReader& in, const Model& model) {
  internal::BayesTreeEngine e = engine;
  e.load(in, model);
  UpdateReport r = internal::CheckpointAccess::readUpdateReport(in);
  Eigen::VectorXd c = in.vec("constants at the last relinearization check");
  if (c.size() != 0 && c.size() != model.dims().nb) in.fail("constants at the last check have the wrong size");
  engine = std::move(e);
  last = std::move(r);
  constants_at_last_check_ = std::move(c);
}

}  // namespace gssm
