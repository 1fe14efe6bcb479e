#include "gssm/io/learn_config.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/estimator/method.h"
#include "gssm/io/config.h"
#include "gssm/io/json_text.h"
#include "io/byte_order_mark.h"

namespace gssm::io {

namespace fs = std::filesystem;

std::vector<IniKey> learnIniKeyDocs() {
  const NoiseLearningOptions o;
  const auto number = [](double v) { return formatDouble(v); };
  return {
      {"enabled", "flag", "false", "learn before the run (gssm-process; gssm-learn always does)"},
      {"parameters", "words", "(all)", "the learnable parameters to learn, by key (see each model's keys)"},
      {"start", "number", number(o.start), "every learnt σ starts here (0: the model's values)"},
      {"search_range", "number", number(o.search_range), "each σ is searched within this factor of its start"},
      {"outliers", "flag", "false", "then learn again with each measurement an outlier with a learnt probability"},
      {"max_evaluations", "integer", std::to_string(o.max_evaluations), "likelihood evaluations (EKF passes) in all"},
      {"optimizer", "word", o.optimizer, "scoring (gradient and score outer product) or nelder-mead"},
      {"tolerance", "number", number(o.tolerance), "converged when the next step would gain less than this, relative"},
      {"max_restarts", "integer", std::to_string(o.max_restarts), "Nelder–Mead restarts from the best point"},
      {"standard_errors", "flag", "true", "standard errors from the likelihood's curvature (2p² more passes; EM's σs have theirs regardless)"},
      {"prior_iterations", "integer", std::to_string(o.prior_iterations), "EM E-steps for the constants' prior σs"},
      {"prior_tolerance", "number", number(o.prior_tolerance), "EM converged when no σ changes by more than this, relative"},
      {"likelihood_channels", "words", "(all)",
       "the channels whose innovations the likelihood counts; the others condition it"},
      {"likelihood_spacing", "number", number(o.likelihood_spacing),
       "the counted channels' measurements at least this far apart (s), the others left out of the learning "
       "passes: each is predicted over that span (0: every measurement, one step ahead)"},
      {"batch_likelihood_spacing", "number", "(none)",
       "learn the batch's own noise again with this likelihood_spacing (s), into [batch.<section>] (none: the "
       "batch runs with the other methods' noise)"}};
}

std::vector<std::string> learnIniKeys() { return iniKeyNames(learnIniKeyDocs()); }

LearnSettings learnSettings(const IniDocument& ini) {
  LearnSettings s;
  if (!ini.hasSection("learn")) return s;
  ini.requireOnlyKeys("learn", learnIniKeys());
  NoiseLearningOptions& o = s.options;
  s.enabled = ini.getBool("learn", "enabled", false);
  std::istringstream words(ini.getString("learn", "parameters", ""));
  for (std::string w; words >> w;) o.parameters.push_back(w);
  o.start = ini.getDouble("learn", "start", o.start);
  o.search_range = ini.getDouble("learn", "search_range", o.search_range);
  o.outliers = ini.getBool("learn", "outliers", o.outliers);
  o.max_evaluations = static_cast<int>(ini.getInt("learn", "max_evaluations", o.max_evaluations));
  o.optimizer = ini.getString("learn", "optimizer", o.optimizer);
  o.tolerance = ini.getDouble("learn", "tolerance", o.tolerance);
  o.max_restarts = static_cast<int>(ini.getInt("learn", "max_restarts", o.max_restarts));
  o.standard_errors = ini.getBool("learn", "standard_errors", o.standard_errors);
  o.prior_iterations = static_cast<int>(ini.getInt("learn", "prior_iterations", o.prior_iterations));
  o.prior_tolerance = ini.getDouble("learn", "prior_tolerance", o.prior_tolerance);
  o.likelihood_spacing = ini.getDouble("learn", "likelihood_spacing", o.likelihood_spacing);
  if (ini.has("learn", "batch_likelihood_spacing")) {
    s.batch_likelihood_spacing = ini.getDouble("learn", "batch_likelihood_spacing");
    if (!(*s.batch_likelihood_spacing >= 0) || !std::isfinite(*s.batch_likelihood_spacing))
      throw InputError(ini.where("learn", "batch_likelihood_spacing") + ": must be >= 0 s");
  }
  o.batch = batchOptions(ini);  // the E-steps solve as the run's batch does
  std::string why;
  if (!o.validate(&why)) {
    std::string key = "start";  // the key the message is about
    for (const auto& k : learnIniKeys())
      if (why.find(k) != std::string::npos) key = k;
    throw InputError(ini.where("learn", key) + ": " + why);
  }
  return s;
}

namespace {
// The INI text of each learnt key's new value ("0.55", "[0.1 0; 0 0.2]").
// In [prefix.section] when a prefix is given.
std::map<std::pair<std::string, std::string>, std::string> learntValues(const NoiseLearningReport& r,
                                                                        const std::string& prefix) {
  std::map<std::pair<std::string, std::string>, std::string> out;
  IniDocument scratch;
  for (const auto& p : r.parameters) {
    if (p.index < 0) scratch.set(p.section, p.key, p.value);
    else if (p.of_vector) scratch.set(p.section, p.key, Eigen::MatrixXd(r.values.vector(p.section, p.key).transpose()));
    else scratch.set(p.section, p.key, r.values.matrix(p.section, p.key));
    out[{prefix.empty() ? p.section : prefix + "." + p.section, p.key}] = scratch.getString(p.section, p.key);
  }
  return out;
}

std::vector<std::string> linesOf(const IniDocument& input) {
  std::vector<std::string> lines;
  std::ifstream in(input.source(), std::ios::binary);
  if (!in) {  // not from a file: its serialization
    std::istringstream ss(input.toString());
    for (std::string l; std::getline(ss, l);) lines.push_back(l);
    return lines;
  }
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  if (!lines.empty()) lines.front().erase(0, byteOrderMarkLength(lines.front()));
  return lines;
}

std::string header(const NoiseLearningReport& r) {
  std::ostringstream os;
  os << "# Noise learnt from the log by gssm (prediction-error maximum likelihood; the constants' prior by EM,\n"
     << "# docs/DESIGN.md §10);\n"
     << "# data files are the dataset's: gssm-process --data <dataset> --config <this file>\n";
  std::istringstream summary(r.toString());
  for (std::string l; std::getline(summary, l);) os << "#   " << l << "\n";
  os << "# log-likelihood per iteration:";
  const std::size_t n = r.log_likelihood.size(), every = std::max<std::size_t>(1, n / 40);
  for (std::size_t i = 0; i < n; i += every) os << (i % (every * 8) == 0 ? "\n#  " : "") << " " << r.log_likelihood[i];
  if (n) os << "\n#   final " << r.log_likelihood.back();
  return os.str() + "\n\n";
}
}  // namespace

std::string learntScenarioText(const IniDocument& input, const NoiseLearningReport& r,
                               const std::string& section_prefix) {
  std::vector<std::string> lines = linesOf(input);
  std::map<int, std::vector<std::string>> after;  // lines to insert after a line (0: at the end)
  std::map<std::string, std::vector<std::string>> added;  // sections the file lacks, with their keys
  std::vector<std::string> added_order;
  auto put = [&](const std::string& section, const std::string& key, const std::string& value) {
    const int line = input.lineOf(section, key);
    if (line > 0 && line <= static_cast<int>(lines.size())) {
      lines[static_cast<std::size_t>(line - 1)] = key + " = " + value;
    } else if (const int last = input.lastLineOf(section); last > 0) {
      after[last].push_back(key + " = " + value);
    } else {
      if (!added.count(section)) added_order.push_back(section);
      added[section].push_back(key + " = " + value);
    }
  };
  for (const auto& [where, value] : learntValues(r, section_prefix)) put(where.first, where.second, value);
  put("learn", "enabled", "false");  // learnt already: the file reproduces the run as it is
  std::string out = header(r);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    out += lines[i] + "\n";
    for (const auto& l : after[static_cast<int>(i + 1)]) out += l + "\n";
  }
  for (const auto& section : added_order) {
    out += "\n[" + section + "]\n";
    for (const auto& l : added[section]) out += l + "\n";
  }
  return out;
}

std::string learnReportJson(const NoiseLearningReport& r, const std::string& dataset) {
  std::ostringstream os;
  os << "{\n  \"dataset\": " << jsonQuoted(dataset) << ",\n  \"method\": \"prediction-error maximum likelihood (EKF)\""
     << ",\n  \"measurements\": " << r.measurements << ",\n  \"converged\": " << (r.converged ? "true" : "false")
     << ",\n  \"optimizer\": " << jsonQuoted(r.optimizer) << ",\n  \"evaluations\": " << r.evaluations
     << ",\n  \"iterations\": " << r.iterations
     << ",\n  \"restarts\": " << r.restarts << ",\n  \"seconds\": " << jsonNumber(r.seconds)
     << ",\n  \"log_likelihood\": {\"given\": " << jsonNumber(r.given_log_likelihood)
     << ", \"start\": " << jsonNumber(r.start_log_likelihood) << ", \"final\": " << jsonNumber(r.final_log_likelihood)
     << ", \"gaussian\": " << jsonNumber(r.gaussian_log_likelihood) << "},\n  \"outlier_probability\": "
     << jsonNumber(r.outlier_probability) << ",\n  \"outlier_stage_from\": " << r.mixture_from
     << ",\n  \"constants_prior\": {\"method\": \"EM on the factor graph (batch posterior of x_b)\", \"e_steps\": "
     << r.prior_iterations << ", \"converged\": " << (r.prior_converged ? "true" : "false")
     << ", \"expected_log_prior_at_start\": " << jsonNumber(r.prior_start_expected_log_prior)
     << ", \"expected_log_prior\": [" << [&] {
          std::string t;
          for (std::size_t i = 0; i < r.prior_expected_log_prior.size(); ++i)
            t += (i ? ", " : "") + jsonNumber(r.prior_expected_log_prior[i]);
          return t;
        }() << "]}"
     << ",\n  \"parameters\": [";
  for (std::size_t i = 0; i < r.parameters.size(); ++i) {
    const LearntParameter& p = r.parameters[i];
    os << (i ? "," : "") << "\n    {\"name\": " << jsonQuoted(p.name()) << ", \"section\": " << jsonQuoted(p.section)
       << ", \"key\": " << jsonQuoted(p.key) << ", \"index\": " << p.index << ", \"method\": " << jsonQuoted(p.method) << ", \"given\": " << jsonNumber(p.given)
       << ", \"start\": " << jsonNumber(p.start) << ", \"learnt\": " << jsonNumber(p.value)
       << ", \"standard_error\": " << jsonNumber(p.standard_error)
       << ", \"identifiable\": " << (p.identifiable ? "true" : "false") << ", \"note\": " << jsonQuoted(p.note) << "}";
  }
  os << "\n  ],\n  \"log_likelihood_trace\": [";
  for (std::size_t i = 0; i < r.log_likelihood.size(); ++i) os << (i ? ", " : "") << jsonNumber(r.log_likelihood[i]);
  os << "]\n}\n";
  return os.str();
}

namespace {
// [learn] likelihood_channels: the channels, by name, whose innovations the
// likelihood counts (the others condition it: a vehicle's constraint
// pseudo-measurements); none given: every channel, or what the options say.
void readLikelihoodChannels(const IniDocument& input, const Model& model, NoiseLearningOptions& o) {
  std::istringstream words(input.getString("learn", "likelihood_channels", ""));
  for (std::string name; words >> name;) {
    int found = -1;
    for (int c = 0; c < model.numChannels(); ++c)
      if (model.channel(c).name == name) found = c;
    if (found < 0) {
      std::string names;
      for (int c = 0; c < model.numChannels(); ++c) names += (c ? ", " : "") + model.channel(c).name;
      throw InputError(input.where("learn", "likelihood_channels") + ": '" + name + "' is not a channel of " +
                       model.name() + " (" + names + ")");
    }
    o.ekf.likelihood_channels.push_back(found);
  }
}
}  // namespace

namespace {
// Learns `model`'s noise as `input` says and writes OUT/scenario.ini (the
// values in [section], or [prefix.section]) and OUT/<json_name>.
LearnResult learnAndWriteAs(const Model& model, const IniDocument& input, const Dataset& dataset,
                            const std::string& out_dir, NoiseLearningOptions options, const std::string& prefix,
                            const std::string& json_name) {
  if (options.ekf.likelihood_channels.empty()) readLikelihoodChannels(input, model, options);
  std::error_code ec;
  if (!dataset.dir.empty() && fs::exists(out_dir) && fs::equivalent(out_dir, dataset.dir, ec))
    throw InvalidArgument("the output folder " + out_dir +
                          " is the dataset's: the learnt scenario.ini would replace its own; choose another");
  LearnResult out;
  out.report = learnNoise(model, dataset.measurements, dataset.inputs, dataset.t0, options);
  fs::create_directories(out_dir);
  const std::string ini = (fs::path(out_dir) / "scenario.ini").string();
  const std::string text = learntScenarioText(input, out.report, prefix);
  std::ofstream(ini, std::ios::binary) << text;
  out.config = IniDocument::parse(text, ini);
  const std::string json = (fs::path(out_dir) / json_name).string();
  std::ofstream(json, std::ios::binary) << learnReportJson(out.report, dataset.dir);
  out.files = {ini, json};
  return out;
}
}  // namespace

LearnResult learnAndWrite(const Model& model, const IniDocument& input, const Dataset& dataset,
                          const std::string& out_dir, const NoiseLearningOptions& options) {
  return learnAndWriteAs(model, input, dataset, out_dir, options, "", "learn.json");
}

LearnResult learnBatchNoiseAndWrite(const IniDocument& learnt, const Dataset& dataset, const std::string& out_dir,
                                    const NoiseLearningOptions& options) {
  const std::string batch = methodName(Method::Batch);
  const std::unique_ptr<Model> model = makeModel(learnt.overriddenBy(batch), dataset.dir);
  return learnAndWriteAs(*model, learnt, dataset, out_dir, options, batch, "learn-batch.json");
}

std::optional<NoiseLearningOptions> batchNoiseOptions(const LearnSettings& settings) {
  if (!settings.batch_likelihood_spacing) return std::nullopt;
  NoiseLearningOptions options = settings.options;
  options.likelihood_spacing = *settings.batch_likelihood_spacing;
  return options;
}

LearnResult learnScenarioNoise(const Model& model, const IniDocument& input, const Dataset& dataset,
                               const std::string& out_dir, const LearnSettings& settings) {
  LearnResult out = learnAndWrite(model, input, dataset, out_dir, settings.options);
  const std::optional<NoiseLearningOptions> options = batchNoiseOptions(settings);
  if (!options) return out;
  LearnResult batch = learnBatchNoiseAndWrite(out.config, dataset, out_dir, *options);
  out.config = std::move(batch.config);
  out.files.push_back(batch.files.back());
  out.batch_report = std::move(batch.report);
  return out;
}

LearnResult learnDataset(const std::string& data_dir, const std::string& out_dir, const std::string& config,
                         const std::optional<NoiseLearningOptions>& options) {
  const IniDocument ini = readScenario(data_dir, config);
  const std::unique_ptr<Model> model = makeModel(ini, data_dir);
  Dataset dataset;
  readDatasetData(data_dir, *model, dataset, BadRows::Throw, &ini);
  LearnSettings settings = learnSettings(ini);
  if (options) settings.options = *options;
  return learnScenarioNoise(*model, ini, dataset, out_dir, settings);
}

}  // namespace gssm::io
