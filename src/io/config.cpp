#include "gssm/io/config.h"

#include "gssm/core/error.h"
#include "gssm/models/nav2d.h"
#include "gssm/models/radar2d.h"
#include "gssm/models/range_beacon2d.h"

#include <cmath>
#include <limits>

#include "gssm/estimator/option_keys.h"

namespace gssm::io {

namespace {
// Each method's own INI section, from the method table.
std::string sectionOf(Method m) { return methodInfo(m).ini_section; }

// Reads, from one section, every key that optionKeys names for an options
// struct (docs/DESIGN.md §4); absent keys keep the value given.
class IniOptionReader {
 public:
  IniOptionReader(const IniDocument& ini, std::string section) : ini_(ini), section_(std::move(section)) {}
  void operator()(const char* key, bool& v, const char* /*doc*/) const { v = ini_.getBool(section_, key, v); }
  void operator()(const char* key, double& v, const char* /*doc*/) const { v = ini_.getDouble(section_, key, v); }
  void operator()(const char* key, Eigen::VectorXd& v, const char* /*doc*/) const {
    if (ini_.has(section_, key)) v = ini_.getVector(section_, key);
  }
  void operator()(const char* key, int& v, const char* /*doc*/) const {
    const long long n = ini_.getInt(section_, key, v);
    if (n < std::numeric_limits<int>::min() || n > std::numeric_limits<int>::max())
      throw InputError(ini_.where(section_, key) + " = " + std::to_string(n) + ": out of range");
    v = static_cast<int>(n);
  }
  template <class E>
  void operator()(const char* key, Choice<E>& c, const char* /*doc*/) const {
    const std::string text = ini_.getString(section_, key, c.name(c.value));
    const auto named = c.named(text);
    if (!named) throw InputError(ini_.where(section_, key) + " = '" + text + "': expected " + c.expected);
    c.value = *named;
  }

 private:
  const IniDocument& ini_;
  std::string section_;
};

// Writes every key that optionKeys names for an options struct.
class IniOptionWriter {
 public:
  IniOptionWriter(IniDocument& ini, std::string section) : ini_(ini), section_(std::move(section)) {}
  void operator()(const char* key, bool& v, const char* /*doc*/) { ini_.set(section_, key, v ? "true" : "false"); }
  void operator()(const char* key, int& v, const char* /*doc*/) { ini_.set(section_, key, std::to_string(v)); }
  void operator()(const char* key, double& v, const char* /*doc*/) {
    if (std::isfinite(v)) ini_.set(section_, key, v);  // ∞ (a wildfire threshold: none) is the default; not written
  }
  void operator()(const char* key, Eigen::VectorXd& v, const char* /*doc*/) {
    if (v.size() > 0) ini_.set(section_, key, Eigen::MatrixXd(v.transpose()));
  }
  template <class E>
  void operator()(const char* key, Choice<E>& c, const char* /*doc*/) { ini_.set(section_, key, c.name(c.value)); }

 private:
  IniDocument& ini_;
  std::string section_;
};

// One method's section: its keys (and `extra` ones read by the caller) only.
template <class Options>
void readSection(const IniDocument& ini, const std::string& section, Options& o,
                 std::vector<std::string> extra = {}) {
  std::vector<std::string> keys = optionKeyNames<Options>();
  keys.insert(keys.end(), extra.begin(), extra.end());
  ini.requireOnlyKeys(section, keys);
  IniOptionReader reader(ini, section);
  optionKeys(reader, o);
}

ExtendedKalmanFilterOptions ekfOptions(const IniDocument& ini, const Model& model) {
  const std::string ekf = sectionOf(Method::Ekf);
  ExtendedKalmanFilterOptions o;
  readSection(ini, ekf, o);
  std::string why;
  if (!o.validate(model.dims().nb, &why)) throw InputError(ini.source() + ": [" + ekf + "] " + why);
  return o;
}

// [smoother]'s key beyond SmootherOptions': the incremental smoother's ordering.
const std::vector<std::string> kSmootherOwnKeys{"ordering"};
// [fixed_lag]: its window, and its own relinearization check of the constants.
const std::vector<std::string> kFixedLagKeys{"window", "constants_check_sigmas"};

// [smoother]: the relinearization policy both smoothers share, and the
// incremental smoother's ordering.
void readSmoother(const IniDocument& ini, EstimatorOptions& eo) {
  const std::string smoother = sectionOf(Method::Incremental);  // the fixed lag reads it too
  readSection(ini, smoother, eo.smoother, kSmootherOwnKeys);
  const std::string ordering = ini.getString(smoother, "ordering", orderingName(eo.incremental.ordering));
  const auto named = orderingNamed(ordering);
  if (!named)
    throw InputError(ini.source() + ": [" + smoother + "] ordering = '" + ordering + "': expected colamd or time");
  eo.incremental.ordering = *named;
  std::string why;
  if (!eo.smoother.validate(&why)) throw InputError(ini.source() + ": [" + smoother + "] " + why);
}

int readWindow(const IniDocument& ini, const std::string& section, int fallback,
               const std::vector<std::string>& keys) {
  ini.requireOnlyKeys(section, keys);
  const long long w = ini.getInt(section, "window", fallback);
  if (w < 1 || w > 10000000)
    throw InputError(ini.source() + ": [" + section + "] window = " + std::to_string(w) + ": expected >= 1");
  return static_cast<int>(w);
}

void readBatch(const IniDocument& ini, BatchSolverOptions& o) {
  const std::string batch = sectionOf(Method::Batch);
  readSection(ini, batch, o);
  std::string why;
  if (!o.validate(&why)) throw InputError(ini.source() + ": [" + batch + "] " + why);
}
}  // namespace

BatchSolverOptions batchOptions(const IniDocument& ini) {
  BatchSolverOptions o;
  readBatch(ini, o);
  return o;
}

Method parseMethod(const std::string& text, const std::string& where) {
  if (const auto m = methodNamed(text)) return *m;
  throw InputError(where + " = '" + text + "': unknown method (known: " + methodNameList() + ")");
}

EstimatorOptions estimatorOptions(const IniDocument& ini, const Model& model, Method method) {
  EstimatorOptions o(method);
  o.ekf = ekfOptions(ini, model);
  readSmoother(ini, o);
  o.fixed_lag.window = readWindow(ini, sectionOf(Method::FixedLag), o.fixed_lag.window, kFixedLagKeys);
  o.fixed_lag.constants_check_sigmas =
      ini.getDouble(sectionOf(Method::FixedLag), "constants_check_sigmas", o.fixed_lag.constants_check_sigmas);
  o.paper_window.window = readWindow(ini, sectionOf(Method::PaperWindow), o.paper_window.window, {"window"});
  readBatch(ini, o.batch);
  return o;
}

void writeEstimatorOptions(const EstimatorOptions& options, IniDocument& ini) {
  EstimatorOptions o = options;  // visitors take references
  IniOptionWriter ekf(ini, sectionOf(Method::Ekf)), smoother(ini, sectionOf(Method::Incremental)),
      batch(ini, sectionOf(Method::Batch));
  optionKeys(ekf, o.ekf);
  optionKeys(smoother, o.smoother);
  ini.set(sectionOf(Method::Incremental), "ordering", orderingName(o.incremental.ordering));
  ini.set(sectionOf(Method::FixedLag), "window", std::to_string(o.fixed_lag.window));
  if (!std::isnan(o.fixed_lag.constants_check_sigmas))
    ini.set(sectionOf(Method::FixedLag), "constants_check_sigmas", formatDouble(o.fixed_lag.constants_check_sigmas));
  ini.set(sectionOf(Method::PaperWindow), "window", std::to_string(o.paper_window.window));
  optionKeys(batch, o.batch);
}

std::vector<std::pair<std::string, std::vector<std::string>>> estimatorIniKeys() {
  std::vector<std::string> smoother = optionKeyNames<SmootherOptions>();
  smoother.insert(smoother.end(), kSmootherOwnKeys.begin(), kSmootherOwnKeys.end());
  return {{sectionOf(Method::Ekf), optionKeyNames<ExtendedKalmanFilterOptions>()},
          {sectionOf(Method::Incremental), smoother},
          {sectionOf(Method::FixedLag), kFixedLagKeys},
          {sectionOf(Method::PaperWindow), {"window"}},
          {sectionOf(Method::Batch), optionKeyNames<BatchSolverOptions>()}};
}

std::vector<IniKey> scenarioIniKeys() {
  return {{"name", "word", "(the folder's name)", "the run's name, in figures and reports"},
          {"methods", "words", "(all)", "the methods gssm-process runs when --method is all"},
          {"seed", "integer", "1", "the random seed gssm-simulate drew the data with (a record)"},
          {"steps", "integer", "", "simulated steps (gssm-simulate, gssm-montecarlo)"},
          {"measure_every", "integer", "1", "a simulated measurement every this many steps"},
          {"channels", "word", "default", "simulated measurements on the default channel, or cycle (every channel in turn)"},
          {"band_sigmas", "number", "3",
           "the figures' bands: each estimate ± this many standard deviations"}};
}

std::vector<IniKey> truthIniKeys() {
  return {{"state0", "numbers", "(the prior's mean)", "the simulated x_c at t0"},
          {"constants", "numbers", "(the prior's mean)", "the simulated x_b"},
          {"process_noise", "flag", "true", "draw process noise"},
          {"measurement_noise", "flag", "true", "draw measurement noise"},
          {"input", "numbers", "", "a constant input (odometry speed and turn rate)"},
          {"input_amplitude", "number", "", "an input a·(cos ωt, sin ωt) (a turning vehicle's acceleration)"},
          {"input_omega", "number", "", "its ω (rad/s)"},
          {"input_includes_bias", "flag", "true", "the input measured with the first n_u constants as its bias"}};
}

void requireScenarioKeys(const IniDocument& ini) {
  ini.requireOnlyKeys("scenario", iniKeyNames(scenarioIniKeys()));
  ini.requireOnlyKeys("truth", iniKeyNames(truthIniKeys()));
  figureBandSigmas(ini);  // a bad width refused before the run, not after it
}

double figureBandSigmas(const IniDocument& ini) {
  const double k = ini.getDouble("scenario", "band_sigmas", 3.0);
  if (!(k > 0) || !std::isfinite(k))
    throw InputError(ini.where("scenario", "band_sigmas") + ": the figures' band width must be a positive number of "
                     "standard deviations");
  return k;
}

SimulationSpec simulationSpec(const IniDocument& ini, const Model& model) {
  requireScenarioKeys(ini);
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

namespace {
// beacons-*: the Plaza logs' kind, simulated: a vehicle circling (3 m/s,
// 0.1 rad/s) inside four beacons, odometry at 10 Hz, a range every 2nd step,
// the beacons in turn, ranges 7% long.
void beaconScenario(const std::string& name, IniDocument& ini) {
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
}

// nav-*: Nav2D, an accelerometer with a bias and ranges with a bias.
void navScenario(const std::string& name, IniDocument& ini) {
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
}

// paper, consistent: the paper's radar.
void radarScenario(const std::string& name, IniDocument& ini) {
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
}
}  // namespace

IniDocument builtinScenario(const std::string& name, unsigned seed, int steps) {
  IniDocument ini;
  ini.set("scenario", "name", name);
  ini.set("scenario", "seed", std::to_string(seed));
  ini.set("scenario", "steps", std::to_string(steps));
  if (name.rfind("beacons-", 0) == 0) beaconScenario(name, ini);
  else if (name.rfind("nav-", 0) == 0) navScenario(name, ini);
  else radarScenario(name, ini);
  return ini;
}

}  // namespace gssm::io
