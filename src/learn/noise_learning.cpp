#include "gssm/learn/noise_learning.h"

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <algorithm>
#include <map>
#include <numeric>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/core/parallel.h"
#include "gssm/factors/problem.h"
#include "gssm/model/registry.h"
#include "learn/constants_prior.h"
#include "learn/nelder_mead.h"
#include "learn/scoring.h"

namespace gssm {

std::string LearntParameter::name() const {
  std::string n = section == "model" ? key : section + " " + key;
  return index < 0 ? n : n + "[" + std::to_string(index) + "]";
}

bool NoiseLearningOptions::validate(std::string* why) const {
  auto fail = [&](const std::string& msg) {
    if (why) *why = "NoiseLearningOptions: " + msg;
    return false;
  };
  if (!(start >= 0) || !std::isfinite(start)) return fail("start must be 0 (the model's values) or a σ > 0");
  if (max_evaluations < 10) return fail("max_evaluations must be at least 10");
  if (!(tolerance > 0) || tolerance >= 1) return fail("tolerance must be in (0, 1)");
  if (max_restarts < 0) return fail("max_restarts must be >= 0");
  if (optimizer != "scoring" && optimizer != "nelder-mead")
    return fail("optimizer '" + optimizer + "': expected scoring or nelder-mead");
  if (threads < 1 || threads > 256) return fail("threads must be in 1..256");
  if (!(search_range > 1) || !std::isfinite(search_range)) return fail("search_range must be a factor > 1");
  if (prior_iterations < 1) return fail("prior_iterations must be >= 1");
  if (!(prior_tolerance > 0) || prior_tolerance >= 1) return fail("prior_tolerance must be in (0, 1)");
  if (!(likelihood_spacing >= 0) || !std::isfinite(likelihood_spacing))
    return fail("likelihood_spacing must be >= 0 (s; 0: every measurement)");
  if (std::string b; !batch.validate(&b)) return fail(b);
  return true;  // the EKF options are checked against the model when the filter is made
}

namespace {
// likelihood_spacing: the counted channels' measurements at least `spacing`
// apart per channel (the first kept), the others as they are.
std::vector<Measurement> spacedOut(const std::vector<Measurement>& measurements, const NoiseLearningOptions& o) {
  const std::vector<int>& counted = o.ekf.likelihood_channels;
  std::map<int, double> last;  // per counted channel, the last kept time
  std::vector<Measurement> out;
  for (const Measurement& m : measurements) {
    const bool spaced = counted.empty() || std::find(counted.begin(), counted.end(), m.channel) != counted.end();
    if (spaced) {
      const auto it = last.find(m.channel);
      if (it != last.end() && m.t - it->second < o.likelihood_spacing) continue;
      last[m.channel] = m.t;
    }
    out.push_back(m);
  }
  return out;
}

// The likelihood over a schedule computed once (learning evaluates hundreds).
internal::LikelihoodTerms logLikelihoodAlong(const Model& model, const std::vector<ScheduledStep>& schedule,
                                             const std::vector<Measurement>& measurements,
                                             const std::vector<Input>& inputs, double t0,
                                             ExtendedKalmanFilterOptions ekf) {
  ekf.use_gates = false;
  ExtendedKalmanFilter filter(model, ekf, t0);
  filterAlong(filter, schedule, measurements, inputs);
  internal::LikelihoodTerms out;
  out.total = filter.logLikelihood();
  const std::vector<double>& terms = filter.logLikelihoodTerms();
  out.terms = Eigen::Map<const Eigen::VectorXd>(terms.data(), static_cast<Eigen::Index>(terms.size()));
  return out;
}
}  // namespace

double predictionErrorLogLikelihood(const Model& model, const std::vector<Measurement>& measurements,
                                    const std::vector<Input>& inputs, double t0, ExtendedKalmanFilterOptions ekf) {
  return logLikelihoodAlong(model, stepSchedule(measurements, inputs, t0), measurements, inputs, t0, std::move(ekf))
      .total;
}

namespace {


// The spec declaring [section] key: the section itself or its sub-section prefix ("channel.gps" → "channel").
const ParamSpec* specOf(const ModelType& type, const std::string& section, const std::string& key) {
  if (const ParamSpec* p = type.param(section, key)) return p;
  const auto dot = section.find('.');
  return dot == std::string::npos ? nullptr : type.param(section.substr(0, dot), key);
}

bool selected(const LearntParameter& p, const std::vector<std::string>& names) {
  if (names.empty()) return true;
  LearntParameter whole = p;
  whole.index = -1;
  // A key of a top-level section also by itself ("bias_sd" for "prior bias_sd").
  const bool top = p.section.find('.') == std::string::npos;
  for (const auto& n : names)
    if (n == p.name() || n == whole.name() || (top && (n == p.key || (p.index >= 0 && n == p.key + "[" + std::to_string(p.index) + "]"))))
      return true;
  return false;
}

// Every learnable σ the values hold, with its given value (zero variances are not learnt).
std::vector<LearntParameter> learnableParameters(const ModelType& type, const ParamValues& values) {
  std::vector<LearntParameter> out;
  auto add = [&out](const std::string& section, const std::string& key, int index, double given) {
    LearntParameter p;
    p.section = section, p.key = key, p.index = index, p.given = given;
    out.push_back(p);
  };
  for (const auto& [section, key] : values.keys()) {
    const ParamSpec* spec = specOf(type, section, key);
    if (!spec || !spec->learnable) continue;
    if (spec->kind == ParamKind::Real) {
      add(section, key, -1, values.real(section, key));
      if (spec->constants_prior) out.back().method = "em";
      continue;
    }
    if (spec->kind == ParamKind::Vector) {  // σs: one value is learnt as the key itself
      const Eigen::VectorXd v = values.vector(section, key);
      for (Eigen::Index i = 0; i < v.size(); ++i)
        if (v[i] > 0) {
          add(section, key, v.size() == 1 ? -1 : static_cast<int>(i), v[i]);
          out.back().of_vector = true;
        }
      continue;
    }
    const Eigen::MatrixXd M = values.matrix(section, key);
    for (Eigen::Index i = 0; i < std::min(M.rows(), M.cols()); ++i)
      if (M(i, i) > 0) add(section, key, static_cast<int>(i), std::sqrt(M(i, i)));
  }
  return out;
}

std::vector<LearntParameter> chosenParameters(const ModelType& type, const ParamValues& values,
                                              const NoiseLearningOptions& o) {
  const std::vector<LearntParameter> all = learnableParameters(type, values);
  std::vector<LearntParameter> out;
  for (const auto& p : all)
    if (selected(p, o.parameters)) out.push_back(p);
  for (const auto& n : o.parameters) {
    bool known = false;
    for (const auto& p : out) known = known || selected(p, {n});
    if (known) continue;
    std::string list;
    for (const auto& p : all) list += (list.empty() ? "" : ", ") + p.name();
    throw InvalidArgument("NoiseLearningOptions: '" + n + "' is not a learnable parameter of model '" + type.name +
                          "' (learnable: " + (list.empty() ? "none" : list) + ")");
  }
  if (out.empty()) throw InvalidArgument("model '" + type.name + "' declares no learnable noise parameter");
  for (auto& p : out) p.start = o.start > 0 ? o.start : p.given;
  return out;
}

struct Objective {
  const NoiseFamily& family;
  const std::vector<ScheduledStep>& schedule;  // the states of the run, the same for every σ
  const std::vector<Measurement>& measurements;
  const std::vector<Input>& inputs;
  double t0;
  const ExtendedKalmanFilterOptions& ekf;
  Eigen::VectorXd lo, hi;  // the search range of each log σ (and of logit ε)
  /// With the outlier mixture, θ's last entry is logit ε and these are the
  /// channels' uniform log densities.
  bool mixture = false;
  std::vector<double> outlier_log_density;
  int threads = 1;
  int evaluations = 0;  ///< filter passes run (a θ met again is not run again)
  /// The passes run so far, with their terms: learning meets the same θ
  /// again (the given values, the start and the optimizer's first point
  /// are one θ unless [learn] start moves it), and a pass is a whole
  /// filter run. Exact θ only: the same θ gives the same bits.
  std::vector<std::pair<Eigen::VectorXd, internal::LikelihoodTerms>> seen;

  // The pass at θ = log σ, with its terms (scoring's): total −∞ (no terms)
  // outside the domain or where the filter fails.
  internal::LikelihoodTerms pass(const Eigen::VectorXd& theta) const {
    internal::LikelihoodTerms failed{-std::numeric_limits<double>::infinity(), {}};
    if (!theta.allFinite()) return failed;
    try {  // beyond the search range: the value at its end (flat)
      const Eigen::VectorXd clamped = theta.cwiseMax(lo).cwiseMin(hi);
      const auto n = static_cast<Eigen::Index>(family.names.size());
      const auto model = family.make(clamped.head(n).array().exp().matrix());
      ExtendedKalmanFilterOptions e = ekf;
      e.keep_log_likelihood_terms = true;
      if (mixture) e.outlier_probability = 1.0 / (1.0 + std::exp(-clamped[n])), e.outlier_log_density = outlier_log_density;
      internal::LikelihoodTerms l = logLikelihoodAlong(*model, schedule, measurements, inputs, t0, e);
      return std::isfinite(l.total) ? l : failed;
    } catch (const NumericalError&) {
      return failed;
    }
  }
  double logLikelihood(const Eigen::VectorXd& theta) { return passes({theta}).front().total; }
  // The passes at several θ, `threads` at a time; a θ seen before, and one
  // met twice here, is run once. Only the first few passes are kept (the
  // repeats are at the start; Nelder–Mead's thousands of points are not).
  std::vector<internal::LikelihoodTerms> passes(const std::vector<Eigen::VectorXd>& thetas) {
    std::vector<internal::LikelihoodTerms> out(thetas.size());
    std::vector<std::size_t> run;  // the first of each θ not seen before
    constexpr std::size_t kSeen = static_cast<std::size_t>(-1);
    std::vector<std::size_t> first(thetas.size(), kSeen);  // each θ not seen: the θ in `run` that is it
    for (std::size_t k = 0; k < thetas.size(); ++k) {
      if (const internal::LikelihoodTerms* s = findSeen(thetas[k])) {
        out[k] = *s;
        continue;
      }
      const auto earlier = std::find_if(run.begin(), run.end(), [&](std::size_t j) { return thetas[j] == thetas[k]; });
      first[k] = earlier == run.end() ? k : *earlier;
      if (first[k] == k) run.push_back(k);
    }
    const auto errors = runJobs(run.size(), static_cast<std::size_t>(threads),
                                [&](std::size_t i) { out[run[i]] = pass(thetas[run[i]]); });
    for (const auto& e : errors)
      if (e) std::rethrow_exception(e);
    evaluations += static_cast<int>(run.size());
    for (std::size_t k = 0; k < thetas.size(); ++k)
      if (first[k] != kSeen && first[k] != k) out[k] = out[first[k]];  // a repeat within this batch
    for (std::size_t i : run)
      if (seen.size() < kSeenKept) seen.emplace_back(thetas[i], out[i]);
    return out;
  }
  static constexpr std::size_t kSeenKept = 32;
  const internal::LikelihoodTerms* findSeen(const Eigen::VectorXd& theta) const {
    for (const auto& s : seen)
      if (s.first.size() == theta.size() && s.first == theta) return &s.second;
    return nullptr;
  }
};

// Nelder–Mead from θ0, restarted from its best point with a fresh simplex
// until a restart gains less than the tolerance (a collapsed simplex is not
// proof of a maximum). A σ that reaches the end of its search range is held
// there for the restarts that follow (the simplex then spans the others).
Eigen::VectorXd maximizeByNelderMead(Objective& obj, const Eigen::VectorXd& theta0, const NoiseLearningOptions& o,
                                     NoiseLearningReport& r) {
  Eigen::VectorXd theta = theta0;
  std::vector<Eigen::Index> free(static_cast<std::size_t>(theta.size()));
  std::iota(free.begin(), free.end(), Eigen::Index{0});
  auto full = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd t = theta;
    for (std::size_t i = 0; i < free.size(); ++i) t[free[i]] = x[static_cast<Eigen::Index>(i)];
    return t;
  };
  auto minus = [&](const Eigen::VectorXd& x) { return -obj.logLikelihood(full(x)); };
  auto trace = [&r](double best) { r.log_likelihood.push_back(-best); };
  double best = -std::numeric_limits<double>::infinity();
  double step = 1.0;  // a factor e on every σ: from a generic start the optimum can be decades away
  for (r.restarts = 0; !free.empty(); ++r.restarts) {
    Eigen::VectorXd x(static_cast<Eigen::Index>(free.size()));
    for (std::size_t i = 0; i < free.size(); ++i) x[static_cast<Eigen::Index>(i)] = theta[free[i]];
    const int budget = o.max_evaluations - obj.evaluations;
    const auto nm = internal::nelderMead(minus, x, step, budget, o.tolerance, std::sqrt(o.tolerance), trace);  // ℓ is quadratic in log σ near the top
    r.iterations += nm.iterations;
    const double gain = -nm.value - best;
    if (-nm.value > best) theta = full(nm.x), best = -nm.value;
    r.converged = nm.converged && gain <= o.tolerance * (1.0 + std::abs(best));
    if (r.converged || !nm.converged || r.restarts >= o.max_restarts) break;
    free.erase(std::remove_if(free.begin(), free.end(),
                              [&](Eigen::Index k) { return theta[k] <= obj.lo[k] + 0.1 || theta[k] >= obj.hi[k] - 0.1; }),
               free.end());
    step = 0.25;
  }
  r.final_log_likelihood = best;
  return theta.cwiseMax(obj.lo).cwiseMin(obj.hi);
}

internal::ScoringOptions scoringOptions(const Objective& obj, const NoiseLearningOptions& o) {
  internal::ScoringOptions so;
  so.lo = obj.lo, so.hi = obj.hi;
  so.max_evaluations = o.max_evaluations - obj.evaluations;
  so.tolerance = o.tolerance;
  so.parallel_passes = o.threads;
  return so;
}

// Scoring from θ0 within the search range (learn/scoring.h).
Eigen::VectorXd maximizeByScoring(Objective& obj, const Eigen::VectorXd& theta0, const NoiseLearningOptions& o,
                                  NoiseLearningReport& r) {
  const internal::ScoringOptions so = scoringOptions(obj, o);
  const auto at = [&obj](const std::vector<Eigen::VectorXd>& thetas) { return obj.passes(thetas); };
  const auto res = internal::maximizeByScoring(at, theta0, so, [&r](double l) { r.log_likelihood.push_back(l); });
  r.iterations += res.iterations;
  r.converged = res.converged;
  r.final_log_likelihood = res.value;
  return res.x;
}

Eigen::VectorXd maximize(Objective& obj, const Eigen::VectorXd& theta0, const NoiseLearningOptions& o,
                         NoiseLearningReport& r) {
  return o.optimizer == "scoring" ? maximizeByScoring(obj, theta0, o, r) : maximizeByNelderMead(obj, theta0, o, r);
}

// −∂²ℓ/∂θ² over the free parameters (those inside their search range) by
// central differences of the log-likelihood at the maximum.
Eigen::MatrixXd observedInformation(Objective& obj, const Eigen::VectorXd& theta, double l0,
                                    const std::vector<Eigen::Index>& free) {
  const auto n = static_cast<Eigen::Index>(free.size());
  const double h = 1e-2;  // in log σ: 1%
  std::vector<Eigen::VectorXd> points;  // (i, ±), then (i, j) for j < i at (±, ±): one batch of passes
  auto add = [&](Eigen::Index i, double si, Eigen::Index j, double sj) {
    Eigen::VectorXd t = theta;
    t[free[static_cast<std::size_t>(i)]] += si * h;
    t[free[static_cast<std::size_t>(j)]] += sj * h;
    points.push_back(t);
  };
  for (Eigen::Index i = 0; i < n; ++i) {
    add(i, 1, i, 0), add(i, -1, i, 0);
    for (Eigen::Index j = 0; j < i; ++j) add(i, 1, j, 1), add(i, 1, j, -1), add(i, -1, j, 1), add(i, -1, j, -1);
  }
  const std::vector<internal::LikelihoodTerms> l = obj.passes(points);
  Eigen::MatrixXd I(n, n);
  std::size_t k = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    I(i, i) = -(l[k].total - 2 * l0 + l[k + 1].total) / (h * h);
    k += 2;
    for (Eigen::Index j = 0; j < i; ++j, k += 4)
      I(i, j) = I(j, i) = -(l[k].total - l[k + 1].total - l[k + 2].total + l[k + 3].total) / (4 * h * h);
  }
  return I;
}

// The pseudo-inverse of the information; a parameter on a flat or upward
// direction of the likelihood is flagged.
Eigen::MatrixXd covarianceOf(const Eigen::MatrixXd& info, std::vector<LearntParameter*>& ps) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (info + info.transpose()));
  const Eigen::VectorXd& lambda = es.eigenvalues();
  const double floor = 1e-9 * std::max(1.0, lambda.cwiseAbs().maxCoeff());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(info.rows(), info.cols());
  for (Eigen::Index k = 0; k < lambda.size(); ++k) {
    const Eigen::VectorXd v = es.eigenvectors().col(k);
    if (lambda[k] > floor) {
      cov += v * v.transpose() / lambda[k];
      continue;
    }
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (std::abs(v[i]) > 0.3) ps[static_cast<std::size_t>(i)]->identifiable = false,
                                ps[static_cast<std::size_t>(i)]->note = "the likelihood is flat along it";
  }
  return cov;
}

// Standard errors of the free parameters (delta method: se(σ) = σ·se(log σ))
// and the flags of what the log does not determine.
void standardErrors(const Eigen::MatrixXd& info, std::vector<LearntParameter*> ps) {
  const Eigen::MatrixXd cov = covarianceOf(info, ps);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    LearntParameter& p = *ps[i];
    const auto a = static_cast<Eigen::Index>(i);
    if (!p.identifiable) continue;
    p.standard_error = p.value * std::sqrt(cov(a, a));
    if (std::sqrt(cov(a, a)) > 1.0) p.identifiable = false, p.note = "relative standard error above 100%";
    for (std::size_t j = 0; j < ps.size() && p.identifiable; ++j) {
      const auto b = static_cast<Eigen::Index>(j);
      const double rho = j == i || !(cov(b, b) > 0) ? 0 : cov(a, b) / std::sqrt(cov(a, a) * cov(b, b));
      if (std::abs(rho) <= 0.95) continue;
      std::ostringstream os;
      os << "trades off with " << ps[j]->name() << " (correlation " << rho << "): only their joint effect is determined";
      p.identifiable = false, p.note = os.str();
    }
  }
}
}  // namespace

namespace {
// Each channel's uniform outlier density: 1 / the volume its measurements span.
std::vector<double> outlierLogDensities(const Model& model, const std::vector<Measurement>& ms) {
  const auto channels = static_cast<std::size_t>(model.numChannels());
  std::vector<Eigen::VectorXd> lo(channels), hi(channels);
  for (const auto& m : ms) {
    auto c = static_cast<std::size_t>(m.channel);
    lo[c] = lo[c].size() ? lo[c].cwiseMin(m.y).eval() : m.y;
    hi[c] = hi[c].size() ? hi[c].cwiseMax(m.y).eval() : m.y;
  }
  std::vector<double> out(channels, 0.0);
  for (std::size_t c = 0; c < channels; ++c)
    if (lo[c].size()) out[c] = -(hi[c] - lo[c]).array().max(1e-9).log().sum();
  return out;
}

// The learnt values, the flags of σs at the end of their range, the
// standard errors of the others.
void finish(Objective& obj, const Eigen::VectorXd& theta, const NoiseLearningOptions& o, NoiseLearningReport& r) {
  std::vector<Eigen::Index> free;
  std::vector<LearntParameter*> free_params;
  for (std::size_t i = 0; i < r.parameters.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    LearntParameter& p = r.parameters[i];
    p.value = std::exp(theta[k]);
    if (theta[k] < obj.lo[k] + 0.1 || theta[k] > obj.hi[k] - 0.1)
      p.identifiable = false, p.note = theta[k] < obj.lo[k] + 0.1
                                           ? "at the low end of its search range: the log does not resolve it from 0"
                                           : "at the high end of its search range";
    else
      free.push_back(k), free_params.push_back(&p);
  }
  if (o.standard_errors && !free.empty())
    standardErrors(observedInformation(obj, theta, r.final_log_likelihood, free), free_params);
}
}  // namespace

namespace internal {
ParamValues withSigmas(const ParamValues& base, const std::vector<LearntParameter>& ps, const Eigen::VectorXd& sigmas) {
  ParamValues v = base;
  std::map<std::pair<std::string, std::string>, Eigen::VectorXd> scales;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const LearntParameter& p = ps[i];
    const double sigma = sigmas[static_cast<Eigen::Index>(i)];
    if (p.of_vector) {
      Eigen::VectorXd entries = v.vector(p.section, p.key);
      entries[std::max(p.index, 0)] = sigma;
      v.vector(p.section, p.key, entries);
      continue;
    }
    if (p.index < 0) {
      v.real(p.section, p.key, sigma);
      continue;
    }
    auto& d = scales[{p.section, p.key}];
    if (d.size() == 0) d = Eigen::VectorXd::Ones(base.matrix(p.section, p.key).rows());
    d[p.index] = sigma / p.given;
  }
  for (const auto& [where, d] : scales)
    v.matrix(where.first, where.second, d.asDiagonal() * base.matrix(where.first, where.second) * d.asDiagonal());
  return v;
}
}  // namespace internal

NoiseLearningReport learnNoise(const NoiseFamily& family, const std::vector<Measurement>& all,
                               const std::vector<Input>& inputs, double t0, const NoiseLearningOptions& o) {
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument(why);
  if (family.names.empty() || static_cast<Eigen::Index>(family.names.size()) != family.given.size() || !family.make)
    throw InvalidArgument("learnNoise: a NoiseFamily needs one name and one given σ per parameter, and make");
  const auto started = std::chrono::steady_clock::now();
  std::vector<Measurement> spaced;  // likelihood_spacing's; without it the log itself (no copy)
  const std::vector<Measurement>& measurements = o.likelihood_spacing > 0 ? (spaced = spacedOut(all, o)) : all;
  NoiseLearningReport r;
  r.parameters = family.parameters;
  for (std::size_t i = r.parameters.size(); i < family.names.size(); ++i) {  // undescribed: [model] <name>
    LearntParameter p;
    p.section = "model", p.key = family.names[i], p.given = family.given[static_cast<Eigen::Index>(i)];
    p.start = o.start > 0 ? o.start : p.given;
    r.parameters.push_back(p);
  }
  r.measurements = measurements.size();
  r.optimizer = o.optimizer;
  const std::vector<ScheduledStep> schedule = stepSchedule(measurements, inputs, t0);
  Objective obj{family, schedule, measurements, inputs, t0, o.ekf, {}, {}, false, {}, o.threads, 0, {}};
  const auto n = static_cast<Eigen::Index>(family.names.size());
  Eigen::VectorXd theta(n), given(n);  // by one log, so that a start at the given values is the same θ
  for (Eigen::Index i = 0; i < n; ++i) theta[i] = std::log(r.parameters[static_cast<std::size_t>(i)].start);
  for (Eigen::Index i = 0; i < n; ++i) given[i] = std::log(family.given[i]);
  obj.lo = theta.array() - std::log(o.search_range);
  obj.hi = theta.array() + std::log(o.search_range);
  // The optimizer's first round (scoring's: the start and its slope;
  // Nelder–Mead's: the start) beside the given values' pass, in one round
  // on the threads; the passes below and the optimizer's first are then kept.
  std::vector<Eigen::VectorXd> first =
      o.optimizer == "scoring" ? internal::firstScoringPoints(theta, scoringOptions(obj, o))
                               : std::vector<Eigen::VectorXd>{theta};
  first.push_back(given);
  obj.passes(first);
  r.given_log_likelihood = obj.logLikelihood(given);
  r.start_log_likelihood = obj.logLikelihood(theta);
  if (!std::isfinite(r.start_log_likelihood))
    throw NumericalError("learnNoise: the EKF fails at the starting noise (" + family.names[0] +
                         " = " + std::to_string(r.parameters[0].start) +
                         ", ...): start from other values ([learn] start) or check the data");
  theta = maximize(obj, theta, o, r);  // Gaussian first: from a generic start the mixture's ε would absorb everything
  r.gaussian_log_likelihood = r.final_log_likelihood;
  if (o.outliers) {
    r.mixture_from = r.log_likelihood.size();
    obj.mixture = true;
    obj.seen.clear();  // another objective from here
    obj.outlier_log_density = outlierLogDensities(*family.make(family.given), measurements);
    Eigen::VectorXd with_eps(n + 1), lo(n + 1), hi(n + 1);
    with_eps << theta, std::log(0.01 / 0.99);
    lo << obj.lo, std::log(1e-6), hi << obj.hi, 0.0;  // ε in [1e-6, 0.5]
    obj.lo = lo, obj.hi = hi;
    with_eps = maximize(obj, with_eps, o, r);
    r.outlier_probability = 1.0 / (1.0 + std::exp(-with_eps[n]));
    theta = with_eps;
  }
  finish(obj, theta, o, r);
  r.model = family.make(internal::sigmasOf(theta.head(n)));
  r.evaluations = obj.evaluations;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return r;
}

NoiseLearningReport learnNoise(const Model& model, const std::vector<Measurement>& measurements,
                               const std::vector<Input>& inputs, double t0, const NoiseLearningOptions& o) {
  const ModelType* type = modelTypeOf(model);
  if (!type)
    throw InvalidArgument("learnNoise: model '" + model.name() +
                          "' has no registered type, so no declared learnable parameters (pass a NoiseFamily)");
  const ParamValues base = ParamValues::of(model);
  NoiseFamily family;
  std::vector<LearntParameter> prior;  // σs of the constants' prior: by EM after the noise
  for (auto& p : chosenParameters(*type, base, o)) (p.method == "em" ? prior : family.parameters).push_back(p);
  const std::string type_name = type->name;
  NoiseLearningReport r;
  if (family.parameters.empty()) {
    r.values = base;
    r.measurements = measurements.size();
    r.converged = true;
  } else {
    family.given.resize(static_cast<Eigen::Index>(family.parameters.size()));
    for (std::size_t i = 0; i < family.parameters.size(); ++i) {
      family.names.push_back(family.parameters[i].name());
      family.given[static_cast<Eigen::Index>(i)] = family.parameters[i].given;
    }
    family.make = [&base, &family, type_name](const Eigen::VectorXd& sigmas) -> std::shared_ptr<const Model> {
      return internal::withSigmas(base, family.parameters, sigmas).build(type_name);
    };
    r = learnNoise(family, measurements, inputs, t0, o);
    Eigen::VectorXd sigmas(static_cast<Eigen::Index>(r.parameters.size()));
    for (std::size_t i = 0; i < r.parameters.size(); ++i) sigmas[static_cast<Eigen::Index>(i)] = r.parameters[i].value;
    r.values = internal::withSigmas(base, r.parameters, sigmas);
  }
  if (!prior.empty()) internal::learnConstantsPrior(type_name, prior, measurements, inputs, t0, o, r);
  return r;
}

std::string NoiseLearningReport::toString() const {
  std::ostringstream os;
  if (evaluations > 0)
    os << "noise learnt by prediction-error maximum likelihood from " << measurements << " measurements: log-likelihood "
       << start_log_likelihood << " -> " << final_log_likelihood << " (at the given values " << given_log_likelihood
       << "), " << optimizer << ", " << evaluations << " EKF passes, " << restarts << " restarts, "
       << (converged ? "converged" : "NOT converged") << ", " << seconds << " s\n";
  if (prior_iterations > 0)
    os << "constants' prior learnt by EM on the factor graph: " << prior_iterations << " E-steps (batch solves), "
       << (prior_converged ? "converged" : "NOT converged") << ", expected log prior "
       << prior_expected_log_prior.front() << " -> " << prior_expected_log_prior.back() << "\n";
  if (mixture_from > 0)
    os << "  outliers: a fraction " << outlier_probability << " of the measurements (Gaussian-only log-likelihood "
       << gaussian_log_likelihood << ")\n";
  for (const auto& p : parameters) {
    os << "  " << p.name() << ": " << p.start << " -> " << p.value;
    if (std::isfinite(p.standard_error)) os << " ± " << p.standard_error;
    os << " (given " << p.given << ")";
    if (p.method == "em") os << " [EM]";
    if (!p.identifiable) os << "  [not identifiable: " << p.note << "]";
    os << "\n";
  }
  return os.str();
}

}  // namespace gssm
