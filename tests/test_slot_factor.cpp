// A factor slot of the Bayes tree holds a model's process and measurement
// factors as their numbers: evaluated that way they give the very same
// residual, Jacobians and cost as the factor objects they were made from
// (bit for bit: the engine's estimates must not change with how it stores
// a factor), and turned back into objects they describe and evaluate the
// same. Models with and without inputs, several channels, a robust loss.
#include <gtest/gtest.h>

#include <random>

#include "gssm/models/radar2d.h"
#include "gssm/models/range_beacon2d.h"
#include "solvers/slot_factor.h"

using namespace gssm;
using gssm::internal::SlotFactor;

namespace {

models::RangeBeacon2D rangeBeacon() {
  models::RangeBeacon2D::Params p;
  p.beacon_ids = {0, 1, 5, 6};
  p.beacons = {{0, 0}, {60, 0}, {60, 60}, {0, 60}};
  p.range_scale = p.range_offsets = p.odometry_scale = true;
  p.range_loss = {RobustLoss::Kind::Huber, 1.345};
  p.start = Eigen::Vector3d(30, 10, 0);
  p.start_sd = Eigen::Vector3d(1, 1, 0.1);
  return models::RangeBeacon2D(p);
}

// The variables of f at a random point, in key order.
std::vector<Eigen::VectorXd> randomPoint(const Model& m, const Factor& f, std::mt19937& rng) {
  std::normal_distribution<double> g;
  std::vector<Eigen::VectorXd> x;
  for (const auto& k : f.keys()) {
    Eigen::VectorXd v(variableDim(m, k));
    for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = (k.isConstants() ? 1.0 : 20.0) + 5 * g(rng);
    x.push_back(v);
  }
  return x;
}

// Held as numbers, f evaluates exactly as itself, and comes back as an
// equal object.
void expectSameEvaluation(const Model& m, const FactorPtr& f, std::mt19937& rng) {
  const SlotFactor held(f, &m);
  ASSERT_TRUE(static_cast<bool>(held));
  EXPECT_EQ(held.dim(&m), f->dim());
  EXPECT_TRUE(held.fitsKeys(&m, f->keys()));
  const std::vector<Key> reversed(f->keys().rbegin(), f->keys().rend());
  if (reversed.size() > 1) {
    EXPECT_FALSE(held.fitsKeys(&m, reversed));  // (the step is the keys': any step fits)
  }
  EXPECT_FALSE(held.fitsKeys(&m, std::vector<Key>(f->keys().begin(), f->keys().end() - 1)));
  const FactorPtr back = held.toFactor(&m, f->keys());
  EXPECT_EQ(back->describe(), f->describe());
  EXPECT_EQ(back->keys(), f->keys());
  for (int trial = 0; trial < 4; ++trial) {
    const std::vector<Eigen::VectorXd> x = randomPoint(m, *f, rng);
    std::vector<const Eigen::VectorXd*> at;
    for (const auto& v : x) at.push_back(&v);
    Eigen::VectorXd r_object, r_held, r_back;
    std::vector<Eigen::MatrixXd> J_object, J_held, J_back;
    const double cost_object = f->linearizeRobustAt(at.data(), r_object, &J_object);
    const double cost_held = held.linearizeRobustAt(&m, at.data(), r_held, &J_held);
    const double cost_back = back->linearizeRobustAt(at.data(), r_back, &J_back);
    EXPECT_EQ(cost_held, cost_object) << f->describe();
    EXPECT_EQ(cost_back, cost_object);
    EXPECT_TRUE(r_held == r_object) << f->describe();
    EXPECT_TRUE(r_back == r_object);
    ASSERT_EQ(J_held.size(), J_object.size());
    for (std::size_t i = 0; i < J_object.size(); ++i) {
      EXPECT_TRUE(J_held[i] == J_object[i]) << f->describe() << " block " << i;
      EXPECT_TRUE(J_back[i] == J_object[i]);
    }
    Eigen::VectorXd r_only;
    EXPECT_EQ(held.linearizeRobustAt(&m, at.data(), r_only, nullptr), cost_object);
    EXPECT_TRUE(r_only == r_object);
  }
}

}  // namespace

TEST(SlotFactor, RadarFactorsHeldAsNumbersEvaluateBitForBitAsTheObjects) {
  const models::Radar2D radar;
  std::mt19937 rng(11);
  for (std::int64_t k : {0, 7, 123456}) {
    expectSameEvaluation(radar, std::make_shared<ProcessFactor>(radar, k, Eigen::VectorXd(), 0.05), rng);
    expectSameEvaluation(radar, std::make_shared<MeasurementFactor>(radar, k, Eigen::VectorXd::Constant(1, 1003.5)),
                         rng);
  }
}

TEST(SlotFactor, InputsChannelsRobustLossAndExplicitNoiseAreKept) {
  const models::RangeBeacon2D m = rangeBeacon();
  std::mt19937 rng(12);
  for (std::int64_t k : {1, 42}) {
    expectSameEvaluation(m, std::make_shared<ProcessFactor>(m, k, Eigen::Vector2d(2.5, 0.3), 0.1), rng);
    for (int c = 0; c < m.numChannels(); ++c) {
      Measurement y;
      y.channel = c;
      y.y = Eigen::VectorXd::Constant(1, 35.0 + c);
      expectSameEvaluation(m, std::make_shared<MeasurementFactor>(m, k, y), rng);
      y.R = Eigen::MatrixXd::Constant(1, 1, 4.0);  // this measurement's own noise
      expectSameEvaluation(m, std::make_shared<MeasurementFactor>(m, k, y), rng);
    }
  }
}

TEST(SlotFactor, OtherFactorsAreKeptAsTheyAre) {
  const models::Radar2D radar;
  const FactorPtr prior = std::make_shared<PriorFactor>(Key::state(3), Gaussian{Eigen::VectorXd::Constant(1, 2.0),
                                                                                Eigen::MatrixXd::Identity(1, 1)});
  const SlotFactor held(prior, &radar);
  EXPECT_EQ(held.toFactor(&radar, prior->keys()), prior);  // the same object
  EXPECT_EQ(SlotFactor::modelOf(prior), nullptr);
  std::mt19937 rng(13);
  expectSameEvaluation(radar, prior, rng);
  EXPECT_FALSE(static_cast<bool>(SlotFactor()));
  EXPECT_FALSE(static_cast<bool>(SlotFactor(FactorPtr(), &radar)));
}

// A slot holds one model's factors as numbers (the engine's, named in every
// call); another model's factor stays an object and evaluates as itself.
TEST(SlotFactor, AnotherModelsFactorIsKeptAsAnObject) {
  const models::Radar2D radar, other;
  const FactorPtr f = std::make_shared<MeasurementFactor>(other, 5, Eigen::VectorXd::Constant(1, 1002.0));
  EXPECT_EQ(SlotFactor::modelOf(f), &other);
  const SlotFactor held(f, &radar);
  EXPECT_EQ(held.toFactor(&radar, f->keys()), f);  // kept as it is, not rebuilt on radar
  EXPECT_EQ(SlotFactor(f, &other).toFactor(&other, f->keys())->describe(), f->describe());
  EXPECT_NE(SlotFactor(f, &other).toFactor(&other, f->keys()), f);  // held as numbers, rebuilt
}
