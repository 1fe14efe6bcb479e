// The manual's INI reference against the readers' own key lists: every key a
// reader accepts is documented with a type and a meaning, and no other; a key
// outside the tables is refused by name, file and line.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/io/dataset.h"
#include "gssm/io/ini_keys.h"
#include "gssm/io/learn_config.h"
#include "gssm/model/registry.h"

namespace gssm::io {
namespace {

using Documented = std::map<std::string, std::set<std::string>>;  // section -> keys

// Reads the sections and keys back from the generated Markdown.
Documented parseReference(const std::string& md, const std::string& from_heading) {
  Documented out;
  std::istringstream in(md.substr(md.find(from_heading)));
  std::string line, section;
  bool first = true;
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0 && !first) break;  // the next part
    first = false;
    if (line.rfind("### [", 0) == 0) section = line.substr(5, line.size() - 6);
    if (line.rfind("| `", 0) == 0) out[section].insert(line.substr(3, line.find('`', 3) - 3));
  }
  return out;
}

std::set<std::string> asSet(const std::vector<std::string>& v) { return {v.begin(), v.end()}; }

TEST(IniReference, CommonSectionsAreTheReadersKeys) {
  const Documented doc = parseReference(iniReferenceMarkdown(), "## Every scenario");
  for (const auto& [section, keys] : estimatorIniKeys()) EXPECT_EQ(doc.at(section), asSet(keys)) << section;
  EXPECT_EQ(doc.at("learn"), asSet(learnIniKeys()));
  std::set<std::string> dataset, scenario, truth;
  for (const auto& k : datasetIniKeys()) dataset.insert(k.key);
  for (const auto& k : scenarioIniKeys()) scenario.insert(k.key);
  for (const auto& k : truthIniKeys()) truth.insert(k.key);
  EXPECT_EQ(doc.at("dataset"), dataset);
  EXPECT_EQ(doc.at("scenario"), scenario);
  EXPECT_EQ(doc.at("truth"), truth);
  EXPECT_EQ(doc.size(), 9u);  // scenario, dataset, truth, learn and the five estimators' sections
  for (const auto& section : commonIniSections())
    for (const auto& k : section.keys) EXPECT_FALSE(k.type.empty() || k.meaning.empty()) << section.name << " " << k.key;
}

TEST(IniReference, EveryModelTypesKeysAreDocumented) {
  const std::string md = iniReferenceMarkdown();
  for (const ModelType* type : modelTypes()) {
    const Documented doc = parseReference(md, "## Model `" + type->name + "`");
    for (const std::string& section : type->sections()) {
      std::set<std::string> keys = asSet(type->keysOf(section));
      if (section == "model") keys.insert("type");
      EXPECT_EQ(doc.at(section), keys) << type->name << " [" << section << "]";
    }
    for (const ParamSpec& p : type->params) {
      if (p.kind == ParamKind::Sections) {
        EXPECT_EQ(doc.at(p.subsection + ".&lt;name&gt;"), asSet(type->keysOf(p.subsection))) << type->name;
      }
    }
  }
}

TEST(IniReference, DefaultsAreTheValuesAModelTakesWithoutTheKey) {
  const ModelType* radar = findModelType("radar_2d");
  ASSERT_NE(radar, nullptr);
  std::string step;
  for (const auto& s : modelIniSections(*radar))
    for (const auto& k : s.keys)
      if (s.name == "model" && k.key == "T") step = k.default_value;
  EXPECT_EQ(step, "0.05");  // the paper's step
}

TEST(IniReference, AKeyOutsideTheTablesIsRefusedWithItsLine) {
  for (const std::string section : {"scenario", "truth"}) {
    const IniDocument ini = IniDocument::parse("[" + section + "]\nnmae = x\n", "typo.ini");
    try {
      requireScenarioKeys(ini);
      FAIL() << "[" << section << "] nmae must be refused";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("typo.ini:2"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("nmae"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace gssm::io
