// Rotation blocks in the state (docs/DESIGN.md §12), against independent
// references: central differences on the manifold (⊕/⊖) for every analytic
// Jacobian, the truth a simulation was drawn with, and the batch solve of
// the same graph for the incremental smoother, the fixed lag and the EKF.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "attitude_model.h"
#include "gssm/analysis/offline.h"
#include "gssm/core/rotation_blocks.h"
#include "gssm/core/so3.h"
#include "gssm/factors/problem.h"
#include "gssm/model/simulation.h"
#include "gssm/solvers/batch_solver.h"
#include "jacobian_check.h"
#include "reference_kalman.h"

namespace gssm {
namespace {

using testing::AttitudeModel;

AttitudeModel attitude() { return AttitudeModel(0.05, 0.01, 0.05, 0.02, 0.3); }

// Tiny, gimbal-lock pitch, yaw near ±π, |φ| near π, and a generic one.
std::vector<Eigen::Vector3d> attitudeVectors() {
  return {Eigen::Vector3d(1e-9, -2e-9, 0.0),
          so3::Log(so3::fromRollPitchYaw(Eigen::Vector3d(0.3, M_PI / 2, 1.0))),
          so3::Log(so3::fromRollPitchYaw(Eigen::Vector3d(0.1, -0.2, M_PI - 1e-6))),
          so3::Log(so3::fromRollPitchYaw(Eigen::Vector3d(0.0, 0.0, -M_PI + 1e-6))),
          Eigen::Vector3d(0.0, 0.0, M_PI - 1e-7),
          Eigen::Vector3d(1.2, -0.8, 0.5)};
}

double rotationDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return so3::minus(so3::Exp(a), so3::Exp(b)).norm();
}

TEST(RotationStates, RetractionAndLocalRoundTrip) {
  const std::vector<int> blocks{1};  // [a, φ, b]
  std::mt19937 rng(7);
  for (const Eigen::Vector3d& phi : attitudeVectors())
    for (double size : {1e-9, 0.3, 2.5}) {
      Eigen::VectorXd x(5), d = testing::uniformVector(rng, 5, -1, 1);
      x << 0.5, phi, -2.0;
      d.segment<3>(1) *= size / d.segment<3>(1).norm();
      Eigen::VectorXd y = x, back;
      retractBlocks(y, d, blocks);
      localBlocks(y, x, back, blocks);
      EXPECT_LT((back - d).cwiseAbs().maxCoeff(), 1e-9) << "φ " << phi.transpose() << ", |δ| " << size;
      EXPECT_LE(y.segment<3>(1).norm(), M_PI + 1e-12);
      Eigen::VectorXd z = x;  // x ⊕ (y ⊖ x) = y, as rotations
      retractBlocks(z, back, blocks);
      EXPECT_LT(rotationDistance(z.segment<3>(1), y.segment<3>(1)), 1e-9);
      EXPECT_NEAR(z[0], y[0], 1e-15);
    }
}

TEST(RotationStates, ModelJacobiansMatchTangentDifferences) {
  const AttitudeModel m = attitude();
  const std::vector<Eigen::Vector3d> at = attitudeVectors();
  testing::expectJacobiansMatchDifferences(m, [&](std::mt19937& rng) {
    testing::JacobianPoint p;
    p.xc = at[std::uniform_int_distribution<std::size_t>(0, at.size() - 1)(rng)];
    p.xb = testing::uniformVector(rng, 3, -0.05, 0.05);
    p.u = testing::uniformVector(rng, 3, -2, 2);
    p.dt = 0.05;
    return p;
  }, 30);
}

// The factors' Jacobians are with respect to each variable's tangent:
// ∂r(x ⊕ δ)/∂δ by central differences, at every listed attitude.
void expectFactorJacobians(const Factor& f, const Values& x, const Model& m) {
  Eigen::VectorXd r0, rp, rm;
  std::vector<Eigen::MatrixXd> J;
  f.linearize(x, r0, &J);
  for (std::size_t a = 0; a < f.keys().size(); ++a) {
    const Key k = f.keys()[a];
    const int offset = k.isConstants() ? m.dims().nc : 0;
    const Eigen::Index n = x.at(k).size();
    for (Eigen::Index j = 0; j < n; ++j) {
      const double h = 1e-6;
      Values xp = x, xm = x;
      Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
      d[j] = h;
      retractBlocks(xp.at(k), d, m.rotationBlocks(), offset);
      retractBlocks(xm.at(k), -d, m.rotationBlocks(), offset);
      f.linearize(xp, rp, nullptr);
      f.linearize(xm, rm, nullptr);
      const Eigen::VectorXd numeric = (rp - rm) / (2 * h);
      EXPECT_LT((J[a].col(j) - numeric).cwiseAbs().maxCoeff(), 1e-6 * (1 + numeric.cwiseAbs().maxCoeff()))
          << f.describe() << ": column " << j << " of " << k.toString() << " at " << x.at(Key::state(0)).transpose();
    }
  }
}

TEST(RotationStates, ProcessAndPriorFactorJacobiansMatchTangentDifferences) {
  const AttitudeModel m = attitude();
  const Eigen::Vector3d u(0.4, -1.1, 2.0), b(0.01, -0.02, 0.03);
  for (const Eigen::Vector3d& phi : attitudeVectors()) {
    Values x;
    x.insert(Key::state(0), phi);
    Eigen::VectorXd next = m.f(phi, b, u, 0.05);
    retractBlocks(next, Eigen::Vector3d(0.02, -0.01, 0.03), m.rotationBlocks());  // off the prediction
    x.insert(Key::state(1), next);
    x.insert(Key::constants(), b);
    expectFactorJacobians(ProcessFactor(m, 0, u, 0.05), x, m);
    expectFactorJacobians(PriorFactor(Key::state(0), {Eigen::Vector3d(0.2, 0.1, -3.0), Eigen::Matrix3d::Identity()},
                                      {}, m.rotationBlocks()),
                          x, m);
    expectFactorJacobians(MeasurementFactor(m, 1, Measurement{0.05, Eigen::Vector3d(1, 0, 0), 1, {}}), x, m);
  }
}

struct Spin {
  SimulatedRun run;
  OfflineRun batch;
};

// A body yawing at 1 rad/s (20 s: three turns through ±π) with roll and
// pitch wobbling, its gyro biased, gravity and north measured in turn.
Spin spin(const Model& m, unsigned seed, int steps = 400) {
  SimulationSpec spec;
  spec.steps = steps;
  spec.channels = {0, 1};
  spec.input = [](double t, const Eigen::VectorXd& bias) -> Eigen::VectorXd {
    return Eigen::Vector3d(0.3 * std::sin(t), 0.2 * std::cos(0.7 * t), 1.0) + bias;
  };
  Spin s;
  s.run = simulate(m, spec, testing::normalSampler(seed));
  s.batch = runOffline(m, {Method::Batch}, s.run.measurements, s.run.inputs);
  return s;
}

// Stacked [φ; b] estimates compared as rotations and vectors.
double stackedDistance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return std::max(rotationDistance(a.head<3>(), b.head<3>()), (a.tail<3>() - b.tail<3>()).cwiseAbs().maxCoeff());
}

TEST(RotationStates, BatchAndEkfHoldTheTruth) {
  const AttitudeModel m = attitude();
  int inside = 0, total = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Spin s = spin(m, seed);
    const EstimateRow& end = s.batch.rows.back();
    Eigen::VectorXd err;
    Eigen::VectorXd truth(6);
    truth << s.run.states.back(), s.run.constants;
    localBlocks(end.mean, truth, err, m.rotationBlocks());
    for (int i = 0; i < 6; ++i, ++total) {
      const bool ok = std::abs(err[i]) <= 3 * std::sqrt(end.covariance(i, i));
      inside += ok;
      if (!ok) std::cout << "batch seed " << seed << " component " << i << ": " << err[i] << " vs σ " << std::sqrt(end.covariance(i, i)) << "\n";
    }
    // The EKF linearizes once per measurement (from a 0.3 rad start): its
    // end is its own, judged against the truth by its own covariance.
    const OfflineRun ekf_run = runOffline(m, {Method::Ekf}, s.run.measurements, s.run.inputs);
    const EstimateRow& ekf = ekf_run.rows.back();
    localBlocks(ekf.mean, truth, err, m.rotationBlocks());
    for (int i = 0; i < 6; ++i, ++total) {
      const bool ok = std::abs(err[i]) <= 3 * std::sqrt(ekf.covariance(i, i));
      inside += ok;
      if (!ok) std::cout << "EKF seed " << seed << " component " << i << ": " << err[i] << " vs σ " << std::sqrt(ekf.covariance(i, i)) << "\n";
    }
  }
  EXPECT_GE(inside, 0.95 * total) << inside << " of " << total << " within 3σ of the truth";
}

// 10 s (a turn and a half through ±π), every update iterated to the
// batch's fixed point (not iSAM2's relinearization threshold).
TEST(RotationStates, SmoothersEndAtTheBatch) {
  const AttitudeModel m = attitude();
  const Spin s = spin(m, 1, 200);
  const EstimateRow& end = s.batch.rows.back();
  for (Method method : {Method::Incremental, Method::FixedLag}) {
    EstimatorOptions o(method);
    o.fixed_lag.window = 1000;  // the whole run: the exact marginal is the batch's
    o.smoother.iterate_to_convergence = true;
    o.smoother.convergence_tolerance = 1e-12;
    const OfflineRun r = runOffline(m, o, s.run.measurements, s.run.inputs);
    EXPECT_LT(stackedDistance(r.rows.back().mean, end.mean), 1e-6) << methodName(method);
    EXPECT_LT((r.rows.back().covariance - end.covariance).cwiseAbs().maxCoeff(), 1e-6 * end.covariance.norm())
        << methodName(method);
  }
}

// The batch's answer is a minimum on the manifold: the cost along every
// tangent direction of a state, by central differences, is flat there.
TEST(RotationStates, BatchSolutionIsAMinimumAlongEveryTangent) {
  const AttitudeModel m = attitude();
  const Spin s = spin(m, 3);
  Problem p = buildProblem(m, s.run.measurements, s.run.inputs);
  BatchSolver solver;
  ASSERT_TRUE(solver.solve(p.graph, p.initial).converged);
  for (std::int64_t k : {std::int64_t(0), std::int64_t(137), std::int64_t(400)}) {
    for (int j = 0; j < 3; ++j) {
      const double h = 1e-4;
      Eigen::VectorXd d = Eigen::VectorXd::Zero(3);
      d[j] = h;
      Values xp = p.initial, xm = p.initial;
      retractBlocks(xp.at(Key::state(k)), d, m.rotationBlocks());
      retractBlocks(xm.at(Key::state(k)), -d, m.rotationBlocks());
      const double c0 = p.graph.cost(p.initial), cp = p.graph.cost(xp), cm = p.graph.cost(xm);
      const double slope = (cp - cm) / (2 * h), curvature = (cp - 2 * c0 + cm) / (h * h);
      ASSERT_GT(curvature, 0) << "state " << k;
      EXPECT_LT(std::abs(slope / curvature), 1e-5) << "state " << k << " direction " << j;  // the minimum's offset
    }
  }
}

}  // namespace
}  // namespace gssm
