#include "gssm/analysis/bounds.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "gssm/solvers/batch_solver.h"
#include "gssm/core/error.h"
#include "gssm/core/time.h"
#include "gssm/factors/problem.h"

namespace gssm {

namespace {
// The true values of every variable of a problem over the run's first
// measurements: states at the problem's step times, constants.
Values truthAt(const Problem& p, const SimulatedRun& run, const Model& model) {
  Values v;
  TimeMatcher match(run.times);
  for (std::size_t k = 0; k < p.times.size(); ++k) {
    const auto j = match.find(p.times[k]);
    if (!j) throw InvalidArgument("posteriorCramerRao: no true state at t = " + std::to_string(p.times[k]));
    v.insert(Key::state(static_cast<std::int64_t>(k)), run.states[*j]);
  }
  if (model.dims().nb > 0) v.insert(Key::constants(), run.constants);
  return v;
}

// Step index of the state at time t.
std::int64_t stepAt(const Problem& p, double t) {
  const auto k = TimeMatcher(p.times).find(t);
  if (!k) throw InvalidArgument("posteriorCramerRao: no step at t = " + std::to_string(t));
  return static_cast<std::int64_t>(*k);
}

Eigen::MatrixXd boundAt(BatchSolver& solver, const Model& model, std::int64_t k) {
  return solver.jointMarginalCovariance(stackedKeys(model, k));
}
}  // namespace

CramerRaoBound posteriorCramerRao(const Model& model, const SimulatedRun& run, int stride) {
  if (stride < 1) throw InvalidArgument("posteriorCramerRao: stride must be >= 1");
  CramerRaoBound b;
  // Smoothing: one information matrix at the truth with all data.
  const Problem all = buildProblem(model, run.measurements, run.inputs);
  BatchSolver solver;
  solver.evaluateAt(all.graph, truthAt(all, run, model));
  for (const auto& m : run.measurements) {
    b.times.push_back(m.t);
    b.smoothing.push_back(boundAt(solver, model, stepAt(all, m.t)));
  }
  // Filtering: the information of the data up to t_k, at the truth.
  for (std::size_t i = 0; i < run.measurements.size(); ++i) {
    if ((i + 1) % static_cast<std::size_t>(stride) != 0 && i + 1 != run.measurements.size()) {
      b.filtering.emplace_back();
      continue;
    }
    const double t = run.measurements[i].t;
    const std::vector<Measurement> ms(run.measurements.begin(), run.measurements.begin() + static_cast<long>(i) + 1);
    std::vector<Input> in;
    for (const auto& u : run.inputs)
      if (u.t < t) in.push_back(u);
    const Problem p = buildProblem(model, ms, in);
    BatchSolver s;
    s.evaluateAt(p.graph, truthAt(p, run, model));
    b.filtering.push_back(boundAt(s, model, stepAt(p, t)));
  }
  return b;
}

bool ConstantsIdentifiability::determined(double tolerance) const {
  return eigenvalues.size() > 0 && eigenvalues[0] > tolerance * eigenvalues.maxCoeff();
}

ConstantsIdentifiability constantsIdentifiability(const Model& model, const Eigen::MatrixXd& posterior_constants,
                                                  double tolerance) {
  const int nb = model.dims().nb;
  if (posterior_constants.rows() != nb || posterior_constants.cols() != nb)
    throw InvalidArgument("constantsIdentifiability: expected a " + std::to_string(nb) + "x" + std::to_string(nb) +
                          " covariance of the constants");
  const Eigen::MatrixXd info = posterior_constants.inverse() - model.priorConstants().covariance.inverse();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (info + info.transpose()));
  ConstantsIdentifiability out;
  out.eigenvalues = es.eigenvalues();
  out.directions = es.eigenvectors();
  const double top = std::max(out.eigenvalues.maxCoeff(), 0.0);
  for (Eigen::Index i = 0; i < out.eigenvalues.size(); ++i) out.rank += out.eigenvalues[i] > tolerance * top ? 1 : 0;
  out.condition = out.eigenvalues[0] > tolerance * top ? top / out.eigenvalues[0]
                                                       : std::numeric_limits<double>::infinity();
  std::ostringstream os;
  os << std::setprecision(3);
  bool first = true;
  for (Eigen::Index i = 0; i < nb; ++i) {
    const double c = out.directions(i, 0);
    if (std::abs(c) < 1e-3) continue;
    os << (first ? (c < 0 ? "-" : "") : (c < 0 ? " - " : " + ")) << std::abs(c) << "*"
       << model.names().constants[static_cast<std::size_t>(i)];
    first = false;
  }
  os << " (data information " << out.eigenvalues[0] << ", largest " << top << ")";
  out.weakest = os.str();
  return out;
}

}  // namespace gssm
