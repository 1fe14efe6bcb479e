// The model registry (docs/DESIGN.md §3, "Adding a model"): a model defined
// in the test tree through the public registration API (tests/models/drift_1d)
// is read from an INI file, written back, carried through a checkpoint, and
// estimated like a built-in model; the built-in types round-trip through
// their INI form; the registry refuses clashes and names what it knows.
#include <gtest/gtest.h>

#include <random>

#include "gssm/checkpoint/checkpoint.h"
#include "gssm/core/error.h"
#include "gssm/estimator/estimator.h"
#include "gssm/io/config.h"
#include "gssm/model/registry.h"
#include "gssm/model/simulation.h"
#include "gssm/models/linear.h"
#include "models/drift_1d.h"

using namespace gssm;

namespace {

const char* kDriftIni =
    "[model]\ntype = drift_1d\nT = 0.25\nq = 0.04\nr = 0.5\n[prior]\nstart = 3\nstart_sd = 2\ndrift_sd = 0.7\n";

std::vector<Measurement> driftMeasurements(const Model& model, int steps) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  SimulationSpec spec;
  spec.steps = steps;
  return simulate(model, spec, [&] { return n01(rng); }).measurements;
}

// The same system as a LinearModel: x' = drift, y = x + offset.
models::LinearModel driftAsLinear(const gssm::testing::Drift1D& d) {
  models::LinearSystem s;
  s.A_c = Eigen::MatrixXd::Zero(1, 1);
  s.A_b = (Eigen::MatrixXd(1, 2) << 1, 0).finished();
  s.B = Eigen::MatrixXd::Zero(1, 0);
  s.C_c = Eigen::MatrixXd::Ones(1, 1);
  s.C_b = (Eigen::MatrixXd(1, 2) << 0, 1).finished();
  s.noise = d.noise();
  return models::LinearModel(s);
}

StateEstimate finalEstimate(const Model& model, Method method, const std::vector<Measurement>& ms) {
  auto est = makeEstimator(model, EstimatorOptions(method));
  for (const auto& m : ms) est->addMeasurement(m);
  return est->current();
}

}  // namespace

TEST(ModelRegistry, TestTreeModelIsReadFromAnIniFile) {
  const auto model = io::makeModel(io::IniDocument::parse(kDriftIni, "drift.ini"));
  const auto* drift = dynamic_cast<const gssm::testing::Drift1D*>(model.get());
  ASSERT_NE(drift, nullptr);
  EXPECT_EQ(drift->params().T, 0.25);
  EXPECT_EQ(drift->params().q, 0.04);
  EXPECT_EQ(drift->params().start_sd, 2.0);
  EXPECT_EQ(drift->params().offset_sd, gssm::testing::Drift1D::Params{}.offset_sd);  // absent: the default
  // By its alias too, and a typo is named.
  const std::string alias = std::string(kDriftIni).replace(std::string(kDriftIni).find("drift_1d"), 8, "drift");
  EXPECT_EQ(io::makeModel(io::IniDocument::parse(alias, "a.ini"))->name(), "drift_1d");
  try {
    io::makeModel(io::IniDocument::parse(std::string(kDriftIni) + "offset_sdd = 1\n", "typo.ini"));
    FAIL() << "a misspelt key was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("offset_sdd"), std::string::npos) << e.what();
  }
}

TEST(ModelRegistry, TestTreeModelEstimatesAsTheEquivalentLinearModel) {
  const auto model = io::makeModel(io::IniDocument::parse(kDriftIni, "drift.ini"));
  const models::LinearModel linear = driftAsLinear(dynamic_cast<const gssm::testing::Drift1D&>(*model));
  const auto ms = driftMeasurements(*model, 60);
  for (Method method : {Method::Ekf, Method::Incremental, Method::FixedLag}) {
    const StateEstimate a = finalEstimate(*model, method, ms), b = finalEstimate(linear, method, ms);
    EXPECT_LT((a.mean - b.mean).norm(), 1e-9 * (1 + b.mean.norm())) << methodName(method);
    EXPECT_LT((a.covariance - b.covariance).norm(), 1e-9 * (1 + b.covariance.norm())) << methodName(method);
  }
}

TEST(ModelRegistry, TestTreeModelRoundTripsThroughIniAndCheckpoint) {
  const auto model = io::makeModel(io::IniDocument::parse(kDriftIni, "drift.ini"));
  io::IniDocument written;
  io::writeModel(*model, written);
  EXPECT_EQ(written.getString("model", "type"), "drift_1d");
  const auto reread = io::makeModel(io::IniDocument::parse(written.toString(), "written.ini"));
  const auto ms = driftMeasurements(*model, 40);
  auto whole = makeEstimator(*model, EstimatorOptions(Method::Incremental));
  auto first = makeEstimator(*model, EstimatorOptions(Method::Incremental));
  for (std::size_t i = 0; i < ms.size(); ++i) {
    whole->addMeasurement(ms[i]);
    if (i < 20) first->addMeasurement(ms[i]);
  }
  // Restored on the model read back from its written INI, and continued.
  auto resumed = restoreCheckpointBytes(*reread, checkpointBytes(*first));
  for (std::size_t i = 20; i < ms.size(); ++i) resumed->addMeasurement(ms[i]);
  EXPECT_EQ(resumed->current().mean, whole->current().mean);
  EXPECT_EQ(resumed->current().covariance, whole->current().covariance);
}

TEST(ModelRegistry, BuiltinTypesRoundTripThroughTheirIniForm) {
  for (const char* name : {"paper", "nav-paper-like", "beacons-consistent"}) {
    const io::IniDocument scenario = io::builtinScenario(name, 1, 10);
    const auto model = io::makeModel(scenario);
    io::IniDocument written;
    io::writeModel(*model, written);
    const auto again = io::makeModel(written);
    EXPECT_EQ(again->name(), model->name());
    EXPECT_EQ(again->noise().Q, model->noise().Q) << name;
    EXPECT_EQ(again->noise().R, model->noise().R) << name;
    EXPECT_EQ(again->priorConstants().covariance, model->priorConstants().covariance) << name;
    EXPECT_EQ(again->landmarks().size(), model->landmarks().size()) << name;
  }
}

TEST(ModelRegistry, RefusesClashesAndNamesTheKnownTypes) {
  ASSERT_NE(findModelType("drift_1d"), nullptr);
  EXPECT_EQ(findModelType("radar2d"), findModelType("radar_2d"));  // the old name, kept as an alias
  ModelType clash = *findModelType("drift_1d");
  EXPECT_THROW(registerModelType(clash), InvalidArgument);
  clash.name = "drift_again", clash.aliases = {}, clash.class_name = "Radar2D";
  EXPECT_THROW(registerModelType(clash), InvalidArgument);
  clash.class_name = "DriftAgain", clash.read = nullptr;
  EXPECT_THROW(registerModelType(clash), InvalidArgument);
  try {
    io::makeModel(io::IniDocument::parse("[model]\ntype = sonar\n", "s.ini"));
    FAIL();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const char* known : {"radar_2d", "linear", "nav_2d", "range_beacon_2d", "drift_1d", "s.ini:2"})
      EXPECT_NE(msg.find(known), std::string::npos) << msg;
  }
}
