#include "gssm/analysis/montecarlo.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <thread>

#include "gssm/analysis/errors.h"
#include "gssm/core/error.h"
#include "gssm/estimator/estimator.h"
#include "gssm/analysis/offline.h"

namespace gssm {

bool MonteCarloOptions::validate(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = "MonteCarloOptions: " + m;
    return false;
  };
  if (seeds < 1) return fail("seeds must be >= 1");
  if (threads < 1) return fail("threads must be >= 1");
  if (methods.empty()) return fail("no methods");
  if (std::find(methods.begin(), methods.end(), Method::Ekf) == methods.end())
    return fail("methods must include ekf (the baseline every method is compared with)");
  return true;
}

void validateMonteCarlo(const MonteCarloScenario& scenario, const MonteCarloOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument(why);
  if (!scenario.truth) throw InvalidArgument("MonteCarlo: the scenario has no truth model");
  const Model& model = *scenario.truth;
  const Model& estimator_model = scenario.estimator ? *scenario.estimator : model;
  for (const Method m : options.methods) {
    EstimatorOptions eo = scenario.options;
    eo.method = m;
    if (!eo.validate(estimator_model, &why)) throw InvalidArgument("MonteCarlo: " + why);
  }
  if (estimator_model.dims().nc != model.dims().nc || estimator_model.dims().nb != model.dims().nb ||
      estimator_model.dims().ny != model.dims().ny || estimator_model.dims().nu != model.dims().nu)
    throw InvalidArgument("MonteCarlo: the estimators' model must have the truth model's dimensions");
}

MonteCarloSeedResult runMonteCarloSeed(const MonteCarloScenario& scenario, const MonteCarloOptions& options,
                                       unsigned seed, const NormalSampler& draw) {
  const Model& model = *scenario.truth;
  const Model& estimator_model = scenario.estimator ? *scenario.estimator : model;
  MonteCarloSeedResult out;
  out.seed = seed;
  const SimulatedRun run = simulate(model, scenario.spec, draw);
  const Truth truth = run.truth();
  for (const auto& m : run.measurements) out.times.push_back(m.t);
  for (const Method method : options.methods) {
    MonteCarloSeedResult::PerMethod r;
    r.method = method;
    try {
      EstimatorOptions eo = scenario.options;
      eo.method = method;
      eo.compute_nis = true;
      const OfflineRun est = runOffline(estimator_model, eo, run.measurements, run.inputs);
      r.nis = est.nis;
      const RunErrors errors = runErrors(est, truth, estimator_model.angleStates());
      for (const auto& e : errors.error) r.sq.push_back(e.cwiseAbs2());
      r.nees = errors.nees;
      r.rmse = errors.rmse();
      r.final_error = errors.error.back();
      r.ok = true;
    } catch (const std::exception& e) {
      r = MonteCarloSeedResult::PerMethod{};
      r.method = method;
      r.error = e.what();
    }
    out.methods.push_back(std::move(r));
  }
  return out;
}

MonteCarloResult runMonteCarlo(const MonteCarloScenario& scenario, const MonteCarloOptions& options,
                               const std::function<NormalSampler(unsigned)>& sampler_for_seed) {
  validateMonteCarlo(scenario, options);
  const auto start = std::chrono::steady_clock::now();
  std::vector<MonteCarloSeedResult> results(static_cast<std::size_t>(options.seeds));
  std::atomic<int> next{0}, done{0};
  auto worker = [&] {
    for (int s = next++; s < options.seeds; s = next++) {
      const unsigned seed = options.first_seed + static_cast<unsigned>(s);
      results[static_cast<std::size_t>(s)] = runMonteCarloSeed(scenario, options, seed, sampler_for_seed(seed));
      if (options.progress) options.progress(++done, options.seeds);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < std::min(options.threads, options.seeds); ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  MonteCarloResult res = summarizeMonteCarlo(scenario, options, results);
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return res;
}

namespace {
// Results in seed order, each with every method of the options.
void requireSeedOrder(const MonteCarloOptions& options, const std::vector<MonteCarloSeedResult>& results) {
  const std::size_t M = options.methods.size(), S = static_cast<std::size_t>(options.seeds);
  if (results.size() != S)
    throw InvalidArgument("summarizeMonteCarlo: " + std::to_string(results.size()) + " seed results for " +
                          std::to_string(S) + " seeds");
  for (std::size_t s = 0; s < S; ++s) {
    const unsigned want = options.first_seed + static_cast<unsigned>(s);
    if (results[s].seed != want || results[s].methods.size() != M)
      throw InvalidArgument("summarizeMonteCarlo: result " + std::to_string(s) + " is seed " +
                            std::to_string(results[s].seed) + " with " + std::to_string(results[s].methods.size()) +
                            " methods; expected seed " + std::to_string(want) + " with " + std::to_string(M) +
                            " (results in seed order, every method of the options)");
    for (std::size_t mi = 0; mi < M; ++mi)
      if (results[s].methods[mi].method != options.methods[mi])
        throw InvalidArgument("summarizeMonteCarlo: seed " + std::to_string(want) + ": method " + std::to_string(mi) +
                              " is " + methodName(results[s].methods[mi].method) + ", the options say " +
                              methodName(options.methods[mi]));
  }
}

const char* verdict(double mean, double lo, double hi) {
  return mean > hi ? "over-confident" : mean < lo ? "under-confident" : "consistent";
}

// One method's sums over the seeds that ran it, per step and in all.
struct MethodSums {
  std::vector<Eigen::VectorXd> sq_t;
  std::vector<double> nees_t, nis_t;
  int ok = 0;
};

MethodSums sumSeeds(MethodSummary& m, std::size_t mi, std::size_t ekf, int n, std::size_t rows,
                    const std::vector<MonteCarloSeedResult>& results) {
  MethodSums sums{std::vector<Eigen::VectorXd>(rows, Eigen::VectorXd::Zero(n)), std::vector<double>(rows, 0.0),
                  std::vector<double>(rows, 0.0), 0};
  for (const auto& seed : results) {
    const auto& r = seed.methods[mi];
    if (!r.ok) {
      if (m.failures++ == 0) m.first_failure = "seed " + std::to_string(seed.seed) + ": " + r.error;
      continue;
    }
    ++sums.ok;
    m.mean_rmse += r.rmse;
    m.rms_final_error += r.final_error.cwiseAbs2();
    const auto& base = seed.methods[ekf];
    if (base.ok)
      for (int i = 0; i < n; ++i) m.beats_ekf[i] += r.rmse[i] < base.rmse[i] ? 1.0 : 0.0;
    for (std::size_t k = 0; k < r.sq.size() && k < sums.sq_t.size(); ++k) {
      sums.sq_t[k] += r.sq[k];
      sums.nees_t[k] += r.nees[k];
      sums.nis_t[k] += k < r.nis.size() ? r.nis[k] : std::numeric_limits<double>::quiet_NaN();
    }
  }
  return sums;
}

// Averages, the RMSE over time, NEES and NIS against their intervals.
void averageSeeds(MethodSummary& m, const MethodSums& sums, const MonteCarloResult& res) {
  const int ok = sums.ok;
  m.mean_rmse /= ok;
  m.rms_final_error = (m.rms_final_error / ok).cwiseSqrt();
  m.beats_ekf /= ok;
  int inside = 0;
  for (std::size_t k = 0; k < sums.sq_t.size(); ++k) {
    m.rmse_over_time.push_back((sums.sq_t[k] / ok).cwiseSqrt());
    const double avg = sums.nees_t[k] / ok;
    m.mean_nees += avg / static_cast<double>(sums.sq_t.size());
    inside += (avg >= res.nees_lo && avg <= res.nees_hi) ? 1 : 0;
  }
  m.nees_step_in_interval = static_cast<double>(inside) / static_cast<double>(sums.sq_t.size());
  m.consistency = verdict(m.mean_nees, res.nees_lo, res.nees_hi);
  m.mean_nis = 0;
  int nis_inside = 0;
  for (double v : sums.nis_t) {
    m.mean_nis += v / ok / static_cast<double>(sums.nis_t.size());
    nis_inside += (v / ok >= res.nis_lo && v / ok <= res.nis_hi) ? 1 : 0;
  }
  m.nis_step_in_interval = static_cast<double>(nis_inside) / static_cast<double>(sums.nis_t.size());
  if (std::isfinite(m.mean_nis)) m.nis_consistency = verdict(m.mean_nis, res.nis_lo, res.nis_hi);
}
}  // namespace

MonteCarloResult summarizeMonteCarlo(const MonteCarloScenario& scenario, const MonteCarloOptions& options,
                                     const std::vector<MonteCarloSeedResult>& results) {
  validateMonteCarlo(scenario, options);
  requireSeedOrder(options, results);
  const Model* model = scenario.truth;
  const SimulationSpec& spec = scenario.spec;
  const int n = model->dims().nc + model->dims().nb;
  MonteCarloResult res;
  res.scenario = scenario.name;
  res.seeds = options.seeds;
  res.steps = spec.steps;
  res.dof = n;
  res.state_names = model->stackedStateNames();
  res.nees_lo = chiSquareQuantile(0.025, n * options.seeds) / options.seeds;
  res.nees_hi = chiSquareQuantile(0.975, n * options.seeds) / options.seeds;
  res.nis_dof = model->dims().ny;
  res.nis_lo = chiSquareQuantile(0.025, res.nis_dof * options.seeds) / options.seeds;
  res.nis_hi = chiSquareQuantile(0.975, res.nis_dof * options.seeds) / options.seeds;
  const std::size_t ekf = static_cast<std::size_t>(
      std::find(options.methods.begin(), options.methods.end(), Method::Ekf) - options.methods.begin());
  const std::size_t rows = static_cast<std::size_t>(spec.steps / spec.measure_every);
  for (std::size_t mi = 0; mi < options.methods.size(); ++mi) {
    MethodSummary m;
    m.method = options.methods[mi];
    m.times = results.front().times;
    m.mean_rmse = m.rms_final_error = m.beats_ekf = Eigen::VectorXd::Zero(n);
    const MethodSums sums = sumSeeds(m, mi, ekf, n, rows, results);
    if (sums.ok > 0) averageSeeds(m, sums, res);
    res.methods.push_back(std::move(m));
  }
  return res;
}

std::string MonteCarloResult::markdown() const {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  auto perState = [&](const Eigen::VectorXd& v, int prec) {
    std::ostringstream o;
    o.setf(std::ios::fixed);
    o.precision(prec);
    for (Eigen::Index i = 0; i < v.size(); ++i) o << (i ? " / " : "") << v[i];
    return o.str();
  };
  std::string names;
  for (const auto& s : state_names) names += (names.empty() ? "" : " / ") + s;
  os.precision(2);
  os << "Scenario `" << scenario << "`, " << seeds << " seeds × " << steps << " steps; NEES has " << dof
     << " dof, 95% interval of a " << seeds << "-seed average at one step: [" << nees_lo << ", " << nees_hi
     << "].\n\n";
  os << "| method | mean RMSE (" << names << ") | RMS final error (" << names << ") | mean NEES | verdict | steps with NEES in 95% interval | mean NIS (" << nis_dof << " dof) | seeds beating the EKF (" << names << ") | failures |\n";
  os << "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& m : methods) {
    os << "| " << methodName(m.method) << (methodInfo(m.method).streaming ? "" : " (smoother, uses future data)") << " | "
       << perState(m.mean_rmse, 3) << " | " << perState(m.rms_final_error, 3) << " | ";
    os.precision(2);
    os << m.mean_nees << " | " << m.consistency << " | " << std::lround(100 * m.nees_step_in_interval) << "% | ";
    if (std::isfinite(m.mean_nis))
      os << m.mean_nis << " (" << m.nis_consistency << ", " << std::lround(100 * m.nis_step_in_interval)
         << "% of steps inside) | ";
    else os << "— | ";
    if (m.method == Method::Ekf) os << "— | ";
    else {
      Eigen::VectorXd pct = 100 * m.beats_ekf;
      os << perState(pct, 0) << " % | ";
    }
    os << m.failures << " |\n";
  }
  return os.str();
}

}  // namespace gssm
