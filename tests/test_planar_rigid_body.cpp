// PlanarRigidBody (the UWB planar-pose model): Jacobians of every link
// against central differences (yaw near ±π too), its INI form, and a
// simulated run of the uwb-fast layout (the same anchors and lever arms,
// known biases, white noise) on which every method recovers the biases
// within their reported 2σ and the incremental smoother equals the batch.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cstdio>
#include <random>

#include "gssm/analysis/offline.h"
#include "gssm/checkpoint/checkpoint.h"
#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/learn/noise_learning.h"
#include "gssm/model/simulation.h"
#include "gssm/model/colored_noise.h"
#include "gssm/models/planar_rigid_body.h"
#include "jacobian_check.h"

using namespace gssm;
using models::PlanarRigidBody;

namespace {
// The uwb-fast layout: eight anchors around 7 m × 6 m, three tags on a plate.
PlanarRigidBody::Params uwbLayout() {
  PlanarRigidBody::Params p;
  p.anchor_ids = {0, 1, 2, 3, 4, 5, 6, 7};
  p.anchors = {{-3.4203, 3.0053, 1.0442}, {0.0016, 3.0110, 1.0446}, {3.6056, 2.9795, 1.0463},
               {3.6011, -0.0008, 1.0422}, {3.5674, -3.0087, 1.0443}, {-0.0072, -2.9652, 1.0444},
               {-3.4673, -2.9587, 1.0445}, {-3.4858, -0.0098, 1.0457}};
  p.tag_ids = {0, 1, 2};
  p.tags = {{-0.0689, -0.1423, 0.0011}, {-0.0750, 0.1402, 0.0016}, {0.2034, 0.1451, -0.0008}};
  p.height = 0.97;
  return p;
}
}  // namespace

TEST(PlanarRigidBody, AnalyticJacobiansMatchCentralDifferencesOnEveryLink) {
  for (int variant = 0; variant < 4; ++variant) {
    const bool scale = variant == 1 || variant == 3, errors = variant == 2;
    const int antenna = variant == 3 ? 2 * 2 * 3 : 0;  // harmonics 2 and 3 of three tags
    PlanarRigidBody::Params p = uwbLayout();
    p.range_scale = scale;
    p.antenna_harmonics = variant == 3 ? 3 : 0;
    ColoredNoise gm;  // a Gauss–Markov error state per link
    if (errors) gm.channels = {"all"}, gm.tau = 0.3, gm.sd = 0.05;
    const std::unique_ptr<Model> wrapped = withColoredNoise(std::make_unique<PlanarRigidBody>(p), gm);
    const Model& model = *wrapped;
    ASSERT_EQ(model.numChannels(), 24);
    ASSERT_EQ(model.dims().nb, 24 + (scale ? 1 : 0) + antenna);
    ASSERT_EQ(model.dims().nc, errors ? 30 : 6);
    gssm::testing::expectJacobiansMatchDifferences(model, [&](std::mt19937& rng) {
      gssm::testing::JacobianPoint pt;
      pt.xc = gssm::testing::uniformVector(rng, model.dims().nc, -2, 2);
      if (errors) pt.xc.tail(24) *= 0.05;
      std::uniform_real_distribution<double> yaw(-M_PI, M_PI);
      pt.xc[2] = std::uniform_int_distribution<int>(0, 1)(rng) ? yaw(rng) : M_PI - 1e-4;  // near the cut too
      pt.xb = gssm::testing::uniformVector(rng, model.dims().nb, -0.3, 0.3);
      if (scale) pt.xb[24] = 1.02;
      if (antenna) pt.xb.tail(antenna) *= 0.2;
      pt.u = Eigen::VectorXd(0);
      pt.dt = 0.013;
      return pt;
    });
  }
}

TEST(PlanarRigidBody, BiasOfALinkIsOnlyInThatLinksFactors) {
  const PlanarRigidBody model(uwbLayout());
  const Eigen::VectorXd xc = (Eigen::VectorXd(6) << 0.5, -0.3, 0.4, 0.2, 0.1, 0.05).finished();
  Eigen::VectorXd xb = Eigen::VectorXd::Zero(24);
  const int c = model.channelOf(2, 5);
  EXPECT_EQ(model.channel(c).name, "range_2_5");
  EXPECT_EQ(model.stackedStateNames()[6 + static_cast<std::size_t>(model.biasIndex(c))], "bias_2_5");
  Eigen::MatrixXd J_xc, J_xb;
  const double r0 = model.h(c, xc, xb, &J_xc, &J_xb)[0];
  EXPECT_EQ(J_xb.cwiseAbs().sum(), 1.0);
  EXPECT_EQ(J_xb(0, model.biasIndex(c)), 1.0);
  xb[model.biasIndex(c)] = 0.25;
  EXPECT_NEAR(model.h(c, xc, xb)[0], r0 + 0.25, 1e-15);
  EXPECT_EQ(model.h(model.channelOf(0, 0), xc, xb)[0], model.h(model.channelOf(0, 0), xc, Eigen::VectorXd::Zero(24))[0]);
}

TEST(PlanarRigidBody, RoundTripsThroughItsIniForm) {
  PlanarRigidBody::Params p = uwbLayout();
  p.range_sd = 0.05;
  p.range_scale = true;
  p.bias_common_sd = 0.4;
  p.antenna_harmonics = 2;
  p.antenna_sd = 0.02;
  const PlanarRigidBody model(p);
  io::IniDocument ini;
  io::writeModel(model, ini);
  const auto again = io::makeModel(io::IniDocument::parse(ini.toString(), "uwb.ini"));
  const auto& q = dynamic_cast<const PlanarRigidBody&>(*again).params();
  EXPECT_EQ(q.anchors, p.anchors);
  EXPECT_EQ(q.tags, p.tags);
  EXPECT_EQ(again->stackedStateNames(), model.stackedStateNames());
  EXPECT_EQ(again->noise().Q, model.noise().Q);
  EXPECT_EQ(again->priorConstants().covariance, model.priorConstants().covariance);
  EXPECT_EQ(q.bias_common_sd, 0.4);
  EXPECT_EQ(q.antenna_harmonics, 2);
  EXPECT_EQ(q.antenna_sd, 0.02);
}

// g_i(β) = a cos 2β + b sin 2β of tag i, β the anchor's bearing in the body
// frame seen from the tag: checked against that bearing computed here from
// the geometry, on every link of tag 1; the other tags' ranges unchanged.
TEST(PlanarRigidBody, AntennaDelayIsTheTagsHarmonicsOfTheAnchorsBodyFrameBearing) {
  PlanarRigidBody::Params p = uwbLayout();
  p.antenna_harmonics = 2;
  const PlanarRigidBody model(p);
  ASSERT_EQ(model.dims().nb, 24 + 6);
  EXPECT_EQ(model.stackedStateNames()[6 + 24 + 2], "antenna_1_c2");
  const Eigen::VectorXd xc = (Eigen::VectorXd(6) << 0.5, -0.3, 2.4, 0.2, 0.1, 0.05).finished();
  Eigen::VectorXd xb = Eigen::VectorXd::Zero(30);
  xb[26] = 0.04, xb[27] = -0.03;  // tag 1: a, b
  const Eigen::Rotation2Dd R(xc[2]);
  for (std::size_t a = 0; a < p.anchors.size(); ++a) {
    const Eigen::Vector2d tag = xc.head<2>() + R * p.tags[1].head<2>();
    const Eigen::Vector2d body = R.inverse() * (p.anchors[a].head<2>() - tag);
    const double beta = std::atan2(body.y(), body.x());
    const int c = model.channelOf(1, a);
    EXPECT_NEAR(model.h(c, xc, xb)[0] - model.h(c, xc, Eigen::VectorXd::Zero(30))[0],
                0.04 * std::cos(2 * beta) - 0.03 * std::sin(2 * beta), 1e-14);
    const int other = model.channelOf(0, a);
    EXPECT_EQ(model.h(other, xc, xb)[0], model.h(other, xc, Eigen::VectorXd::Zero(30))[0]);
  }
  p.antenna_harmonics = 9;
  EXPECT_THROW(PlanarRigidBody{p}, gssm::InvalidArgument);
}

// A link's Gauss–Markov range error (the general mechanism,
// test_colored_noise.cpp) adds to its own link's range only.
TEST(PlanarRigidBody, ColoredNoiseIsPerLink) {
  ColoredNoise gm;
  gm.channels = {"all"}, gm.tau = 0.3, gm.sd = 0.05;
  const std::unique_ptr<Model> model = withColoredNoise(std::make_unique<PlanarRigidBody>(uwbLayout()), gm);
  const auto& body = dynamic_cast<const PlanarRigidBody&>(withoutColoredNoise(*model));
  EXPECT_EQ(model->names().state[6], "err_range_0_0");
  EXPECT_EQ(model->names().state[29], "err_range_2_7");
  Eigen::VectorXd xc = Eigen::VectorXd::Zero(30), xb = Eigen::VectorXd::Zero(24);
  xc.head<3>() << 0.5, -0.3, 0.4;
  const int c = body.channelOf(1, 3);
  const double r0 = model->h(c, xc, xb)[0];
  xc[6 + c] = 0.02;
  EXPECT_NEAR(model->h(c, xc, xb)[0], r0 + 0.02, 1e-15);
  Eigen::VectorXd no_errors = xc;
  no_errors.tail(24).setZero();
  EXPECT_EQ(model->h(body.channelOf(0, 0), xc, xb)[0], model->h(body.channelOf(0, 0), no_errors, xb)[0]);
  io::IniDocument ini;
  io::writeModel(*model, ini);
  const auto again = io::makeModel(io::IniDocument::parse(ini.toString(), "uwb.ini"));
  EXPECT_EQ(again->dims().nc, 30);
  EXPECT_EQ(again->noise().Q, model->noise().Q);
}

// b_ij = c + d_ij marginalized: bias_sd²·I + bias_common_sd²·11ᵀ on the
// biases, the range scale's prior untouched.
TEST(PlanarRigidBody, CommonBiasPartIsInThePriorCovariance) {
  PlanarRigidBody::Params p = uwbLayout();
  p.bias_sd = 0.06;
  p.bias_common_sd = 0.5;
  p.range_scale = true;
  p.range_scale_sd = 0.02;
  const Eigen::MatrixXd P = PlanarRigidBody(p).priorConstants().covariance;
  ASSERT_EQ(P.rows(), 25);
  for (int i = 0; i < 25; ++i)
    for (int j = 0; j < 25; ++j) {
      const double expected = i == 24 || j == 24 ? (i == j ? 0.02 * 0.02 : 0.0) : 0.25 + (i == j ? 0.0036 : 0.0);
      EXPECT_NEAR(P(i, j), expected, 1e-15) << i << ", " << j;
    }
  p.bias_common_sd = -0.1;
  EXPECT_THROW(PlanarRigidBody{p}, gssm::InvalidArgument);
}

namespace {
// The uwb-fast layout simulated: a slow random walk, the links measured in
// turn (each 50 times), white range noise, biases drawn from the prior.
SimulatedRun layoutRun(const PlanarRigidBody& model, unsigned seed, int steps) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  SimulationSpec spec;
  spec.steps = steps;
  spec.x0 = (Eigen::VectorXd(6) << 0.3, -0.2, 0.5, 0.2, 0.1, 0.05).finished();
  spec.channels.clear();
  for (int c = 0; c < model.numChannels(); ++c) spec.channels.push_back(c);
  return simulate(model, spec, [&] { return n01(rng); });
}

PlanarRigidBody::Params simulatedLayout() {
  PlanarRigidBody::Params p = uwbLayout();
  p.accel_sd = 0.3;
  p.yaw_accel_sd = 0.3;
  p.range_sd = 0.03;
  p.start << 0.3, -0.2, 0.5;  // the prior mean at the truth's start, sds as in the scenario
  return p;
}
}  // namespace

// Every exact method, with the prior of the shipped scenario (the links'
// own parts σ 0.06 about a part they share, σ 1 m; the biases drawn from
// it). Measured: EKF 435, fixed lag 470, incremental 471, batch 470 of 480
// within 2σ. With independent σ = 0.3 priors instead (no common part) the
// filters were overconfident (EKF 374, fixed lag 353 of 480): at the start
// (few links seen, the pose unknown) pose and biases trade off, and the
// information they marginalized there came from linearizations at poses
// they no longer revisit, as in EKF-SLAM. The paper window's diagonal
// re-priors drop the biases' correlations: 46 of 480 (not tested here).
TEST(PlanarRigidBody, EveryMethodRecoversTheLinkBiasesWithinTwoSigmaOverSeeds) {
  PlanarRigidBody::Params p = simulatedLayout();
  p.bias_sd = 0.06;
  p.bias_common_sd = 1.0;
  const PlanarRigidBody model(p);
  for (Method method : {Method::Ekf, Method::FixedLag, Method::Incremental, Method::Batch}) {
    int inside = 0, total = 0;
    for (unsigned seed = 1; seed <= 20; ++seed) {
      const SimulatedRun run = layoutRun(model, seed, 1200);
      EstimatorOptions o(method);
      o.incremental.ordering = EliminationOrdering::TimeOrdered;
      const OfflineRun r = runOffline(model, o, run.measurements);
      const EstimateRow& last = r.rows.back();
      for (int b = 0; b < 24; ++b, ++total) {
        const double err = last.mean[6 + b] - run.constants[b];
        inside += std::abs(err) <= 2 * std::sqrt(last.covariance(6 + b, 6 + b)) ? 1 : 0;
      }
    }
    std::printf("%s: %d of %d biases within 2σ\n", methodName(method), inside, total);
    // 2σ holds ~95% of the time for a consistent estimator.
    EXPECT_GE(inside, 0.9 * total) << methodName(method) << ": " << inside << " of " << total << " biases within 2σ";
  }
}

// The antennas' bearing-dependent delays (harmonics 2 and 3, drawn from
// their prior like the biases) are recovered by the batch within 2σ.
TEST(PlanarRigidBody, AntennaHarmonicsAreRecoveredWithinTwoSigmaOverSeeds) {
  PlanarRigidBody::Params p = simulatedLayout();
  p.bias_sd = 0.06;
  p.bias_common_sd = 1.0;
  p.antenna_harmonics = 3;
  p.antenna_sd = 0.03;
  const PlanarRigidBody model(p);
  int inside = 0, total = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const SimulatedRun run = layoutRun(model, seed, 1200);
    const OfflineRun r = runOffline(model, EstimatorOptions(Method::Batch), run.measurements);
    const EstimateRow& last = r.rows.back();
    for (int i = 24; i < 36; ++i, ++total) {
      const double err = last.mean[6 + i] - run.constants[i];
      inside += std::abs(err) <= 2 * std::sqrt(last.covariance(6 + i, 6 + i)) ? 1 : 0;
    }
  }
  std::printf("batch: %d of %d antenna coefficients within 2σ\n", inside, total);
  EXPECT_GE(inside, 0.9 * total);
}

TEST(PlanarRigidBody, IncrementalSmootherEqualsTheBatchOnTheLayout) {
  const PlanarRigidBody model(simulatedLayout());
  const SimulatedRun run = layoutRun(model, 7, 192);  // each link 8 times
  EstimatorOptions inc(Method::Incremental);
  inc.smoother.iterate_to_convergence = true;
  inc.smoother.convergence_tolerance = 1e-12;
  EstimatorOptions batch(Method::Batch);
  batch.batch.relative_cost_tolerance = 0;
  batch.batch.gradient_tolerance = 0;
  batch.batch.step_tolerance = 1e-13;
  const OfflineRun a = runOffline(model, inc, run.measurements), b = runOffline(model, batch, run.measurements);
  const Eigen::VectorXd& x = a.rows.back().mean;
  const Eigen::VectorXd& y = b.rows.back().mean;
  EXPECT_LT((x - y).cwiseAbs().maxCoeff(), 1e-6 * (1 + y.cwiseAbs().maxCoeff())) << (x - y).transpose();
  EXPECT_LT((a.rows.back().covariance - b.rows.back().covariance).cwiseAbs().maxCoeff(), 1e-8);
}

// EM for the links' spread (bias_sd, about a common part): the learnt σ is a
// stationary point of the expected log prior at the batch posterior of x_b
// computed here independently (dQ/dσ² = ½ tr(Σ⁻¹SΣ⁻¹) − ½ tr(Σ⁻¹) = 0 with
// S = P + m mᵀ), and it recovers the spread the biases were drawn with.
// EM's E-steps share one graph: the priors re-made from a model that
// differs in its constants' prior alone must give the graph that model
// builds (the same cost and gradient everywhere), its start included.
TEST(PlanarRigidBody, ReplacedPriorsGiveTheGraphOfTheModelWithThosePriors) {
  PlanarRigidBody::Params a = simulatedLayout(), b = a;
  a.bias_sd = 0.3;
  b.bias_sd = 0.05;
  const PlanarRigidBody model_a(a), model_b(b);
  const SimulatedRun run = layoutRun(model_a, 5, 72);
  const Problem original = buildProblem(model_a, run.measurements);
  Problem replaced = buildProblem(model_a, run.measurements);
  replacePriors(replaced, model_b);
  const Problem built = buildProblem(model_b, run.measurements);
  ASSERT_EQ(replaced.graph.size(), built.graph.size());
  EXPECT_TRUE(replaced.initial.at(Key::constants()).isApprox(built.initial.at(Key::constants()), 0));
  std::mt19937 rng(6);
  std::normal_distribution<double> n01;
  for (int trial = 0; trial < 3; ++trial) {
    Values x = built.initial;
    for (auto& [key, v] : x) v += 0.1 * Eigen::VectorXd::NullaryExpr(v.size(), [&] { return n01(rng); });
    EXPECT_DOUBLE_EQ(replaced.graph.cost(x), built.graph.cost(x));
    EXPECT_GT(std::abs(original.graph.cost(x) - built.graph.cost(x)), 1.0);  // the priors do differ
    for (std::size_t i = 0; i < built.graph.size(); ++i) {
      Eigen::VectorXd r1, r2;
      built.graph[i]->linearize(x, r1, nullptr);
      replaced.graph[i]->linearize(x, r2, nullptr);
      ASSERT_TRUE(r1.isApprox(r2, 1e-14)) << "factor " << i;
    }
  }
}

TEST(PlanarRigidBody, LinkBiasSpreadLearntByEmIsAStationaryPointOfTheExpectedLogPrior) {
  PlanarRigidBody::Params truth = simulatedLayout();
  truth.bias_sd = 0.06;
  truth.bias_common_sd = 0.2;
  const SimulatedRun run = layoutRun(PlanarRigidBody(truth), 11, 960);  // each link 40 times
  PlanarRigidBody::Params start = truth;
  start.bias_sd = 0.3;
  NoiseLearningOptions o;
  o.parameters = {"bias_sd"};
  const NoiseLearningReport r = learnNoise(PlanarRigidBody(start), run.measurements, {}, 0.0, o);
  ASSERT_EQ(r.parameters.size(), 1u);
  EXPECT_EQ(r.parameters[0].method, "em");
  EXPECT_TRUE(r.prior_converged);
  EXPECT_EQ(r.evaluations, 0);  // no likelihood stage: only the prior was asked for
  const double s = r.parameters[0].value;
  PlanarRigidBody::Params given = start;
  given.bias_sd = s;
  const OfflineRun batch = runOffline(PlanarRigidBody(given), EstimatorOptions(Method::Batch), run.measurements);
  // Learning's last E-step starts the learnt model's batch nearly converged:
  // the MAP the EKF's start reaches, in fewer iterations.
  ASSERT_FALSE(r.posterior.empty());
  const OfflineRun warm = runBatch(PlanarRigidBody(given), EstimatorOptions(Method::Batch), run.measurements, {},
                                   RowTimes::Measurements, &r.posterior);
  ASSERT_EQ(warm.rows.size(), batch.rows.size());
  for (std::size_t i = 0; i < warm.rows.size(); ++i) {
    ASSERT_LT((warm.rows[i].mean - batch.rows[i].mean).cwiseAbs().maxCoeff(), 1e-6) << "row " << i;
    ASSERT_LT((warm.rows[i].covariance - batch.rows[i].covariance).cwiseAbs().maxCoeff(), 1e-8) << "row " << i;
  }
  EXPECT_LT(warm.iterations, batch.iterations);
  Values other = r.posterior;
  other.erase(Key::state(3));
  EXPECT_THROW(
      {
        try {
          runBatch(PlanarRigidBody(given), EstimatorOptions(Method::Batch), run.measurements, {}, RowTimes::Measurements, &other);
        } catch (const InvalidArgument& e) {
          EXPECT_NE(std::string(e.what()).find("is not of this run"), std::string::npos) << e.what();
          throw;
        }
      },
      InvalidArgument);
  const Eigen::VectorXd m = batch.rows.back().mean.tail(24);
  const Eigen::MatrixXd P = batch.rows.back().covariance.bottomRightCorner(24, 24);
  const Eigen::MatrixXd Sigma = PlanarRigidBody(given).priorConstants().covariance;
  const Eigen::MatrixXd Si = Sigma.inverse(), S = P + m * m.transpose();
  const double gradient = 0.5 * (Si * S * Si).trace() - 0.5 * Si.trace();
  EXPECT_LT(std::abs(gradient), 1e-3 * Si.trace()) << "σ = " << s;
  // The spread of the drawn biases about their mean (what 24 draws show).
  const Eigen::VectorXd b = run.constants;
  const double spread = std::sqrt((b.array() - b.mean()).square().sum() / 23.0);
  std::printf("bias_sd learnt %g ± %g in %d E-steps (drawn with %g, the 24 draws' spread %g), dQ/dσ² %g\n", s,
              r.parameters[0].standard_error, r.prior_iterations, truth.bias_sd, spread, gradient);
  EXPECT_NEAR(s, spread, 0.15 * spread);
  EXPECT_LT(std::abs(s - truth.bias_sd), 3 * r.parameters[0].standard_error)
      << s << " ± " << r.parameters[0].standard_error << ", drawn with " << truth.bias_sd;
  // EM's standard error comes from the expected log prior, not from filter
  // passes: given without the likelihood's curvature too, the same.
  o.standard_errors = false;
  const NoiseLearningReport quick = learnNoise(PlanarRigidBody(start), run.measurements, {}, 0.0, o);
  ASSERT_EQ(quick.parameters.size(), 1u);
  EXPECT_GT(r.parameters[0].standard_error, 0.0);
  EXPECT_EQ(quick.parameters[0].value, r.parameters[0].value);
  EXPECT_EQ(quick.parameters[0].standard_error, r.parameters[0].standard_error);
}

// The simulated layout started away from the truth: the constants move a lot.
PlanarRigidBody::Params startAwayFromTheTruth() {
  PlanarRigidBody::Params p = simulatedLayout();
  p.start << 0, 0, 0;
  p.position_sd = 2;
  return p;
}

EstimatorOptions incrementalByTime(double full_pass_growth, int full_pass_rounds) {
  EstimatorOptions o(Method::Incremental);
  o.incremental.ordering = EliminationOrdering::TimeOrdered;
  o.smoother.full_pass_growth = full_pass_growth;
  o.smoother.full_pass_rounds = full_pass_rounds;
  return o;
}

// SmootherOptions::full_pass_growth = 2: full relinearization passes only
// once the history doubled since the last (here every pass re-eliminates
// the chain from an old factor up, O(n)): at most log2(n) + 2 of them, fewer
// than with growth 1, the final biases within a tenth of their σ of the
// batch's; the schedule is checkpointed (a resumed run equals the
// uninterrupted one bit for bit).
TEST(PlanarRigidBody, FullPassGrowthBoundsThePassesAndResumesExactly) {
  const PlanarRigidBody model(startAwayFromTheTruth());
  const SimulatedRun run = layoutRun(model, 5, 1200);
  auto passes = [&](double growth, std::unique_ptr<Estimator>* resumed) {
    auto est = makeEstimator(model, incrementalByTime(growth, 1));
    int count = 0;
    for (std::size_t i = 0; i < run.measurements.size(); ++i) {
      est->addMeasurement(run.measurements[i]);
      count += est->report().smoother.relinearization_pass ? 1 : 0;
      if (resumed && i == 500) *resumed = restoreCheckpointBytes(model, checkpointBytes(*est));
      if (resumed && i > 500) (*resumed)->addMeasurement(run.measurements[i]);
    }
    return std::pair{count, est->current()};
  };
  std::unique_ptr<Estimator> resumed;
  const auto [every, a] = passes(1.0, nullptr);
  const auto [doubling, b] = passes(2.0, &resumed);
  std::printf("full passes over 1200 states: %d with growth 1, %d with growth 2\n", every, doubling);
  EXPECT_LE(doubling, static_cast<int>(std::log2(1200.0)) + 2);
  EXPECT_LT(doubling, every);
  EXPECT_EQ(resumed->current().mean, b.mean);
  EXPECT_EQ(resumed->current().covariance, b.covariance);
  const OfflineRun batch = runOffline(model, EstimatorOptions(Method::Batch), run.measurements);
  const Eigen::VectorXd& x = batch.rows.back().mean;
  for (int i = 6; i < 30; ++i)
    EXPECT_LT(std::abs(b.mean[i] - x[i]), 0.1 * std::sqrt(batch.rows.back().covariance(i, i))) << i;
  EstimatorOptions bad(Method::Incremental);
  bad.smoother.full_pass_growth = 0.5;
  EXPECT_THROW(makeEstimator(model, bad), gssm::InvalidArgument);
}

// SmootherOptions::full_pass_rounds: a full pass relinearizes and
// re-eliminates until no factor is stale (at most that many rounds), not
// once. With the constants moving a lot between rare passes (growth 2),
// right after each pass the newest state and the constants are nearer the
// causal optimum (the batch of the data so far) with more rounds; the
// rounds are checkpointed (a resumed run equals the uninterrupted one bit
// for bit).
TEST(PlanarRigidBody, FullPassRoundsLandNearerTheCausalOptimum) {
  const PlanarRigidBody model(startAwayFromTheTruth());
  const SimulatedRun run = layoutRun(model, 5, 600);
  // The mean over the passes of the largest distance from the batch (its sds).
  auto offOptimum = [&](int rounds, std::unique_ptr<Estimator>* resumed) {
    auto est = makeEstimator(model, incrementalByTime(2.0, rounds));
    double sum = 0;
    int passes = 0;
    for (std::size_t i = 0; i < run.measurements.size(); ++i) {
      est->addMeasurement(run.measurements[i]);
      if (resumed && i == 300) *resumed = restoreCheckpointBytes(model, checkpointBytes(*est));
      if (resumed && i > 300) (*resumed)->addMeasurement(run.measurements[i]);
      if (!est->report().smoother.relinearization_pass) continue;
      const std::vector<Measurement> so_far(run.measurements.begin(), run.measurements.begin() + i + 1);
      const EstimateRow optimum = runOffline(model, EstimatorOptions(Method::Batch), so_far).rows.back();
      const Eigen::VectorXd sd = optimum.covariance.diagonal().cwiseSqrt();
      sum += ((est->current().mean - optimum.mean).cwiseAbs().cwiseQuotient(sd)).maxCoeff(), ++passes;
    }
    if (resumed) {
      EXPECT_EQ((*resumed)->current().mean, est->current().mean);
    }
    EXPECT_GT(passes, 2);
    return sum / std::max(passes, 1);
  };
  std::unique_ptr<Estimator> resumed;
  const double one = offOptimum(1, nullptr), three = offOptimum(3, &resumed);
  std::printf("after a full pass, from the causal optimum (its sds, mean over passes): %.3g with one round, %.3g "
              "with three\n", one, three);
  EXPECT_LT(three, one);
  EstimatorOptions bad(Method::Incremental);
  bad.smoother.full_pass_rounds = 0;
  EXPECT_THROW(makeEstimator(model, bad), gssm::InvalidArgument);
}

// With a range scale s, a bias-only calibration constant is the range error
// at the link's mean true distance d̄: b + (s − 1)·d̄ (d̄ computed here from
// the geometry), its variance σ_b² + d̄²σ_s² + 2d̄·cov(b, s); the scale
// itself unchanged. Without a scale the constants are compared as they are.
TEST(PlanarRigidBody, ConstantsComparedWithACalibrationAtTheLinksMeanDistance) {
  PlanarRigidBody::Params p = uwbLayout();
  p.range_scale = true;
  const PlanarRigidBody model(p);
  Truth truth;
  truth.components = {0, 1, 2};
  truth.states = {Eigen::Vector3d(0.5, -0.3, 0.4), Eigen::Vector3d(-1.0, 1.2, -2.0)};
  Gaussian xb;
  xb.mean = Eigen::VectorXd::LinSpaced(25, 0.1, 0.3);
  xb.mean[24] = 1.02;
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(25, 25) * 0.01;
  xb.covariance = A * A.transpose() + 1e-6 * Eigen::MatrixXd::Identity(25, 25);
  const Gaussian c = model.comparableConstants(xb, truth);
  const int link = model.channelOf(2, 5);
  double d = 0;
  for (const auto& x : truth.states) {
    const double yaw = x[2];
    const Eigen::Vector3d l = p.tags[2], a = p.anchors[5];
    const double tx = x[0] + std::cos(yaw) * l.x() - std::sin(yaw) * l.y(), ty = x[1] + std::sin(yaw) * l.x() + std::cos(yaw) * l.y();
    d += std::sqrt(std::pow(tx - a.x(), 2) + std::pow(ty - a.y(), 2) + std::pow(p.height + l.z() - a.z(), 2)) / 2;
  }
  const int b = model.biasIndex(link);
  EXPECT_NEAR(c.mean[b], xb.mean[b] + 0.02 * d, 1e-12);
  EXPECT_EQ(c.mean[24], 1.02);
  const double var = xb.covariance(b, b) + d * d * xb.covariance(24, 24) + 2 * d * xb.covariance(b, 24);
  EXPECT_NEAR(c.covariance(b, b), var, 1e-12);
  p.range_scale = false;
  const PlanarRigidBody plain(p);
  Gaussian xb24{xb.mean.head(24), xb.covariance.topLeftCorner(24, 24)};
  EXPECT_EQ(plain.comparableConstants(xb24, truth).mean, xb24.mean);
}
