#include "learn/constants_prior.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "gssm/core/error.h"
#include "gssm/core/parallel.h"
#include "gssm/factors/problem.h"
#include "learn/nelder_mead.h"

namespace gssm::internal {

namespace {
// −Q(σ) at θ = log σ (+∞ where the prior is not positive definite).
struct ExpectedLogPrior {
  const ParamValues& base;
  const std::vector<LearntParameter>& params;
  const std::string& type_name;
  Eigen::VectorXd m;
  Eigen::MatrixXd P;

  double negative(const Eigen::VectorXd& theta) const {
    if (!theta.allFinite()) return std::numeric_limits<double>::infinity();
    try {
      const Gaussian g = withSigmas(base, params, theta.array().exp().matrix()).build(type_name)->priorConstants();
      const Eigen::LLT<Eigen::MatrixXd> llt(g.covariance);
      if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
      const Eigen::VectorXd d = m - g.mean;
      const Eigen::MatrixXd S = P + d * d.transpose();
      const double logdet = 2 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
      return 0.5 * (logdet + llt.solve(S).trace());
    } catch (const Error&) {
      return std::numeric_limits<double>::infinity();
    }
  }
};

// E-step: the batch posterior of x_b on p's graph (its model's), from x
// (kept as the next start).
void posteriorOfConstants(const Problem& p, const BatchSolverOptions& batch, Values& x, ExpectedLogPrior& q) {
  // The M-step needs the posterior far less exactly than a batch run: a
  // last step lowering the cost by < 1e-8 of it leaves σ unchanged to 9
  // digits on the UWB log, and saves two of ~11 linearizations of the log.
  BatchSolverOptions e_step = batch;
  e_step.relative_cost_tolerance = std::max(e_step.relative_cost_tolerance, 1e-8);
  // Its last, undamped step (predicted to lower the cost by < 1e-8 of it)
  // is taken without a linearization after it: one pass of the log of ~6
  // fewer, P from the factorization before that step (a polish, asked
  // for, relinearizes anyway).
  if (e_step.newton_polish_steps == 0) e_step.relinearize_at_solution = false;
  BatchSolver solver(e_step);
  solver.solve(p.graph, x);
  q.m = x.at(Key::constants());
  q.P = solver.marginalCovariance(Key::constants());
}

// Standard errors from the curvature of Q in log σ: the complete-data
// information, so they are lower bounds (the batch posterior's own
// uncertainty about x_b is small beside the spread when it matters).
void standardErrorsOfQ(const ExpectedLogPrior& q, const Eigen::VectorXd& theta, std::vector<LearntParameter>& ps) {
  const Eigen::Index n = theta.size();
  const double h = 1e-3, f0 = q.negative(theta);
  Eigen::MatrixXd H(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      Eigen::VectorXd a = theta, b = theta, c = theta, d = theta;
      a[i] += h, a[j] += h, b[i] += h, b[j] -= h, c[i] -= h, c[j] += h, d[i] -= h, d[j] -= h;
      H(i, j) = i == j ? (q.negative(a) - 2 * f0 + q.negative(d)) / (4 * h * h)
                       : (q.negative(a) - q.negative(b) - q.negative(c) + q.negative(d)) / (4 * h * h);
    }
  const Eigen::LLT<Eigen::MatrixXd> llt(H);
  if (llt.info() != Eigen::Success) {
    for (auto& p : ps) p.identifiable = false, p.note = "the expected log prior is flat here";
    return;
  }
  const Eigen::MatrixXd C = llt.solve(Eigen::MatrixXd::Identity(n, n));
  for (Eigen::Index i = 0; i < n; ++i) {
    LearntParameter& p = ps[static_cast<std::size_t>(i)];
    p.standard_error = p.value * std::sqrt(C(i, i));
    if (p.standard_error > p.value) p.identifiable = false, p.note = "relative standard error > 100%";
  }
}
}  // namespace

void learnConstantsPrior(const std::string& type_name, std::vector<LearntParameter> params,
                         const std::vector<Measurement>& measurements, const std::vector<Input>& inputs, double t0,
                         const NoiseLearningOptions& o, NoiseLearningReport& r) {
  const auto started = std::chrono::steady_clock::now();
  const ParamValues base = r.values;
  const auto n = static_cast<Eigen::Index>(params.size());
  Eigen::VectorXd theta(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    LearntParameter& p = params[static_cast<std::size_t>(i)];
    p.start = o.start > 0 ? o.start : p.given;
    if (!(p.start > 0))
      throw InvalidArgument("learning " + p.name() + ": it is 0 in the model; give a start ([learn] start) or a value > 0");
    theta[i] = std::log(p.start);
  }
  ExpectedLogPrior q{base, params, type_name, {}, {}};
  ParamValues values = withSigmas(base, params, theta.array().exp().matrix());
  std::shared_ptr<const Model> model = values.build(type_name);
  // The EKF's pass (the first E-step's start) and the E-steps' graph are
  // independent: on two threads when the batch may use two. EM changes the
  // constants' prior alone, so every E-step solves this graph with its
  // model's priors (its other factors refer to this first model, kept).
  const std::shared_ptr<const Model> graph_model = model;
  Values x;
  Problem p;
  const auto failed = runJobs(2, static_cast<std::size_t>(o.batch.threads), [&](std::size_t k) {
    if (k == 0) x = ekfInitialGuess(*model, o.ekf, measurements, inputs, t0);
    else p = buildProblem(*model, measurements, inputs, t0);
  });
  for (const auto& e : failed)
    if (e) std::rethrow_exception(e);
  r.prior_converged = false;
  for (int it = 1; it <= o.prior_iterations && !r.prior_converged; ++it) {
    r.prior_iterations = it;
    if (it > 1) replacePriors(p, *model);
    posteriorOfConstants(p, o.batch, x, q);
    if (it == 1) r.prior_start_expected_log_prior = -q.negative(theta);
    const NelderMeadResult m = nelderMead([&q](const Eigen::VectorXd& t) { return q.negative(t); }, theta, 0.5,
                                          200 * static_cast<int>(n + 1), 1e-12, 1e-9);
    r.prior_converged = ((m.x - theta).array().abs()).maxCoeff() <= o.prior_tolerance;  // in log σ: relative
    theta = m.x;
    r.prior_expected_log_prior.push_back(-m.value);
    values = withSigmas(base, params, theta.array().exp().matrix());
    model = values.build(type_name);
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    LearntParameter& p = params[static_cast<std::size_t>(i)];
    p.value = std::exp(theta[i]);
    p.method = "em";
  }
  standardErrorsOfQ(q, theta, params);  // from Q's curvature: no filter pass, so always
  r.values = withSigmas(base, params, sigmasOf(theta));  // the σs the parameters report, to the bit
  r.model = r.values.build(type_name);
  r.posterior = std::move(x);
  r.parameters.insert(r.parameters.end(), params.begin(), params.end());
  r.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

}  // namespace gssm::internal
