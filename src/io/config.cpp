#include "gssm/io/config.h"

#include "gssm/core/error.h"
#include "gssm/models/linear.h"
#include "gssm/models/nav2d.h"
#include "gssm/models/radar2d.h"
#include "gssm/models/range_beacon2d.h"
#include "gssm/io/csv.h"

#include <cmath>
#include <filesystem>
#include <sstream>

namespace gssm::io {

namespace {
// Reads Q, R, T and the priors, which every model has.
ModelNoise readNoise(const IniDocument& ini, int nc, int nb, int ny) {
  ModelNoise n;
  n.T = ini.getDouble("model", "T");
  n.Q = ini.getMatrix("model", "Q", nc, nc);
  n.R = ini.getMatrix("model", "R", ny, ny);
  n.prior_state.mean = ini.getVector("prior", "state_mean", nc);
  n.prior_state.covariance = ini.getMatrix("prior", "state_cov", nc, nc);
  n.prior_constants.mean = nb ? ini.getVector("prior", "constants_mean", nb) : Eigen::VectorXd();
  n.prior_constants.covariance =
      nb ? ini.getMatrix("prior", "constants_cov", nb, nb) : Eigen::MatrixXd();
  return n;
}

// Model constructors validate covariances; prefix their messages with the file.
template <class Fn>
std::unique_ptr<Model> withSource(const IniDocument& ini, Fn make) {
  try {
    return make();
  } catch (const InputError&) {
    throw;
  } catch (const Error& e) {
    throw InputError(ini.source() + ": " + e.what());
  }
}
}  // namespace

// A file named in the INI: in the dataset folder when one is given, else
// beside the INI.
std::string dataFile(const IniDocument& ini, const std::string& data_dir, const std::string& file) {
  const std::filesystem::path p(file);
  if (p.is_absolute()) return file;
  const std::filesystem::path base = data_dir.empty() ? std::filesystem::path(ini.source()).parent_path()
                                                      : std::filesystem::path(data_dir);
  return (base / p).string();
}

RobustLoss readLoss(const IniDocument& ini, const std::string& section) {
  RobustLoss loss;
  const std::string kind = ini.getString(section, "loss", "none");
  bool known = false;
  for (auto k : {RobustLoss::Kind::None, RobustLoss::Kind::Huber, RobustLoss::Kind::Cauchy, RobustLoss::Kind::Tukey})
    if (kind == RobustLoss::name(k)) loss.kind = k, known = true;
  if (!known)
    throw InputError(ini.source() + ": [" + section + "] loss = '" + kind + "': expected none, huber, cauchy or tukey");
  loss.scale = ini.getDouble(section, "loss_scale", loss.kind == RobustLoss::Kind::Huber ? 1.345 : 2.5);
  std::string why;
  if (!loss.validate(&why)) throw InputError(ini.source() + ": [" + section + "] " + why);
  return loss;
}

// [model] beacons of a range-beacon model: a CSV file (beacon,x,y) beside
// the INI, or inline rows "id x y".
void readBeacons(const IniDocument& ini, const std::string& data_dir, std::vector<int>& ids,
                 std::vector<Eigen::Vector2d>& positions) {
  const std::string beacons = ini.getString("model", "beacons");
  // Inline rows of numbers, or the name of a file (anything else).
  if (beacons.find_first_not_of("0123456789.-+eE \t;,[]") == std::string::npos) {
    const Eigen::MatrixXd B = ini.getMatrix("model", "beacons");
    if (B.cols() != 3) throw InputError(ini.source() + ": [model] beacons: expected rows of 'id x y' or a CSV file");
    for (Eigen::Index i = 0; i < B.rows(); ++i) {
      ids.push_back(static_cast<int>(B(i, 0)));
      positions.emplace_back(B(i, 1), B(i, 2));
    }
    return;
  }
  const CsvTable t = readCsv(dataFile(ini, data_dir, beacons));
  const int id = t.column("beacon"), x = t.column("x"), y = t.column("y");
  if (id < 0 || x < 0 || y < 0) throw InputError(t.source + ":1: expected columns beacon,x,y");
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    const double v = t.rows[r][static_cast<std::size_t>(id)];
    if (v != std::floor(v))
      throw InputError(t.source + ":" + std::to_string(t.line_of_row[r]) + ": column 'beacon': id must be an integer");
    ids.push_back(static_cast<int>(v));
    positions.emplace_back(t.rows[r][static_cast<std::size_t>(x)], t.rows[r][static_cast<std::size_t>(y)]);
  }
}

// [model] type = range_beacon_2d: beacons from a CSV file (beacon,x,y) or
// inline rows "id x y"; [prior] start from the truth file's first row or
// given.
std::unique_ptr<Model> makeRangeBeacon2D(const IniDocument& ini, const std::string& data_dir) {
  ini.requireOnlyKeys("model", {"type", "T", "beacons", "range_scale", "range_offsets", "odometry_scale", "range_sd",
                                "distance_sd", "turn_sd", "heading_drift_sd", "position_sd_per_s", "heading_sd_per_s",
                                "loss", "loss_scale", "ekf_gate"});
  ini.requireOnlyKeys("prior", {"start", "position_sd", "heading", "heading_sd", "range_scale_sd", "range_offset_sd",
                                "odometry_scale_sd"});
  models::RangeBeacon2D::Params p;
  p.T = ini.getDouble("model", "T", p.T);
  readBeacons(ini, data_dir, p.beacon_ids, p.beacons);
  p.range_scale = ini.getBool("model", "range_scale", p.range_scale);
  p.range_offsets = ini.getBool("model", "range_offsets", p.range_offsets);
  p.odometry_scale = ini.getBool("model", "odometry_scale", p.odometry_scale);
  p.range_sd = ini.getDouble("model", "range_sd", p.range_sd);
  p.distance_sd = ini.getDouble("model", "distance_sd", p.distance_sd);
  p.turn_sd = ini.getDouble("model", "turn_sd", p.turn_sd);
  p.heading_drift_sd = ini.getDouble("model", "heading_drift_sd", p.heading_drift_sd);
  p.position_sd_per_s = ini.getDouble("model", "position_sd_per_s", p.position_sd_per_s);
  p.heading_sd_per_s = ini.getDouble("model", "heading_sd_per_s", p.heading_sd_per_s);
  p.range_loss = readLoss(ini, "model");
  p.ekf_gate = ini.getDouble("model", "ekf_gate", 0.0);
  const std::string start = ini.getString("prior", "start", "0 0");
  if (start == "truth") {  // the first row of the dataset's truth file
    const std::string truth = ini.getString("dataset", "truth", "truth.csv");
    const CsvTable t = readCsv(dataFile(ini, data_dir, truth));
    const int px = t.column("px"), py = t.column("py");
    if (px < 0 || py < 0 || t.rows.empty())
      throw InputError(t.source + ": [prior] start = truth needs columns px, py and a first row");
    p.start.head<2>() << t.rows[0][static_cast<std::size_t>(px)], t.rows[0][static_cast<std::size_t>(py)];
  } else {
    p.start.head<2>() = ini.getVector("prior", "start", 2);
  }
  p.start[2] = ini.getDouble("prior", "heading", 0.0);
  const double psd = ini.getDouble("prior", "position_sd", 1.0);
  p.start_sd << psd, psd, ini.getDouble("prior", "heading_sd", M_PI);
  p.range_scale_sd = ini.getDouble("prior", "range_scale_sd", p.range_scale_sd);
  p.range_offset_sd = ini.getDouble("prior", "range_offset_sd", p.range_offset_sd);
  p.odometry_scale_sd = ini.getDouble("prior", "odometry_scale_sd", p.odometry_scale_sd);
  return withSource(ini, [&] { return std::unique_ptr<Model>(std::make_unique<models::RangeBeacon2D>(p)); });
}

std::unique_ptr<Model> makeModel(const IniDocument& ini, const std::string& data_dir) {
  const std::string type = ini.getString("model", "type");
  if (type == "radar2d") {
    ini.requireOnlyKeys("model", {"type", "T", "Q", "R"});
    return withSource(ini, [&] {
      return std::make_unique<models::Radar2D>(readNoise(ini, 1, 2, 1));
    });
  }
  if (type == "linear") {
    ini.requireOnlyKeys("model", {"type", "T", "Q", "R", "A_c", "A_b", "B", "C_c", "C_b",
                                  "discretization", "channels"});
    models::LinearSystem s;
    s.A_c = ini.getMatrix("model", "A_c");
    const auto nc = s.A_c.rows();
    s.C_c = ini.getMatrix("model", "C_c");
    // No A_b and C_b: a model without constants (n_b = 0).
    s.A_b = ini.has("model", "A_b") ? ini.getMatrix("model", "A_b") : Eigen::MatrixXd::Zero(nc, 0);
    s.C_b = ini.has("model", "C_b") ? ini.getMatrix("model", "C_b") : Eigen::MatrixXd::Zero(s.C_c.rows(), 0);
    s.B = ini.has("model", "B") ? ini.getMatrix("model", "B") : Eigen::MatrixXd::Zero(nc, 0);
    // Further sensors: channels = gps wheel, each in its own [channel.<name>].
    std::istringstream names(ini.getString("model", "channels", ""));
    for (std::string name; names >> name;) {
      const std::string section = "channel." + name;
      if (!ini.hasSection(section))
        throw InputError(ini.source() + ": [model] channels names '" + name + "' but there is no [" + section + "]");
      ini.requireOnlyKeys(section, {"C_c", "C_b", "R"});
      models::LinearChannel c;
      c.name = name;
      c.C_c = ini.getMatrix(section, "C_c");
      c.C_b = ini.has(section, "C_b") ? ini.getMatrix(section, "C_b") : Eigen::MatrixXd::Zero(c.C_c.rows(), 0);
      c.R = ini.getMatrix(section, "R");
      s.channels.push_back(std::move(c));
    }
    s.noise = readNoise(ini, static_cast<int>(nc), static_cast<int>(s.A_b.cols()),
                        static_cast<int>(s.C_c.rows()));
    const std::string disc = ini.getString("model", "discretization", "euler");
    if (disc != "euler" && disc != "exact")
      throw InputError(ini.source() + ": [model] discretization = '" + disc +
                       "': expected euler or exact");
    return withSource(ini, [&] {
      return std::make_unique<models::LinearModel>(
          s, disc == "exact" ? models::Discretization::Exact : models::Discretization::Euler);
    });
  }
  if (type == "nav2d") {
    ini.requireOnlyKeys("model", {"type", "T", "R", "accel_noise", "beacons"});
    const Eigen::MatrixXd B = ini.getMatrix("model", "beacons");
    if (B.cols() != 2 || B.rows() < 1)
      throw InputError(ini.source() + ": [model] beacons: expected rows of 'x y', one per beacon");
    std::vector<Eigen::Vector2d> beacons;
    for (Eigen::Index i = 0; i < B.rows(); ++i) beacons.emplace_back(B(i, 0), B(i, 1));
    const double q = ini.getDouble("model", "accel_noise");
    ModelNoise n;
    n.T = ini.getDouble("model", "T");
    n.R = ini.getMatrix("model", "R", B.rows(), B.rows());
    n.prior_state.mean = ini.getVector("prior", "state_mean", 4);
    n.prior_state.covariance = ini.getMatrix("prior", "state_cov", 4, 4);
    n.prior_constants.mean = ini.getVector("prior", "constants_mean", 3);
    n.prior_constants.covariance = ini.getMatrix("prior", "constants_cov", 3, 3);
    return withSource(ini, [&] {
      n.Q = Eigen::MatrixXd::Identity(4, 4);  // replaced by the white-acceleration model
      auto m = std::make_unique<models::Nav2D>(n, beacons, q);
      return std::unique_ptr<Model>(std::move(m));
    });
  }
  if (type == "range_beacon_2d") return makeRangeBeacon2D(ini, data_dir);
  throw InputError(ini.source() + ": [model] type = '" + type +
                   "': unknown model (known: radar2d, linear, nav2d, range_beacon_2d)");
}

std::vector<Eigen::Vector2d> landmarks(const IniDocument& ini, const std::string& data_dir) {
  std::vector<Eigen::Vector2d> out;
  if (!ini.has("model", "beacons")) return out;
  if (ini.getString("model", "type") == "range_beacon_2d") {
    std::vector<int> ids;
    readBeacons(ini, data_dir, ids, out);
    return out;
  }
  const Eigen::MatrixXd B = ini.getMatrix("model", "beacons");
  if (B.cols() != 2) throw InputError(ini.source() + ": [model] beacons: expected rows of 'x y', one per beacon");
  for (Eigen::Index i = 0; i < B.rows(); ++i) out.emplace_back(B(i, 0), B(i, 1));
  return out;
}

void writeModel(const Model& model, IniDocument& ini) {
  ini.set("model", "type", model.name());
  if (const auto* rb = dynamic_cast<const models::RangeBeacon2D*>(&model)) {
    const auto& p = rb->params();
    Eigen::MatrixXd B(static_cast<Eigen::Index>(p.beacons.size()), 3);
    for (std::size_t i = 0; i < p.beacons.size(); ++i)
      B.row(static_cast<Eigen::Index>(i)) << p.beacon_ids[i], p.beacons[i].x(), p.beacons[i].y();
    ini.set("model", "T", p.T);
    ini.set("model", "beacons", B);
    ini.set("model", "range_scale", p.range_scale ? "true" : "false");
    ini.set("model", "range_offsets", p.range_offsets ? "true" : "false");
    ini.set("model", "odometry_scale", p.odometry_scale ? "true" : "false");
    ini.set("model", "range_sd", p.range_sd);
    ini.set("model", "distance_sd", p.distance_sd);
    ini.set("model", "turn_sd", p.turn_sd);
    ini.set("model", "heading_drift_sd", p.heading_drift_sd);
    ini.set("model", "position_sd_per_s", p.position_sd_per_s);
    ini.set("model", "heading_sd_per_s", p.heading_sd_per_s);
    ini.set("model", "loss", RobustLoss::name(p.range_loss.kind));
    ini.set("model", "loss_scale", p.range_loss.scale);
    ini.set("model", "ekf_gate", p.ekf_gate);
    ini.set("prior", "start", Eigen::MatrixXd(p.start.head<2>().transpose()));
    ini.set("prior", "position_sd", p.start_sd[0]);
    ini.set("prior", "heading", p.start[2]);
    ini.set("prior", "heading_sd", p.start_sd[2]);
    ini.set("prior", "range_scale_sd", p.range_scale_sd);
    ini.set("prior", "range_offset_sd", p.range_offset_sd);
    ini.set("prior", "odometry_scale_sd", p.odometry_scale_sd);
    return;
  }
  if (const auto* lin = dynamic_cast<const models::LinearModel*>(&model)) {
    const auto& s = lin->system();
    ini.set("model", "A_c", s.A_c);
    if (s.A_b.cols() > 0) ini.set("model", "A_b", s.A_b);
    if (s.B.size()) ini.set("model", "B", s.B);
    ini.set("model", "C_c", s.C_c);
    if (s.C_b.cols() > 0) ini.set("model", "C_b", s.C_b);
    std::string channels;
    for (const auto& c : s.channels) {
      channels += (channels.empty() ? "" : " ") + c.name;
      ini.set("channel." + c.name, "C_c", c.C_c);
      if (c.C_b.cols() > 0) ini.set("channel." + c.name, "C_b", c.C_b);
      ini.set("channel." + c.name, "R", c.R);
    }
    if (!channels.empty()) ini.set("model", "channels", channels);
    ini.set("model", "discretization",
            lin->discretization() == models::Discretization::Exact ? "exact" : "euler");
  } else if (const auto* nav = dynamic_cast<const models::Nav2D*>(&model)) {
    Eigen::MatrixXd B(static_cast<Eigen::Index>(nav->beacons().size()), 2);
    for (std::size_t i = 0; i < nav->beacons().size(); ++i) B.row(static_cast<Eigen::Index>(i)) = nav->beacons()[i].transpose();
    ini.set("model", "beacons", B);
    ini.set("model", "accel_noise", nav->accelNoise());
  } else if (model.name() != "radar2d") {
    throw InvalidArgument("writeModel: model '" + model.name() + "' has no INI form");
  }
  ini.set("model", "T", model.nominalStep());
  if (!dynamic_cast<const models::Nav2D*>(&model)) ini.set("model", "Q", model.noise().Q);
  ini.set("model", "R", model.noise().R);
  ini.set("prior", "state_mean", Eigen::MatrixXd(model.priorState().mean.transpose()));
  ini.set("prior", "state_cov", model.priorState().covariance);
  if (model.dims().nb > 0) {
    ini.set("prior", "constants_mean", Eigen::MatrixXd(model.priorConstants().mean.transpose()));
    ini.set("prior", "constants_cov", model.priorConstants().covariance);
  }
}

namespace {
// Each method's own INI section, from the method table.
std::string sectionOf(Method m) { return methodInfo(m).ini_section; }

ExtendedKalmanFilterOptions ekfOptions(const IniDocument& ini, const Model& model) {
  const std::string ekf = sectionOf(Method::Ekf);
  ini.requireOnlyKeys(ekf, {"constant_process_noise", "joseph_form"});
  ExtendedKalmanFilterOptions o;
  if (ini.has(ekf, "constant_process_noise"))
    o.constant_process_noise = ini.getVector(ekf, "constant_process_noise", model.dims().nb);
  o.joseph_form = ini.getBool(ekf, "joseph_form", true);
  std::string why;
  if (!o.validate(model.dims().nb, &why)) throw InputError(ini.source() + ": [" + ekf + "] " + why);
  return o;
}

void readSmoother(const IniDocument& ini, EstimatorOptions& eo) {
  const std::string smoother = sectionOf(Method::Incremental);  // the fixed lag reads it too
  ini.requireOnlyKeys(smoother, {"relinearize", "relinearize_threshold", "constants_check_sigmas",
                                   "max_local_iterations", "wildfire_threshold", "ordering",
                                   "iterate_to_convergence", "convergence_tolerance", "max_iterations",
                                   "newton_polish_steps"});
  SmootherOptions& o = eo.smoother;
  o.relinearize = ini.getBool(smoother, "relinearize", o.relinearize);
  o.relinearize_threshold = ini.getDouble(smoother, "relinearize_threshold", o.relinearize_threshold);
  o.constants_check_sigmas = ini.getDouble(smoother, "constants_check_sigmas", o.constants_check_sigmas);
  o.max_local_iterations =
      static_cast<int>(ini.getInt(smoother, "max_local_iterations", o.max_local_iterations));
  o.wildfire_threshold = ini.getDouble(smoother, "wildfire_threshold", o.wildfire_threshold);
  o.iterate_to_convergence = ini.getBool(smoother, "iterate_to_convergence", o.iterate_to_convergence);
  o.convergence_tolerance = ini.getDouble(smoother, "convergence_tolerance", o.convergence_tolerance);
  o.max_iterations = static_cast<int>(ini.getInt(smoother, "max_iterations", o.max_iterations));
  o.newton_polish_steps = static_cast<int>(ini.getInt(smoother, "newton_polish_steps", o.newton_polish_steps));
  const std::string ordering = ini.getString(smoother, "ordering", orderingName(eo.incremental.ordering));
  const auto named = orderingNamed(ordering);
  if (!named)
    throw InputError(ini.source() + ": [" + smoother + "] ordering = '" + ordering + "': expected colamd or time");
  eo.incremental.ordering = *named;
  std::string why;
  if (!o.validate(&why)) throw InputError(ini.source() + ": [" + smoother + "] " + why);
}

int readWindow(const IniDocument& ini, const std::string& section, int fallback) {
  ini.requireOnlyKeys(section, {"window"});
  const long long w = ini.getInt(section, "window", fallback);
  if (w < 1 || w > 10000000)
    throw InputError(ini.source() + ": [" + section + "] window = " + std::to_string(w) + ": expected >= 1");
  return static_cast<int>(w);
}

void readBatch(const IniDocument& ini, BatchSolverOptions& o) {
  const std::string batch = sectionOf(Method::Batch);
  ini.requireOnlyKeys(batch, {"algorithm", "max_iterations", "newton_polish_steps", "initial_lambda"});
  const std::string algorithm = ini.getString(batch, "algorithm", BatchSolverOptions::methodName(o.method));
  const auto named = BatchSolverOptions::methodNamed(algorithm);
  if (!named)
    throw InputError(ini.source() + ": [" + batch + "] algorithm = '" + algorithm +
                     "': expected levenberg-marquardt or gauss-newton");
  o.method = *named;
  o.max_iterations = static_cast<int>(ini.getInt(batch, "max_iterations", o.max_iterations));
  o.newton_polish_steps = static_cast<int>(ini.getInt(batch, "newton_polish_steps", o.newton_polish_steps));
  o.initial_lambda = ini.getDouble(batch, "initial_lambda", o.initial_lambda);
  std::string why;
  if (!o.validate(&why)) throw InputError(ini.source() + ": [" + batch + "] " + why);
}
}  // namespace

Method parseMethod(const std::string& text, const std::string& where) {
  if (const auto m = methodNamed(text)) return *m;
  throw InputError(where + " = '" + text + "': unknown method (known: " + methodNameList() + ")");
}

EstimatorOptions estimatorOptions(const IniDocument& ini, const Model& model, Method method) {
  EstimatorOptions o(method);
  o.ekf = ekfOptions(ini, model);
  readSmoother(ini, o);
  o.fixed_lag.window = readWindow(ini, sectionOf(Method::FixedLag), o.fixed_lag.window);
  o.paper_window.window = readWindow(ini, sectionOf(Method::PaperWindow), o.paper_window.window);
  readBatch(ini, o.batch);
  return o;
}

SimulationSpec simulationSpec(const IniDocument& ini, const Model& model) {
  SimulationSpec s;
  s.steps = static_cast<int>(ini.getInt("scenario", "steps"));
  if (s.steps < 1) throw InputError(ini.source() + ": [scenario] steps must be >= 1");
  if (ini.has("truth", "state0")) s.x0 = ini.getVector("truth", "state0", model.dims().nc);
  if (ini.has("truth", "constants"))
    s.xb = ini.getVector("truth", "constants", model.dims().nb);
  s.process_noise = ini.getBool("truth", "process_noise", true);
  s.measurement_noise = ini.getBool("truth", "measurement_noise", true);
  s.measure_every = static_cast<int>(ini.getInt("scenario", "measure_every", 1));
  if (s.measure_every < 1) throw InputError(ini.source() + ": [scenario] measure_every must be >= 1");
  // Several sensors taking turns: "cycle" = every channel of the model in turn.
  const std::string channels = ini.getString("scenario", "channels", "default");
  if (channels == "cycle") {
    s.channels.clear();
    for (int c = 0; c < model.numChannels(); ++c) s.channels.push_back(c);
  } else if (channels != "default") {
    throw InputError(ini.source() + ": [scenario] channels = '" + channels + "': expected default or cycle");
  }
  // A constant measured input (odometry speed and turn rate: a circle).
  if (ini.has("truth", "input")) {
    const Eigen::VectorXd u = ini.getVector("truth", "input", model.dims().nu);
    s.input = [u](double, const Eigen::VectorXd&) { return u; };
  }
  // Input profile: true acceleration a(t) = amplitude·(cos ωt, sin ωt) (a
  // turning vehicle); an accelerometer measures a + b_a, the first n_u
  // constants being its bias (Nav2D).
  if (ini.has("truth", "input_amplitude")) {
    const double amp = ini.getDouble("truth", "input_amplitude");
    const double omega = ini.getDouble("truth", "input_omega");
    const int nu = model.dims().nu;
    const bool biased = ini.getBool("truth", "input_includes_bias", true) && model.dims().nb >= nu;
    s.input = [amp, omega, nu, biased](double t, const Eigen::VectorXd& xb) {
      Eigen::VectorXd u = Eigen::VectorXd::Zero(nu);
      for (int i = 0; i + 1 < nu; i += 2) {
        u[i] = amp * std::cos(omega * t);
        u[i + 1] = amp * std::sin(omega * t);
      }
      if (biased) u += xb.head(nu);
      return u;
    };
  }
  return s;
}

LoadedScenario loadScenario(const IniDocument& scenario, const IniDocument* estimator_config) {
  LoadedScenario out;
  out.truth = makeModel(scenario);
  if (estimator_config) out.estimator = makeModel(*estimator_config);
  const Model& est = out.estimator ? *out.estimator : *out.truth;
  out.scenario.name = scenario.getString("scenario", "name", "?");
  out.scenario.truth = out.truth.get();
  out.scenario.spec = simulationSpec(scenario, *out.truth);
  out.scenario.estimator = out.estimator.get();
  out.scenario.options = estimatorOptions(estimator_config ? *estimator_config : scenario, est);
  return out;
}

std::vector<std::string> scenarioNames() {
  return {"paper", "consistent", "nav-paper-like", "nav-consistent", "beacons-plaza-like", "beacons-consistent"};
}

IniDocument builtinScenario(const std::string& name, unsigned seed, int steps) {
  IniDocument ini;
  ini.set("scenario", "name", name);
  ini.set("scenario", "seed", std::to_string(seed));
  ini.set("scenario", "steps", std::to_string(steps));
  if (name.rfind("beacons-", 0) == 0) {
    // The Plaza logs' kind, simulated: a vehicle circling (3 m/s, 0.1 rad/s)
    // inside four beacons, odometry at 10 Hz, a range every 2nd step, the
    // beacons in turn, ranges 7% long.
    models::RangeBeacon2D::Params p;
    p.beacon_ids = {0, 1, 5, 6};
    p.beacons = {{-33.6, 27.0}, {-68.9, 18.4}, {1.7, -5.8}, {-37.6, 69.2}};
    p.start = Eigen::Vector3d(-34, 55, 0);
    p.start_sd = Eigen::Vector3d(1, 1, 0.5);
    p.range_sd = 0.5;
    const models::RangeBeacon2D rb(p);
    writeModel(rb, ini);
    ini.set("scenario", "measure_every", "2");
    ini.set("scenario", "channels", "cycle");
    ini.set("truth", "input", Eigen::MatrixXd(Eigen::RowVector2d(3.0, 0.1)));
    ini.set("truth", "measurement_noise", "true");
    if (name == "beacons-plaza-like") {
      ini.setComment("scenario",
                     "RangeBeacon2D like the CMU Plaza logs: ranges 7% long (range scale 1.07, 0.7 prior sd\n"
                     "from its mean 1), heading 0.3 rad off the prior mean; no process noise in the truth.");
      ini.set("truth", "state0", Eigen::MatrixXd(Eigen::RowVector3d(-34, 55, 0.3)));
      ini.set("truth", "constants", Eigen::MatrixXd::Constant(1, 1, 1.07));
      ini.set("truth", "process_noise", "false");
    } else if (name == "beacons-consistent") {
      ini.setComment("scenario", "RangeBeacon2D with the truth drawn from the estimators' own prior and noise models.");
      ini.set("truth", "process_noise", "true");
    } else {
      throw InvalidArgument("unknown scenario '" + name + "'");
    }
    return ini;
  }
  if (name.rfind("nav-", 0) == 0) {
    const models::Nav2D nav;
    writeModel(nav, ini);
    ini.set("scenario", "measure_every", "5");  // ranges at 2 Hz, accelerometer at 10 Hz
    // Centripetal acceleration of a 50 m circle at 0.1 rad/s about (100, 100).
    ini.set("truth", "input_amplitude", -0.5);
    ini.set("truth", "input_omega", 0.1);
    ini.set(sectionOf(Method::Ekf), "constant_process_noise", Eigen::MatrixXd(Eigen::RowVector3d::Zero()));
    if (name == "nav-paper-like") {
      ini.setComment("scenario",
                     "Nav2D with priors several sigmas from the truth, as in the radar paper scenario:\n"
                     "position 10 m (2 sd) and velocity 3 m/s (3 sd) off, accelerometer bias 2.5 sd,\n"
                     "range bias 4 sd; no process noise in the truth.");
      ini.set("prior", "state_mean", Eigen::MatrixXd(Eigen::RowVector4d(140, 110, 3, 2)));
      ini.set("truth", "state0", Eigen::MatrixXd(Eigen::RowVector4d(150, 100, 0, 5)));
      ini.set("truth", "constants", Eigen::MatrixXd(Eigen::RowVector3d(0.25, -0.15, 20)));
      ini.set("truth", "process_noise", "false");
    } else if (name == "nav-consistent") {
      ini.setComment("scenario", "Nav2D with the truth drawn from the estimators' own prior and noise models.");
      ini.set("truth", "process_noise", "true");
    } else {
      throw InvalidArgument("unknown scenario '" + name + "'");
    }
    ini.set("truth", "measurement_noise", "true");
    return ini;
  }
  const models::Radar2D radar;  // the paper's settings
  writeModel(radar, ini);
  if (name == "paper") {
    ini.setComment("scenario",
                   "The paper's radar example: truth x(0) = 0, xdot = 100, h = 1000, no process\n"
                   "noise, range noise sigma = 3; the estimators keep the paper's prior\n"
                   "(-100, 200, 2000, variance 49), many sigmas from the truth.");
    ini.set("truth", "state0", Eigen::MatrixXd::Constant(1, 1, 0.0));
    ini.set("truth", "constants", Eigen::MatrixXd(Eigen::RowVector2d(100, 1000)));
    ini.set("truth", "process_noise", "false");
    ini.set("truth", "measurement_noise", "true");
    // The paper's EKF: Q = diag(0.005², 0.005², 0) on [x, xdot, h].
    ini.set(sectionOf(Method::Ekf), "constant_process_noise",
            Eigen::MatrixXd(Eigen::RowVector2d(0.005 * 0.005, 0.0)));
  } else if (name == "consistent") {
    ini.setComment("scenario",
                   "Radar with the truth drawn from the estimators' own prior and noise\n"
                   "models, so a consistent estimator's NEES averages about 3.");
    ini.set("truth", "process_noise", "true");
    ini.set("truth", "measurement_noise", "true");
    ini.set(sectionOf(Method::Ekf), "constant_process_noise", Eigen::MatrixXd(Eigen::RowVector2d(0.0, 0.0)));
  } else {
    std::string known;
    for (const auto& n : scenarioNames()) known += (known.empty() ? "" : ", ") + n;
    throw InvalidArgument("unknown scenario '" + name + "' (known: " + known + ")");
  }
  return ini;
}

}  // namespace gssm::io
