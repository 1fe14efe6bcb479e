#include "gssm/analysis/scenario_analysis.h"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <iomanip>
#include <sstream>

#include "gssm/core/error.h"

namespace gssm {

namespace {
const MethodSummary* find(const MonteCarloResult& r, Method m) {
  for (const auto& s : r.methods)
    if (s.method == m) return &s;
  return nullptr;
}
}  // namespace

ScenarioAnalysis analyzeScenario(const MonteCarloScenario& scenario, const SimulatedRun& run,
                                 const MonteCarloOptions& options,
                                 const std::function<NormalSampler(unsigned)>& sampler_for_seed) {
  if (!scenario.truth) throw InvalidArgument("analysis: the scenario has no truth model");
  const Model& model = *scenario.truth;
  ScenarioAnalysis a;
  a.scenario = scenario.name;
  a.state_names = model.stackedStateNames();
  const int stride = std::max<int>(1, static_cast<int>(run.measurements.size() / 40));
  a.bound = posteriorCramerRao(model, run, stride);
  const int nc = model.dims().nc, nb = model.dims().nb;
  const double prior_info =
      nb ? 1.0 / Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(model.priorConstants().covariance).eigenvalues().maxCoeff()
         : 0;
  for (std::size_t i = 0; i < a.bound.filtering.size() && nb > 0; ++i) {
    if (a.bound.filtering[i].size() == 0) continue;
    IdentifiabilityAt at;
    at.t = a.bound.times[i];
    at.id = constantsIdentifiability(model, a.bound.filtering[i].bottomRightCorner(nb, nb));
    at.data_dominates = at.id.eigenvalues.minCoeff() >= prior_info;
    if (at.data_dominates && a.determined_from < 0) a.determined_from = at.t;
    a.identifiability.push_back(std::move(at));
  }
  (void)nc;
  a.montecarlo = runMonteCarlo(scenario, options, sampler_for_seed);
  return a;
}

namespace {
void boundSection(const ScenarioAnalysis& a, std::ostream& os) {
  const auto& mc = a.montecarlo;
  const auto& state_names = a.state_names;
  const std::size_t n = state_names.size();
  os << "## 1. How close each estimator gets to the bound (end of run)\n\n";
  os << "Final-step RMS error over the runs vs the bound's standard deviation; efficiency = bound / RMS "
     << "(1 = attains the bound; the filters are compared with the filtering bound, batch with the smoothing bound). "
     << "The bound is evaluated along the dataset's one true trajectory; where the runs draw their own truth "
     << "(a `consistent` scenario) efficiencies a little above 1 are sampling, not a violation.\n\n";
  os << "| state | filtering bound sd | smoothing bound sd |";
  for (const auto& m : mc.methods) os << " " << methodName(m.method) << " RMS (efficiency) |";
  os << "\n| --- | --- | --- |";
  for (std::size_t i = 0; i < mc.methods.size(); ++i) os << " --- |";
  os << "\n";
  const auto& fb = a.bound.filtering.back();
  const auto& sb = a.bound.smoothing.back();
  for (std::size_t i = 0; i < n; ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    const double f = std::sqrt(fb(ii, ii)), s = std::sqrt(sb(ii, ii));
    os << "| " << state_names[i] << " | " << f << " | " << s << " |";
    for (const auto& m : mc.methods) {
      const double rms = m.rms_final_error[ii];
      os << " " << rms << " (" << std::setprecision(2) << (methodInfo(m.method).streaming ? f : s) / rms
         << std::setprecision(3) << ") |";
    }
    os << "\n";
  }
}

void consistencySection(const MonteCarloResult& mc, std::ostream& os) {
  os << "\n## 2. Consistency (NEES, " << mc.dof << " dof; 95% interval of a " << mc.seeds
     << "-run average: [" << mc.nees_lo << ", " << mc.nees_hi << "])\n\n";
  os << "| method | mean NEES | steps inside the interval | verdict | mean NIS (" << mc.nis_dof
     << " dof, interval [" << mc.nis_lo << ", " << mc.nis_hi << "]) | steps inside | verdict |\n"
     << "| --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& m : mc.methods) {
    os << "| " << methodName(m.method) << " | " << m.mean_nees << " | " << std::lround(100 * m.nees_step_in_interval)
       << "% | " << m.consistency << " | ";
    if (std::isfinite(m.mean_nis))
      os << m.mean_nis << " | " << std::lround(100 * m.nis_step_in_interval) << "% | " << m.nis_consistency << " |\n";
    else
      os << "— (no innovations: uses all data) | — | — |\n";
  }
}

void identifiabilitySection(const ScenarioAnalysis& a, std::ostream& os) {
  const auto& identifiability = a.identifiability;
  os << "\n## 3. Identifiability of the constants (filtering bound, data information only)\n\n";
  if (identifiability.empty()) {
    os << "The model has no constants.\n";
  } else {
    os << "| t | rank | condition | weakest direction | data dominates the prior |\n| --- | --- | --- | --- | --- |\n";
    const std::size_t rows = identifiability.size();
    for (std::size_t i = 0; i < rows; i += std::max<std::size_t>(1, rows / 8)) {
      const auto& at = identifiability[i];
      os << "| " << at.t << " | " << at.id.rank << " | " << at.id.condition << " | " << at.id.weakest << " | "
         << (at.data_dominates ? "yes" : "no") << " |\n";
    }
    const auto& last = identifiability.back();
    os << "\n";
    if (!last.id.determined())
      os << "**Not identifiable**: the data never determine " << last.id.weakest << "; only the prior does.\n";
    else if (a.determined_from >= 0)
      os << "All constants are determined by the data (more than by the prior in every direction) from t = "
         << a.determined_from << ".\n";
    else
      os << "The constants are observable but the prior still dominates in the weakest direction at the end: "
         << last.id.weakest << ".\n";
  }
}

std::string commaList(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

// One GSSM method against the EKF, state by state, and why.
void comparisonLine(const ScenarioAnalysis& a, const MethodSummary& ekf, const MethodSummary& m, std::ostream& os) {
  const bool smoother = !methodInfo(m.method).streaming;  // uses future data
  const std::size_t n = a.state_names.size();
  os << "* **" << methodName(m.method) << "**: ";
  std::vector<std::string> better, same, worse;
  for (std::size_t i = 0; i < n; ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    const double r = m.mean_rmse[ii] / ekf.mean_rmse[ii];
    std::ostringstream item;
    item << std::setprecision(2) << a.state_names[i] << " (RMSE ×" << r << ", better in "
         << std::lround(100 * m.beats_ekf[ii]) << "% of runs)";
    (r < 0.95 ? better : r > 1.05 ? worse : same).push_back(item.str());
  }
  if (!better.empty()) os << "better on " << commaList(better) << ". ";
  if (!same.empty()) os << "same as the EKF (within 5%) on " << commaList(same) << ". ";
  if (!worse.empty()) os << "worse on " << commaList(worse) << ". ";
  if (smoother && !better.empty())
    os << "Why: smoothing — every state uses the later measurements too (not available online).";
  else if (!smoother && !better.empty())
    os << "Why: the window's factors are relinearized at the current estimate (the EKF linearizes each "
          "measurement once, at its prediction), which matters where the model is nonlinear for the "
          "prior's error (e.g. a start-up).";
  else if (!smoother)
    os << "Why: the EKF's linearization is adequate here; both are the same Bayesian filter.";
  os << "\n";
}
}  // namespace

std::string ScenarioAnalysis::markdown() const {
  std::ostringstream os;
  os << std::setprecision(3);
  os << "# Analysis of `" << scenario << "`\n\n";
  os << "Monte Carlo: " << montecarlo.seeds << " runs × " << montecarlo.steps
     << " steps. Bound: posterior Cramér–Rao at the dataset's true states (filtering = data up to t; smoothing = "
        "all data).\n\n";
  boundSection(*this, os);
  consistencySection(montecarlo, os);
  identifiabilitySection(*this, os);
  os << "\n## 4. Does the GSSM improve on the EKF here?\n\n";
  const MethodSummary* ekf = find(montecarlo, Method::Ekf);
  for (const Method g : {Method::FixedLag, Method::Incremental, Method::Batch}) {
    const MethodSummary* m = find(montecarlo, g);
    if (ekf && m) comparisonLine(*this, *ekf, *m, os);
  }
  return os.str();
}

}  // namespace gssm
