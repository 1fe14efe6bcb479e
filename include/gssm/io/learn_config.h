#pragma once
// Noise learning from files (docs/DESIGN.md §10): the [learn] section of a
// scenario.ini, the learnt scenario.ini written back with the input's own
// lines and comments, and learn.json. What gssm-learn, `gssm-process
// --learn` and gssm.learn run.
#include <optional>
#include <string>
#include <vector>

#include "gssm/io/dataset.h"
#include "gssm/io/ini.h"
#include "gssm/io/ini_keys.h"
#include "gssm/learn/noise_learning.h"

namespace gssm::io {

/// [learn]:
///   enabled = true | false     gssm-process learns before estimating (default false)
///   parameters = NAMES         what to learn (default: every learnable σ of the model)
///   start = SIGMA              every σ starts here (default 0: the [model] values)
///   search_range, max_evaluations, tolerance, max_restarts, standard_errors
struct LearnSettings {
  bool enabled = false;
  NoiseLearningOptions options;
};
/// Reads [learn]; InputError naming file:line for a bad or unknown key.
LearnSettings learnSettings(const IniDocument& ini);
/// [learn]'s keys, with type, default and meaning (the manual's reference).
std::vector<IniKey> learnIniKeyDocs();
/// The keys of [learn], in order.
std::vector<std::string> learnIniKeys();

/// The scenario as learnt: the input file's text (its comments kept) with
/// each learnt key's line replaced by the learnt value (a key the file did
/// not have is added to its section), [learn] enabled = false (so that the
/// file reproduces the run without learning again), and a comment at the top
/// with the learning's summary and its log-likelihood trace.
std::string learntScenarioText(const IniDocument& input, const NoiseLearningReport& report);
/// learn.json: every parameter (given, start, learnt, standard error,
/// identifiable, note), the log-likelihood trace and the counts.
std::string learnReportJson(const NoiseLearningReport& report, const std::string& dataset);

struct LearnResult {
  NoiseLearningReport report;
  IniDocument config;              ///< the learnt scenario.ini, parsed
  std::vector<std::string> files;  ///< OUT/scenario.ini, OUT/learn.json
};

/// Learns the noise of `model` (read from `input` over `dataset`) and writes
/// out_dir/scenario.ini and out_dir/learn.json with `options`
/// (the [learn] options, or the caller's; [learn] likelihood_channels, the
/// channels the likelihood counts by name, unless the options name them).
/// Refuses an out_dir that is the dataset's
/// folder (its scenario.ini would be overwritten).
LearnResult learnAndWrite(const Model& model, const IniDocument& input, const Dataset& dataset,
                          const std::string& out_dir, const NoiseLearningOptions& options);

/// What gssm-learn runs: reads data_dir with its scenario.ini (or `config`;
/// a bad row is an InputError naming file:line:column: learning from part of
/// a log is not done silently), learns with its [learn] options (`options`
/// when given) and writes out_dir/scenario.ini and learn.json.
LearnResult learnDataset(const std::string& data_dir, const std::string& out_dir, const std::string& config = "",
                         const std::optional<NoiseLearningOptions>& options = std::nullopt);

}  // namespace gssm::io
