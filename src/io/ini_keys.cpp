#include "gssm/io/ini_keys.h"

#include <cmath>
#include <sstream>

#include "gssm/estimator/method.h"
#include "gssm/estimator/option_keys.h"
#include "gssm/io/config.h"
#include "gssm/io/dataset.h"
#include "gssm/io/ini.h"
#include "gssm/io/learn_config.h"
#include "gssm/model/registry.h"
#include "gssm/io/number_text.h"
#include "gssm/model/params.h"

namespace gssm::io {

std::vector<std::string> iniKeyNames(const std::vector<IniKey>& keys) {
  std::vector<std::string> out;
  for (const auto& k : keys) out.push_back(k.key);
  return out;
}

namespace {

// An options struct's keys (option_keys.h), with the struct's defaults.
struct OptionDocs {
  std::vector<IniKey> keys;
  void operator()(const char* key, bool& v, const char* doc) { keys.push_back({key, "flag", v ? "true" : "false", doc}); }
  void operator()(const char* key, int& v, const char* doc) { keys.push_back({key, "integer", std::to_string(v), doc}); }
  void operator()(const char* key, double& v, const char* doc) {
    keys.push_back({key, "number", std::isfinite(v) ? formatDouble(v) : "inf", doc});
  }
  void operator()(const char* key, Eigen::VectorXd& v, const char* doc) {
    std::ostringstream os;
    os << "[" << v.transpose() << "]";
    keys.push_back({key, "numbers", v.size() ? os.str() : "(none)", doc});
  }
  template <class E>
  void operator()(const char* key, Choice<E>& c, const char* doc) {
    keys.push_back({key, "word", c.name(c.value), doc});
  }
};

template <class Options>
std::vector<IniKey> optionDocs() {
  OptionDocs docs;
  Options o;
  optionKeys(docs, o);
  return docs.keys;
}

IniSection scenarioSection() {
  return {"scenario", "the run's name and, for simulated scenarios, what gssm-simulate draws", scenarioIniKeys()};
}

IniSection truthSection() {
  return {"truth", "a simulated scenario's truth (gssm-simulate)", truthIniKeys()};
}

std::vector<IniSection> estimatorSections() {
  const auto section = [](Method m) { return methodInfo(m).ini_section; };
  std::vector<IniKey> smoother = optionDocs<SmootherOptions>();
  const EstimatorOptions defaults;
  smoother.push_back({"ordering", "word", orderingName(defaults.incremental.ordering),
                      "the incremental smoother's elimination ordering: colamd or time"});
  const auto window = [](int w) { return std::vector<IniKey>{{"window", "integer", std::to_string(w), "states the window holds"}}; };
  return {{section(Method::Ekf), "the extended Kalman filter", optionDocs<ExtendedKalmanFilterOptions>()},
          {section(Method::Incremental), "both smoothers' relinearization, and the incremental smoother's ordering",
           smoother},
          {section(Method::FixedLag), "the fixed-lag smoother", [&] {
             std::vector<IniKey> keys = window(defaults.fixed_lag.window);
             keys.push_back({"constants_check_sigmas", "number", "([smoother]'s)",
                             "the fixed lag's own: a large value (1e9) keeps the window's factors at the constants "
                             "they were added with, as its marginal prior does"});
             return keys;
           }()},
          {section(Method::PaperWindow), "the paper's sliding window", window(defaults.paper_window.window)},
          {section(Method::Batch), "the batch solver (and noise learning's E-steps)", optionDocs<BatchSolverOptions>()}};
}

// A parameter's INI type.
std::string typeOf(ParamKind kind) {
  switch (kind) {
    case ParamKind::Real: return "number";
    case ParamKind::Flag: return "flag";
    case ParamKind::Text: return "word";
    case ParamKind::Names: return "words";
    case ParamKind::Vector: return "numbers";
    case ParamKind::Matrix: return "matrix";
    case ParamKind::Table: return "table or file";
    case ParamKind::Sections: return "section names";
    case ParamKind::Any: return "numbers or word";
  }
  return "?";
}

}  // namespace

std::vector<IniSection> commonIniSections() {
  std::vector<IniSection> out{scenarioSection(),
                              {"dataset", "a real log's files and columns (gssm-process)", datasetIniKeys()},
                              truthSection(),
                              {"learn", "noise learnt from the log before the run", learnIniKeyDocs()}};
  for (auto& s : estimatorSections()) out.push_back(std::move(s));
  return out;
}

std::vector<IniSection> modelIniSections(const ModelType& type) {
  IniDocument defaults;
  writeModelDefaults(type, defaults);
  std::vector<IniSection> out;
  auto sectionNamed = [&out](const std::string& name) -> IniSection& {
    for (auto& s : out)
      if (s.name == name) return s;
    out.push_back({name, "", {}});
    return out.back();
  };
  if (type.params.empty() || type.params.front().section != "model") sectionNamed("model");
  sectionNamed("model").keys.push_back({"type", "word", "", "the model type: " + type.name, true});
  for (const ParamSpec& p : type.params) {
    const std::string section = p.section == "model" || p.section == "prior" || p.section == "colored_noise"
                                    ? p.section
                                    : p.section + ".<name>";
    std::string meaning = p.doc;
    if (p.learnable) meaning += p.constants_prior ? " (learnable by EM)" : " (learnable)";
    sectionNamed(section).keys.push_back(
        {p.key, typeOf(p.kind), p.required ? "" : defaults.getString(p.section, p.key, ""), meaning, p.required});
  }
  return out;
}

std::string iniReferenceMarkdown() {
  std::ostringstream md;
  // A table cell: Markdown's and HTML's own characters escaped.
  const auto cell = [](const std::string& text) {
    std::string out;
    for (char c : text) out += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '|' ? "\\|" : std::string(1, c);
    return out;
  };
  const auto defaultOf = [&cell](const IniKey& k) {
    if (k.required) return std::string("required");
    if (k.default_value.empty()) return std::string("—");
    return k.default_value.front() == '(' ? cell(k.default_value) : "`" + k.default_value + "`";
  };
  auto table = [&md, &cell, &defaultOf](const IniSection& s) {
    md << "\n### [" << cell(s.name) << "]\n\n";
    if (!s.about.empty()) md << s.about << ".\n\n";
    md << "| key | type | default | meaning |\n| --- | --- | --- | --- |\n";
    for (const auto& k : s.keys)
      md << "| `" << k.key << "` | " << k.type << " | " << defaultOf(k) << " | " << cell(k.meaning) << " |\n";
  };
  md << "# INI reference\n\nGenerated from the tables the INI readers check their keys against: a key not "
        "listed here is refused with its file and line.\n\nOne method's own values: a section "
        "`[<method>.<section>]` (`[batch.model]`) sets keys of `[<section>]` for that method alone (`ekf`, "
        "`batch`, `incremental`, `fixed-lag`, `paper-window`); `[learn] batch_likelihood_spacing` learns the "
        "batch's noise into `[batch.model]`. They may change numbers, not the model's states or channels; a "
        "`[<method>.<section>]` whose `[<section>]` the file lacks is refused.\n\n## Every scenario\n";
  for (const auto& s : commonIniSections()) table(s);
  for (const ModelType* t : modelTypes()) {
    md << "\n## Model `" << t->name << "` (`gssm.models." << t->class_name << "`)\n\n" << t->summary << "\n";
    for (const auto& s : modelIniSections(*t)) table(s);
  }
  return md.str();
}

}  // namespace gssm::io
