#include "checkpoint/access.h"

#include "solvers/smoother_core.h"

namespace gssm::internal {

namespace {
// One field list per record, visited by a writer or a reader, so the two
// directions cannot drift apart.
struct FieldWriter {
  ByteWriter& out;
  void operator()(const double& v, const char*, bool = false) { out.f64(v); }
  void operator()(const int& v, const char*) { out.i32(v); }
  void operator()(const bool& v, const char*) { out.boolean(v); }
  void operator()(const std::size_t& v, const char*) { out.u64(v); }
  void operator()(const std::int64_t& v, const char*) { out.i64(v); }
  void operator()(const std::string& v, const char*) { out.str(v); }
  void operator()(const Eigen::VectorXd& v, const char*) { out.vec(v); }
  void operator()(const Method& m, const char*) { out.str(methodName(m)); }  // by name: stable
  template <class Enum>
  void enumeration(const Enum& v, int, const char*) { out.u8(static_cast<std::uint8_t>(v)); }
};

struct FieldReader {
  ByteReader& in;
  void operator()(double& v, const char* what, bool allow_nonfinite = false) { v = in.f64(what, allow_nonfinite); }
  void operator()(int& v, const char* what) { v = in.i32(what); }
  void operator()(bool& v, const char* what) { v = in.boolean(what); }
  void operator()(std::size_t& v, const char* what) { v = in.u64(what); }
  void operator()(std::int64_t& v, const char* what) { v = in.i64(what); }
  void operator()(std::string& v, const char* what) { v = in.str(what); }
  void operator()(Eigen::VectorXd& v, const char* what) { v = in.vec(what); }
  void operator()(Method& m, const char* what) {
    const std::string name = in.str(what);
    const auto method = methodNamed(name);
    if (!method || !methodInfo(*method).streaming) in.fail(std::string(what) + ": no streaming method '" + name + "'");
    m = *method;
  }
  template <class Enum>
  void enumeration(Enum& v, int max, const char* what) {
    const std::uint8_t raw = in.u8(what);
    if (raw > max) in.fail(std::string(what) + ": unknown value " + std::to_string(raw));
    v = static_cast<Enum>(raw);
  }
};

// Options and reports are visited through non-const references; writing
// goes through a copy.
template <class Io>
void fields(Io& io, EstimatorOptions& o) {
  io(o.method, "estimator method");
  // Format v1 holds one window: the method's (read after the method).
  io(o.method == Method::PaperWindow ? o.paper_window.window : o.fixed_lag.window, "window");
  io(o.ekf.constant_process_noise, "ekf constant_process_noise");
  io(o.ekf.joseph_form, "ekf joseph_form");
  SmootherOptions& s = o.smoother;
  io.enumeration(o.incremental.ordering, 1, "smoother ordering");
  io(s.relinearize, "smoother relinearize");
  io(s.relinearize_threshold, "smoother relinearize_threshold");
  io(s.constants_check_sigmas, "smoother constants_check_sigmas");
  io(s.max_local_iterations, "smoother max_local_iterations");
  io(s.wildfire_threshold, "smoother wildfire_threshold", true);  // ∞ = lazy
  io(s.iterate_to_convergence, "smoother iterate_to_convergence");
  io(s.convergence_tolerance, "smoother convergence_tolerance");
  io(s.max_iterations, "smoother max_iterations");
  io(s.newton_polish_steps, "smoother newton_polish_steps");
  io(o.t0, "t0");
  io(o.compute_nis, "compute_nis");
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

template <class Io>
void fields(Io& io, EstimatorReport& r) {  // all but the method, which the options carry
  io(r.steps, "report steps");
  io(r.seconds, "report seconds");
  io(r.iterations, "report iterations");
  fields(io, r.smoother);
  io(r.detail, "report detail");
  io(r.nis, "report nis", true);  // NaN without compute_nis
}
}  // namespace

void CheckpointAccess::writeOptions(ByteWriter& out, const EstimatorOptions& o) {
  FieldWriter w{out};
  EstimatorOptions copy = o;
  fields(w, copy);
}

EstimatorOptions CheckpointAccess::readOptions(ByteReader& in) {
  FieldReader r{in};
  EstimatorOptions o;
  fields(r, o);
  return o;
}

void CheckpointAccess::writeUpdateReport(ByteWriter& out, const UpdateReport& report) {
  FieldWriter w{out};
  UpdateReport copy = report;
  fields(w, copy);
}

UpdateReport CheckpointAccess::readUpdateReport(ByteReader& in) {
  FieldReader r{in};
  UpdateReport report;
  fields(r, report);
  return report;
}

void CheckpointAccess::saveEstimator(const Estimator& e, ByteWriter& out) {
  out.f64(e.t_);
  out.i64(e.k_);
  out.vec(e.input_);
  EstimatorReport r = e.report();  // formats a pending detail line
  FieldWriter w{out};
  fields(w, r);
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
  r.method = e.report_.method;  // what makeEstimator set from the options
  r.window = e.report_.window;
  r.ordering = e.report_.ordering;
  FieldReader reader{in};
  fields(reader, r);
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
