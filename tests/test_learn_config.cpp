// [learn] and the learnt scenario.ini (docs/DESIGN.md §10): the input's own
// lines and comments kept, the learnt values in place, the model rebuilt
// from the file equal to the learnt one; bad keys named by file and line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/io/learn_config.h"
#include "gssm/model/param_values.h"
#include "reference_kalman.h"

namespace gssm::io {
namespace {

const char* kScenario = R"([scenario]
name = cv
[model]
type = linear
# a constant-velocity track: position measured
A_c = [0 1; 0 0]
C_c = [1 0]
T = 1
Q = [1 0; 0 1]
R = [1]
[prior]
state_mean = [0 1]
state_cov = [4 0; 0 1]
[learn]
enabled = true
start = 1.0
)";

std::string writeFile(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / "gssm_learn_config";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(LearnConfig, TheLearntScenarioKeepsTheInputsLinesAndRebuildsTheLearntModel) {
  const IniDocument ini = IniDocument::load(writeFile("cv.ini", kScenario));
  const LearnSettings s = learnSettings(ini);
  EXPECT_TRUE(s.enabled);
  EXPECT_EQ(s.options.start, 1.0);
  const auto model = makeModel(ini);
  const SimulatedRun run = simulate(*model, SimulationSpec{}, testing::normalSampler(2));
  const NoiseLearningReport r = learnNoise(*model, run.measurements, {}, 0.0, s.options);
  const std::string text = learntScenarioText(ini, r);
  EXPECT_NE(text.find("# a constant-velocity track: position measured\n"), std::string::npos) << text;
  EXPECT_NE(text.find("# log-likelihood per iteration:"), std::string::npos) << text;
  const IniDocument learnt = IniDocument::parse(text, "learnt.ini");
  EXPECT_FALSE(learnSettings(learnt).enabled);
  EXPECT_EQ(learnt.getString("model", "A_c"), "[0 1; 0 0]");  // untouched lines as they were
  EXPECT_LT(learnt.lineOf("model", "Q"), learnt.lineOf("model", "R"));  // in place, in order
  const ParamValues a = ParamValues::of(*makeModel(learnt)), b = ParamValues::of(*r.model);
  for (const auto& [section, key] : b.keys()) EXPECT_TRUE(*a.find(section, key) == *b.find(section, key)) << key;
}

TEST(LearnConfig, BadLearnKeysAreNamedByFileAndLine) {
  std::string text = kScenario;
  text += "maximum_evaluations = 10\n";
  try {
    learnSettings(IniDocument::parse(text, "bad.ini"));
    FAIL() << "a typo must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.ini"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("maximum_evaluations"), std::string::npos) << e.what();
  }
  text = kScenario;
  text.replace(text.find("start = 1.0"), 11, "start = -1");
  try {
    learnSettings(IniDocument::parse(text, "neg.ini"));
    FAIL() << "a negative start must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("neg.ini:16: [learn] start"), std::string::npos) << e.what();
  }
}

// [learn] likelihood_channels names channels: the learnt noise is the one
// whose counted likelihood is highest (here the only channel, "y": the same
// as counting all), and a name that is no channel is refused with the
// model's channels and the file and line.
TEST(LearnConfig, LikelihoodChannelsAreChannelNames) {
  const auto model = makeModel(IniDocument::parse(kScenario, "cv.ini"));
  Dataset d;
  d.measurements = simulate(*model, SimulationSpec{}, testing::normalSampler(4)).measurements;
  const auto out = std::filesystem::temp_directory_path() / "gssm_learn_channels";
  const LearnResult all = learnAndWrite(*model, IniDocument::parse(kScenario, "cv.ini"), d, out.string(),
                                        learnSettings(IniDocument::parse(kScenario, "cv.ini")).options);
  std::string text = std::string(kScenario) + "likelihood_channels = y\n";
  const IniDocument named = IniDocument::parse(text, "named.ini");
  const LearnResult only_y = learnAndWrite(*model, named, d, out.string(), learnSettings(named).options);
  EXPECT_EQ(only_y.report.final_log_likelihood, all.report.final_log_likelihood);
  text = std::string(kScenario) + "likelihood_channels = y gnss\n";
  const IniDocument bad = IniDocument::parse(text, "bad.ini");
  try {
    learnAndWrite(*model, bad, d, out.string(), learnSettings(bad).options);
    FAIL() << "an unknown channel must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.ini:17: [learn] likelihood_channels"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'gnss' is not a channel of linear (y)"), std::string::npos) << e.what();
  }
}

// [learn] likelihood_spacing reaches the options (s); a negative one is
// refused, naming the file, line and key.
TEST(LearnConfig, LikelihoodSpacingIsReadInSeconds) {
  EXPECT_EQ(learnSettings(IniDocument::parse(kScenario, "cv.ini")).options.likelihood_spacing, 0.0);
  const std::string text = std::string(kScenario) + "likelihood_spacing = 3\n";
  EXPECT_EQ(learnSettings(IniDocument::parse(text, "spaced.ini")).options.likelihood_spacing, 3.0);
  try {
    learnSettings(IniDocument::parse(std::string(kScenario) + "likelihood_spacing = -1\n", "neg.ini"));
    FAIL() << "a negative spacing must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("neg.ini:17: [learn] likelihood_spacing"), std::string::npos) << e.what();
  }
}

// [learn] batch_likelihood_spacing: the noise learnt again with that
// spacing from the scenario as learnt for the other methods, into
// [batch.model] (the batch's own values, IniDocument::overriddenBy). Checked
// against learning run by hand: the plain learning's values in [model], and
// the spaced learning from them in [batch.model]; the two differ (the
// spacing leaves out half the measurements), so the check can fail.
TEST(LearnConfig, TheBatchsOwnNoiseIsLearntWithItsSpacingIntoItsSection) {
  const IniDocument ini = IniDocument::load(writeFile("cvb.ini", std::string(kScenario) + "batch_likelihood_spacing = 2\n"));
  const LearnSettings s = learnSettings(ini);
  ASSERT_TRUE(s.batch_likelihood_spacing.has_value());
  EXPECT_EQ(*s.batch_likelihood_spacing, 2.0);
  EXPECT_FALSE(learnSettings(IniDocument::parse(kScenario, "cv.ini")).batch_likelihood_spacing.has_value());
  const auto model = makeModel(ini);
  Dataset d;
  d.measurements = simulate(*model, SimulationSpec{}, testing::normalSampler(5)).measurements;
  const auto out = std::filesystem::temp_directory_path() / "gssm_learn_batch";
  const LearnResult r = learnScenarioNoise(*model, ini, d, out.string(), s);
  ASSERT_TRUE(r.batch_report.has_value());
  EXPECT_TRUE(std::filesystem::exists(out / "learn-batch.json"));
  EXPECT_EQ(r.files.back(), (out / "learn-batch.json").string());

  const NoiseLearningReport online = learnNoise(*model, d.measurements, {}, 0.0, s.options);
  NoiseLearningOptions spaced = s.options;
  spaced.likelihood_spacing = 2;
  const NoiseLearningReport batch = learnNoise(*online.model, d.measurements, {}, 0.0, spaced);
  const ParamValues in_model = ParamValues::of(*makeModel(r.config));
  const ParamValues in_batch = ParamValues::of(*makeModel(r.config.overriddenBy("batch")));
  for (const char* key : {"Q", "R"}) {
    EXPECT_TRUE(in_model.matrix("model", key).isApprox(ParamValues::of(*online.model).matrix("model", key), 1e-12)) << key;
    EXPECT_TRUE(in_batch.matrix("model", key).isApprox(ParamValues::of(*batch.model).matrix("model", key), 1e-12)) << key;
  }
  EXPECT_GT((in_model.matrix("model", "Q") - in_batch.matrix("model", "Q")).norm(), 1e-3);
  const IniDocument file = IniDocument::load((out / "scenario.ini").string());
  EXPECT_TRUE(file.has("batch.model", "Q") && file.has("batch.model", "R"));
  EXPECT_FALSE(learnSettings(file).enabled);

  try {
    learnSettings(IniDocument::parse(std::string(kScenario) + "batch_likelihood_spacing = -1\n", "neg.ini"));
    FAIL() << "a negative spacing must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("neg.ini:17: [learn] batch_likelihood_spacing"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace gssm::io
