// Noise learnt from the data (docs/DESIGN.md §10), against independent
// references: the Kalman filter's likelihood, the closed-form EM of
// Shumway and Stoffer (1982) for linear Gaussian state space models, and the
// noise a simulation was drawn with.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "gssm/core/error.h"
#include "gssm/learn/noise_learning.h"
#include "gssm/model/param_values.h"
#include "gssm/model/registry.h"
#include "gssm/models/linear.h"
#include "gssm/models/range_beacon2d.h"
#include "learn/scoring.h"
#include "reference_kalman.h"
#include "track_with_bias.h"

namespace gssm {
namespace {

// A constant-velocity track measured with a constant bias: Q = diag(q1, q2), R = r.
models::LinearModel cvWithBias(double q1, double q2, double r) {
  return models::LinearModel(testing::trackWithBias(q1, q2, r, 1.0, 0.5, 1.0));
}

SimulatedRun simulateRun(const Model& m, int steps, unsigned seed) {
  SimulationSpec spec;
  spec.steps = steps;
  return simulate(m, spec, testing::normalSampler(seed));
}

// Σ log N(y_k − H z_{k|k−1}; 0, H P_{k|k−1} Hᵀ + R) from the textbook filter.
double kalmanLogLikelihood(const testing::StackedLinear& s, const testing::KalmanRun& kr,
                           const std::vector<Measurement>& ys) {
  double l = 0;
  for (std::size_t k = 1; k <= ys.size(); ++k) {
    const Eigen::MatrixXd S = s.H * kr.Pp[k] * s.H.transpose() + s.R;
    const Eigen::VectorXd e = ys[k - 1].y - s.H * kr.zp[k];
    l -= 0.5 * (e.dot(S.ldlt().solve(e)) + std::log(S.determinant()) + e.size() * std::log(2 * M_PI));
  }
  return l;
}

// Shumway–Stoffer EM for diagonal Q (of x_c) and R, the prior held: E-step
// by the RTS smoother with the lag-one covariances Cov(z_k, z_{k−1}) =
// P_{k|N} G_{k−1}ᵀ; M-step the diagonals of the expected squared residuals.
struct EmResult {
  Eigen::Vector2d q;
  double r = 0;
  int iterations = 0;
};
EmResult shumwayStofferEm(const std::vector<Measurement>& ys, Eigen::Vector2d q, double r) {
  EmResult out;
  const auto N = static_cast<double>(ys.size());
  for (out.iterations = 0; out.iterations < 100000; ++out.iterations) {
    const auto s = testing::stack(cvWithBias(q[0], q[1], r), 1.0);
    const auto kr = testing::kalmanAndRts(s, ys);
    Eigen::Matrix3d Sq = Eigen::Matrix3d::Zero();
    double Sr = 0;
    for (std::size_t k = 1; k < kr.zs.size(); ++k) {
      const Eigen::MatrixXd G = kr.Pf[k - 1] * s.F.transpose() * kr.Pp[k].inverse();
      const Eigen::MatrixXd C = kr.Ps[k] * G.transpose();  // Cov(z_k, z_{k−1} | all)
      const Eigen::VectorXd w = kr.zs[k] - s.F * kr.zs[k - 1];
      Sq += w * w.transpose() + kr.Ps[k] - s.F * C.transpose() - C * s.F.transpose() +
            s.F * kr.Ps[k - 1] * s.F.transpose();
      const Eigen::VectorXd e = ys[k - 1].y - s.H * kr.zs[k];
      Sr += e.squaredNorm() + (s.H * kr.Ps[k] * s.H.transpose())(0, 0);
    }
    const Eigen::Vector2d q_new = Sq.diagonal().head<2>() / N;
    const double r_new = Sr / N;
    const double change = std::max((q_new - q).cwiseQuotient(q).cwiseAbs().maxCoeff(), std::abs(r_new - r) / r);
    q = q_new, r = r_new;
    if (change < 1e-11) break;
  }
  out.q = q, out.r = r;
  return out;
}

TEST(NoiseLearning, PredictionErrorLikelihoodIsTheKalmanFiltersOnALinearModel) {
  const auto truth = cvWithBias(0.04, 0.01, 1.0);
  const SimulatedRun run = simulateRun(truth, 200, 5);
  for (const auto& [q1, q2, r] : {std::tuple{0.04, 0.01, 1.0}, {1.0, 1.0, 1.0}, {0.001, 0.3, 5.0}}) {
    const auto m = cvWithBias(q1, q2, r);
    const auto s = testing::stack(m, 1.0);
    const double ref = kalmanLogLikelihood(s, testing::kalmanAndRts(s, run.measurements), run.measurements);
    EXPECT_NEAR(predictionErrorLogLikelihood(m, run.measurements, {}, 0.0), ref, 1e-9 * std::abs(ref));
  }
}

// Counting only some channels' innovations (likelihood_channels) gives the
// likelihood of those given the rest: with the other channel carrying no
// information (R = 1e12), the textbook filter's on channel 0's data alone.
TEST(NoiseLearning, LikelihoodOfTheCountedChannelsGivenTheRest) {
  const SimulatedRun run = simulateRun(cvWithBias(0.04, 0.01, 1.0), 200, 9);
  models::LinearSystem sys = testing::trackWithBias(0.04, 0.01, 1.0, 1.0, 0.5, 1.0);
  sys.channels.push_back({"aux", Eigen::RowVector2d(1, 0), Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Constant(1, 1, 1e12), {}});
  const models::LinearModel two(sys);
  std::vector<Measurement> both;
  for (const auto& m : run.measurements) {
    both.push_back(m);
    both.push_back({m.t, Eigen::VectorXd::Constant(1, 5.0), 1});  // after channel 0's at the same time
  }
  const auto s = testing::stack(cvWithBias(0.04, 0.01, 1.0), 1.0);
  const double ref = kalmanLogLikelihood(s, testing::kalmanAndRts(s, run.measurements), run.measurements);
  ExtendedKalmanFilterOptions counted;
  counted.likelihood_channels = {0};
  EXPECT_NEAR(predictionErrorLogLikelihood(two, both, {}, 0.0, counted), ref, 1e-8 * std::abs(ref));
  // Every channel counted: the aux terms, each about −½ log(2π·1e12).
  EXPECT_LT(predictionErrorLogLikelihood(two, both, {}, 0.0), ref - 100 * 14);
  counted.likelihood_channels = {2};
  EXPECT_THROW(predictionErrorLogLikelihood(two, both, {}, 0.0, counted), InvalidArgument);
}

// likelihood_spacing: learning from a log whose counted channel's
// measurements are spaced out equals learning from that log thinned by
// hand (every third of channel 0's, each channel-1 measurement kept, since
// it is not counted); 0 is every measurement; a negative spacing is refused.
TEST(NoiseLearning, LikelihoodSpacingLearnsFromTheCountedMeasurementsSpacedOut) {
  const SimulatedRun run = simulateRun(cvWithBias(0.04, 0.01, 1.0), 300, 21);
  models::LinearSystem sys = testing::trackWithBias(1, 1, 1, 1.0, 0.5, 1.0);
  sys.channels.push_back({"aux", Eigen::RowVector2d(1, 0), Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Constant(1, 1, 4.0), {}});
  const models::LinearModel two(sys);
  std::vector<Measurement> both, by_hand;
  for (std::size_t i = 0; i < run.measurements.size(); ++i) {
    const Measurement& m = run.measurements[i];
    const Measurement aux(m.t, m.y + Eigen::VectorXd::Constant(1, 0.5), 1);
    both.push_back(m);
    both.push_back(aux);
    if (i % 3 == 0) by_hand.push_back(m);
    by_hand.push_back(aux);
  }
  NoiseLearningOptions o;
  o.parameters = {"Q"};
  o.ekf.likelihood_channels = {0};
  const NoiseLearningReport every = learnNoise(two, both, {}, 0.0, o);
  const NoiseLearningReport thinned = learnNoise(two, by_hand, {}, 0.0, o);
  o.likelihood_spacing = 2.5;  // the steps are 1 s: every third kept
  const NoiseLearningReport spaced = learnNoise(two, both, {}, 0.0, o);
  ASSERT_TRUE(spaced.converged) << spaced.toString();
  ASSERT_EQ(spaced.parameters.size(), thinned.parameters.size());
  for (std::size_t i = 0; i < spaced.parameters.size(); ++i) {
    EXPECT_EQ(spaced.parameters[i].value, thinned.parameters[i].value) << spaced.parameters[i].name();
    EXPECT_NE(spaced.parameters[i].value, every.parameters[i].value) << spaced.parameters[i].name();
  }
  EXPECT_EQ(spaced.final_log_likelihood, thinned.final_log_likelihood);
  EXPECT_EQ(spaced.measurements, by_hand.size());
  o.likelihood_spacing = -1;
  std::string why;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("likelihood_spacing"), std::string::npos) << why;
}

// The linear run the EM comparisons learn from, from σ = 1: the learner's
// options, and EM's maximum from the same start.
struct EmCase {
  SimulatedRun run = simulateRun(cvWithBias(0.04, 0.01, 1.0), 400, 11);
  EmResult em = shumwayStofferEm(run.measurements, Eigen::Vector2d(1, 1), 1.0);
  NoiseLearningReport learn(const NoiseLearningOptions& o) const {
    return learnNoise(cvWithBias(1, 1, 1), run.measurements, {}, 0.0, o);
  }
};

// The learnt Q and R are EM's (1e-4), Q still diagonal.
void expectAtTheEmMaximum(const NoiseLearningReport& r, const EmResult& em) {
  ASSERT_TRUE(r.converged) << r.toString();
  ASSERT_EQ(r.parameters.size(), 3u) << r.toString();  // Q[0], Q[1], R[0]
  const auto& sys = dynamic_cast<const models::LinearModel&>(*r.model).system();
  EXPECT_NEAR(sys.noise.Q(0, 0), em.q[0], 1e-4 * em.q[0]) << r.toString() << "EM iterations " << em.iterations;
  EXPECT_NEAR(sys.noise.Q(1, 1), em.q[1], 1e-4 * em.q[1]) << r.toString();
  EXPECT_NEAR(sys.noise.R(0, 0), em.r, 1e-4 * em.r) << r.toString();
  EXPECT_EQ(sys.noise.Q(0, 1), 0.0);
}

TEST(NoiseLearning, EqualsShumwayStofferEmOnALinearModel) {
  const EmCase c;
  NoiseLearningOptions o;
  o.start = 1.0;
  o.tolerance = 1e-13;
  const NoiseLearningReport r = c.learn(o);
  expectAtTheEmMaximum(r, c.em);
  // The learnt model's likelihood is the maximum the report says.
  EXPECT_NEAR(predictionErrorLogLikelihood(*r.model, c.run.measurements, {}, 0.0), r.final_log_likelihood, 1e-9);
}

TEST(NoiseLearning, LogLikelihoodNeverDecreasesAndBeatsTheStart) {
  const SimulatedRun run = simulateRun(cvWithBias(0.04, 0.01, 1.0), 300, 3);
  NoiseLearningOptions o;
  o.start = 1.0;
  const NoiseLearningReport r = learnNoise(cvWithBias(0.5, 0.5, 0.5), run.measurements, {}, 0.0, o);
  ASSERT_GT(r.log_likelihood.size(), 10u);
  for (std::size_t i = 1; i < r.log_likelihood.size(); ++i)
    EXPECT_GE(r.log_likelihood[i], r.log_likelihood[i - 1]) << "iteration " << i;
  EXPECT_GT(r.final_log_likelihood, r.start_log_likelihood);
  EXPECT_GT(r.final_log_likelihood, r.given_log_likelihood);
  EXPECT_EQ(r.log_likelihood.back(), r.final_log_likelihood);
  for (const auto& p : r.parameters) {
    EXPECT_EQ(p.start, 1.0);
    EXPECT_DOUBLE_EQ(p.given, std::sqrt(0.5)) << p.name();  // σ of a variance 0.5
  }
}

// Fraction of (seed, parameter) pairs whose learnt σ is within 2 reported
// standard errors of the σ the data were drawn with; a σ the run did not
// resolve (flagged, no standard error) counts as a miss.
template <class Learn>
double coverage(int seeds, const std::vector<double>& truth, Learn learn) {
  int inside = 0, total = 0, unresolved = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    const NoiseLearningReport r = learn(static_cast<unsigned>(seed));
    EXPECT_EQ(r.parameters.size(), truth.size());
    for (std::size_t i = 0; i < r.parameters.size() && i < truth.size(); ++i) {
      const auto& p = r.parameters[i];
      unresolved += !p.identifiable;
      inside += p.identifiable && std::abs(p.value - truth[i]) <= 2 * p.standard_error;
      ++total;
    }
  }
  std::cout << inside << " of " << total << " learnt σ within 2 standard errors of the truth (" << unresolved
            << " flagged as not resolved)\n";
  return static_cast<double>(inside) / total;
}

TEST(NoiseLearning, RecoversALinearModelsNoiseWithinItsStandardErrors) {
  // Parameters in name order: Q[0], Q[1], R[0] (σs).
  const double c = coverage(50, {0.5, 0.1, 0.5}, [](unsigned seed) {
    const SimulatedRun run = simulateRun(cvWithBias(0.25, 0.01, 0.25), 500, 100 + seed);
    NoiseLearningOptions o;
    o.start = 1.0;
    return learnNoise(cvWithBias(1, 1, 1), run.measurements, {}, 0.0, o);
  });
  EXPECT_GE(c, 0.9) << "learnt σ within 2 standard errors of the truth";
}

models::RangeBeacon2D::Params beaconParams() {
  models::RangeBeacon2D::Params p;
  p.beacon_ids = {0, 1, 5, 6};
  p.beacons = {{-33.6, 27.0}, {-68.9, 18.4}, {1.7, -5.8}, {-37.6, 69.2}};
  p.start = Eigen::Vector3d(-34, 55, 0);
  p.start_sd = Eigen::Vector3d(1, 1, 0.5);
  return p;
}

TEST(NoiseLearning, RecoversRangeBeaconNoiseWithinItsStandardErrors) {
  // beacons-consistent: a vehicle circling inside four beacons. At a constant
  // speed and turn rate the per-metre, per-radian and per-second terms are
  // proportional, so only one position and one heading term can be learnt:
  // range_sd, distance_sd and turn_sd, the floors held at the truth.
  models::RangeBeacon2D::Params p = beaconParams();
  p.range_sd = 0.5, p.distance_sd = 0.05, p.turn_sd = 0.05, p.heading_drift_sd = 0.001;
  const models::RangeBeacon2D truth(p);
  const double c = coverage(50, {0.05, 0.5, 0.05}, [&](unsigned seed) {
    SimulationSpec spec;
    spec.steps = 2000;
    spec.input = [](double, const Eigen::VectorXd&) { return Eigen::Vector2d(3.0, 0.1); };
    spec.measure_every = 2;
    spec.channels = {0, 1, 2, 3};
    const SimulatedRun run = simulate(truth, spec, testing::normalSampler(200 + seed));
    NoiseLearningOptions o;
    o.parameters = {"range_sd", "distance_sd", "turn_sd"};
    o.start = 1.0;
    return learnNoise(truth, run.measurements, run.inputs, 0.0, o);
  });
  EXPECT_GE(c, 0.9) << "learnt σ within 2 standard errors of the truth";
}

TEST(NoiseLearning, NamesWhatItCannotLearn) {
  const auto m = cvWithBias(1, 1, 1);
  const SimulatedRun run = simulateRun(m, 20, 1);
  NoiseLearningOptions o;
  o.parameters = {"range_sd"};
  try {
    learnNoise(m, run.measurements, {}, 0.0, o);
    FAIL() << "an unknown parameter must be refused";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("'range_sd' is not a learnable parameter of model 'linear'"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("Q[0], Q[1], R[0]"), std::string::npos) << e.what();
  }
  o.parameters = {"Q[1]"};
  o.start = 0;
  const auto r = learnNoise(m, run.measurements, {}, 0.0, o);
  ASSERT_EQ(r.parameters.size(), 1u);
  EXPECT_EQ(r.parameters[0].name(), "Q[1]");
  o.search_range = 1.0;
  EXPECT_THROW(learnNoise(m, run.measurements, {}, 0.0, o), InvalidArgument);
}

TEST(ParamValues, AModelRebuildsFromItsValues) {
  for (const ModelType* type : modelTypes()) {
    if (type->name != "linear" && type->name != "range_beacon_2d") continue;
    const std::unique_ptr<Model> m =
        type->name == "linear" ? std::unique_ptr<Model>(new models::LinearModel(cvWithBias(0.1, 0.2, 0.3)))
                               : std::unique_ptr<Model>(new models::RangeBeacon2D(beaconParams()));
    const ParamValues v = ParamValues::of(*m);
    const auto again = v.build(type->name);
    const ParamValues w = ParamValues::of(*again);
    ASSERT_EQ(v.keys(), w.keys()) << type->name;
    for (const auto& [section, key] : v.keys()) EXPECT_TRUE(*v.find(section, key) == *w.find(section, key)) << key;
  }
}

}  // namespace
}  // namespace gssm

namespace gssm {
namespace {

TEST(NoiseLearning, AnOutlierMixtureKeepsGrossErrorsOutOfTheLearntNoise) {
  // 5% of the measurements 10–40 σ long (multipath): the Gaussian
  // likelihood explains them with a larger R; the bounded mixture learns
  // them as outliers and R as it was drawn.
  SimulatedRun run = simulateRun(cvWithBias(0.25, 0.01, 0.25), 1500, 21);
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> u01;
  int outliers = 0;
  for (auto& m : run.measurements)
    if (u01(rng) < 0.05) m.y[0] += 5 + 15 * u01(rng), ++outliers;
  NoiseLearningOptions o;
  o.start = 1.0;
  const NoiseLearningReport gaussian = learnNoise(cvWithBias(1, 1, 1), run.measurements, {}, 0.0, o);
  o.outliers = true;
  const NoiseLearningReport mixture = learnNoise(cvWithBias(1, 1, 1), run.measurements, {}, 0.0, o);
  const LearntParameter& rg = gaussian.parameters[2];
  const LearntParameter& rm = mixture.parameters[2];
  ASSERT_EQ(rm.name(), "R[0]");
  EXPECT_GT(rg.value, 2 * 0.5) << gaussian.toString();  // inflated by the outliers
  EXPECT_LT(std::abs(rm.value - 0.5), 3 * rm.standard_error) << mixture.toString();
  EXPECT_NEAR(mixture.outlier_probability, static_cast<double>(outliers) / run.measurements.size(), 0.02)
      << mixture.toString();
  EXPECT_GT(mixture.mixture_from, 0u);
  for (std::size_t i = mixture.mixture_from + 1; i < mixture.log_likelihood.size(); ++i)
    EXPECT_GE(mixture.log_likelihood[i], mixture.log_likelihood[i - 1]);
  EXPECT_GT(mixture.final_log_likelihood, mixture.gaussian_log_likelihood);
  std::cout << "R σ drawn 0.5: Gaussian " << rg.value << ", mixture " << rm.value << " ± " << rm.standard_error
            << ", ε " << mixture.outlier_probability << " (" << outliers << " outliers)\n";
}

}  // namespace
}  // namespace gssm

namespace gssm {
namespace {

// The filter's log-likelihood terms are the updates' log N(e; 0, S), in
// order: they sum to the total, and only the counted channels are kept.
TEST(NoiseLearning, TheFiltersLikelihoodTermsSumToItsTotal) {
  const SimulatedRun run = simulateRun(cvWithBias(0.04, 0.01, 1.0), 200, 7);
  const auto m = cvWithBias(0.1, 0.02, 0.8);
  ExtendedKalmanFilterOptions o;
  o.use_gates = false;
  o.keep_log_likelihood_terms = true;
  ExtendedKalmanFilter f(m, o, 0.0);
  filterAlong(f, stepSchedule(run.measurements, {}, 0.0), run.measurements, {});
  ASSERT_EQ(f.logLikelihoodTerms().size(), run.measurements.size());
  double sum = 0;
  for (double t : f.logLikelihoodTerms()) sum += t;
  EXPECT_NEAR(sum, f.logLikelihood(), 1e-12 * std::abs(sum));
  EXPECT_NEAR(f.logLikelihood(), predictionErrorLogLikelihood(m, run.measurements, {}, 0.0), 1e-12 * std::abs(sum));
}

// Scoring (gradient from every term's differences, BFGS from their outer
// product) climbs to the maximum Shumway–Stoffer's EM converges to, in far
// fewer filter passes than Nelder–Mead, and the same on two threads.
// From every σ = 1 to a tight tolerance, no standard errors.
NoiseLearningOptions fromOnesToTheTop(const std::string& optimizer) {
  NoiseLearningOptions o;
  o.start = 1.0;
  o.tolerance = 1e-10;
  o.standard_errors = false;
  o.optimizer = optimizer;
  return o;
}

TEST(NoiseLearning, ScoringReachesTheEmMaximumInFewerPasses) {
  const EmCase c;
  NoiseLearningOptions o = fromOnesToTheTop("nelder-mead");
  const NoiseLearningReport nm = c.learn(o);
  o.optimizer = "scoring";
  const NoiseLearningReport r = c.learn(o);
  expectAtTheEmMaximum(r, c.em);
  EXPECT_NEAR(r.final_log_likelihood, nm.final_log_likelihood, 1e-8 * std::abs(nm.final_log_likelihood));
  EXPECT_LT(3 * r.evaluations, nm.evaluations) << "scoring " << r.evaluations << ", Nelder–Mead " << nm.evaluations;
  for (std::size_t i = 1; i < r.log_likelihood.size(); ++i) EXPECT_GT(r.log_likelihood[i], r.log_likelihood[i - 1]);
  std::cout << "filter passes: scoring " << r.evaluations << ", Nelder–Mead " << nm.evaluations << "\n";
  o.threads = 2;
  const NoiseLearningReport two = c.learn(o);
  ASSERT_EQ(two.parameters.size(), r.parameters.size());
  for (std::size_t i = 0; i < r.parameters.size(); ++i) EXPECT_EQ(two.parameters[i].value, r.parameters[i].value);
  EXPECT_EQ(two.log_likelihood, r.log_likelihood);  // the same path
  // the trials after one that passes are extra
  EXPECT_GE(two.evaluations, r.evaluations);
}

// Learning from its own maximum: the given values, the start and scoring's
// first point are one θ, and its filter pass runs once (beside the slope's
// p passes), not three times; the values are what one pass gives.
TEST(NoiseLearning, APassAtANoiseAlreadyRunIsNotRunAgain) {
  const EmCase c;
  NoiseLearningOptions o = fromOnesToTheTop("scoring");
  const NoiseLearningReport top = c.learn(o);
  ASSERT_TRUE(top.converged) << top.toString();
  o.start = 0;  // from the given values: the maximum
  for (const int threads : {1, 2}) {
    o.threads = threads;
    const NoiseLearningReport again = learnNoise(*top.model, c.run.measurements, {}, 0.0, o);
    ASSERT_TRUE(again.converged) << again.toString();
    EXPECT_EQ(again.iterations, 1) << again.toString();
    const int p = static_cast<int>(again.parameters.size());
    EXPECT_EQ(again.evaluations, p + 1) << again.toString();
    const double one_pass = predictionErrorLogLikelihood(*top.model, c.run.measurements, {}, 0.0);
    EXPECT_NEAR(again.given_log_likelihood, one_pass, 1e-12 * std::abs(one_pass));
    EXPECT_EQ(again.start_log_likelihood, again.given_log_likelihood);
    EXPECT_EQ(again.final_log_likelihood, again.given_log_likelihood);
  }
}

// A σ the log cannot tell from 0 (a process noise far below what the data
// resolve) ends at the low end of its range, its gradient pointing out:
// scoring holds it there and it is flagged, as with Nelder–Mead; where the
// two end inside the range they agree.
TEST(NoiseLearning, ScoringHoldsASigmaAtTheEndOfItsRangeAsNelderMeadDoes) {
  int at_end = 0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const SimulatedRun run = simulateRun(cvWithBias(0.25, 1e-12, 0.25), 300, seed);
    NoiseLearningOptions o;
    o.start = 1.0;
    o.search_range = 1e3;
    const NoiseLearningReport nm = learnNoise(cvWithBias(1, 1, 1), run.measurements, {}, 0.0, o);
    o.optimizer = "scoring";
    const NoiseLearningReport r = learnNoise(cvWithBias(1, 1, 1), run.measurements, {}, 0.0, o);
    EXPECT_TRUE(r.converged) << r.toString();
    EXPECT_NEAR(r.final_log_likelihood, nm.final_log_likelihood, 1e-3) << r.toString() << nm.toString();
    for (std::size_t i = 0; i < 3; ++i) {
      const LearntParameter &a = r.parameters[i], &b = nm.parameters[i];
      const bool end = b.value < 1.01e-3;
      at_end += end;
      EXPECT_EQ(a.value < 1.01e-3, end) << "seed " << seed << "\n" << r.toString() << nm.toString();
      if (end) EXPECT_FALSE(a.identifiable) << r.toString();
      else EXPECT_NEAR(a.value, b.value, 0.02 * b.value) << "seed " << seed << "\n" << r.toString() << nm.toString();
    }
  }
  std::cout << at_end << " σ of 24 at the end of their range\n";
  EXPECT_GT(at_end, 0) << "no seed put a σ at the end of its range: the test tests nothing";
}

TEST(NoiseLearning, AnUnknownOptimizerIsRefused) {
  NoiseLearningOptions o;
  o.optimizer = "newton";
  std::string why;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("optimizer 'newton'"), std::string::npos) << why;
}

}  // namespace
}  // namespace gssm

namespace gssm {
namespace {

// Scoring on a likelihood known in closed form: terms −½(y_k − θ)², whose
// maximum is the mean of y; and where passes fail beyond θ = 0.5 (a filter
// that diverges there), it stops below without crashing, converged or not.
TEST(Scoring, ReachesAClosedFormMaximumAndStopsWherePassesFail) {
  const Eigen::VectorXd y = (Eigen::VectorXd(5) << 0.9, 1.3, 0.7, 1.1, 1.5).finished();
  auto at = [&](double fail_above) {
    return [&y, fail_above](const std::vector<Eigen::VectorXd>& thetas) {
      std::vector<internal::LikelihoodTerms> out;
      for (const auto& th : thetas) {
        internal::LikelihoodTerms t;
        if (th[0] > fail_above) {
          t.total = -std::numeric_limits<double>::infinity();
        } else {
          t.terms = -0.5 * (y.array() - th[0]).square().matrix();
          t.total = t.terms.sum();
        }
        out.push_back(t);
      }
      return out;
    };
  };
  internal::ScoringOptions o;
  o.lo = Eigen::VectorXd::Constant(1, -10), o.hi = Eigen::VectorXd::Constant(1, 10);
  o.tolerance = 1e-12;
  const auto r = internal::maximizeByScoring(at(1e9), Eigen::VectorXd::Zero(1), o);
  EXPECT_TRUE(r.converged);
  // Forward differences put the top half a step (step/2 = 5e-6) below it.
  EXPECT_NEAR(r.x[0], y.mean() - 0.5 * o.step, 1e-9);
  const auto cut = internal::maximizeByScoring(at(0.5), Eigen::VectorXd::Zero(1), o);
  EXPECT_LE(cut.x[0], 0.5);
  EXPECT_TRUE(std::isfinite(cut.value));
  EXPECT_GT(cut.value, at(1e9)({Eigen::VectorXd::Zero(1)}).front().total);
  // Two line-search trials at a time (for passes run two at a time) take
  // the step one at a time takes: the same path, only more passes where
  // the first trial passes.
  for (const double fail_above : {1e9, 0.5}) {
    internal::ScoringOptions two = o;
    two.parallel_passes = 2;
    const auto serial = internal::maximizeByScoring(at(fail_above), Eigen::VectorXd::Zero(1), o);
    const auto batched = internal::maximizeByScoring(at(fail_above), Eigen::VectorXd::Zero(1), two);
    EXPECT_EQ(batched.x[0], serial.x[0]) << fail_above;
    EXPECT_EQ(batched.value, serial.value) << fail_above;
    EXPECT_EQ(batched.iterations, serial.iterations) << fail_above;
    EXPECT_EQ(batched.converged, serial.converged) << fail_above;
  }
}

// With passes two at a time, on three parameters each line-search trial
// runs beside a slope pass at its point and the start beside its slope's:
// a taken step costs two rounds (trial + 3 slope passes), not three (the
// trial alone, then the slope's); on two, the trials go two at a time and
// the slope's passes fill a round. Either way along the serial path.
TEST(Scoring, RunsTheNextSlopesPassesBesideEachTrialAlongTheSerialPath) {
  const Eigen::MatrixXd y_all =
      (Eigen::MatrixXd(4, 3) << 0.9, -1, 2, 1.3, -2, 2.5, 0.7, -1.5, 1, 1.1, -0.5, 3).finished();
  for (const Eigen::Index p : {2, 3}) {
    const Eigen::MatrixXd y = y_all.leftCols(p);
    const Eigen::ArrayXd weight = Eigen::Vector3d(1, 4, 0.25).head(p).array();
    int rounds = 0;  // wall-clock rounds of passes two at a time
    const internal::LikelihoodTermsAt at = [&](const std::vector<Eigen::VectorXd>& thetas) {
      rounds += static_cast<int>((thetas.size() + 1) / 2);
      std::vector<internal::LikelihoodTerms> out;
      for (const auto& th : thetas) {
        internal::LikelihoodTerms t;
        t.terms = -0.5 * ((y.rowwise() - th.transpose()).array().square().rowwise() * weight.transpose())
                             .rowwise()
                             .sum()
                             .matrix();
        t.total = t.terms.sum();
        out.push_back(t);
      }
      return out;
    };
    internal::ScoringOptions o;
    o.lo = Eigen::VectorXd::Constant(p, -10), o.hi = Eigen::VectorXd::Constant(p, 10);
    o.tolerance = 1e-12;
    const auto serial = internal::maximizeByScoring(at, Eigen::VectorXd::Zero(p), o);
    internal::ScoringOptions two = o;
    two.parallel_passes = 2;
    rounds = 0;
    const auto batched = internal::maximizeByScoring(at, Eigen::VectorXd::Zero(p), two);
    ASSERT_TRUE(serial.converged) << p;
    EXPECT_EQ(batched.x, serial.x) << p;
    EXPECT_EQ(batched.value, serial.value) << p;
    EXPECT_EQ(batched.iterations, serial.iterations) << p;
    EXPECT_TRUE(batched.converged) << p;
    // the top: each column's mean (less half a forward step)
    EXPECT_LT((serial.x - y.colwise().mean().transpose()).cwiseAbs().maxCoeff(), 1e-4) << p;
    // Serially p + 1 passes a taken step; two at a time a round per two
    // (the trial alone, then the slope's: 3 rounds of 4 passes on three).
    EXPECT_LE(2 * rounds, serial.evaluations + 2 * (batched.evaluations - serial.evaluations)) << p;
    EXPECT_LT(4 * rounds, 3 * serial.evaluations) << rounds << " rounds, " << serial.evaluations << " serial passes";
  }
}

}  // namespace
}  // namespace gssm
