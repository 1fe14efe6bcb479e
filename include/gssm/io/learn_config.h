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
  /// [learn] batch_likelihood_spacing: the batch's own noise, learnt again
  /// with the counted measurements this far apart (s; 0: every one), into
  /// `[batch.section]`; none: the batch runs with the other methods' noise.
  std::optional<double> batch_likelihood_spacing;
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
/// With `section_prefix` ("batch"), the values go to `[prefix.section]`
/// instead: one method's own values (IniDocument::overriddenBy).
std::string learntScenarioText(const IniDocument& input, const NoiseLearningReport& report,
                               const std::string& section_prefix = "");
/// learn.json: every parameter (given, start, learnt, standard error,
/// identifiable, note), the log-likelihood trace and the counts.
std::string learnReportJson(const NoiseLearningReport& report, const std::string& dataset);

struct LearnResult {
  NoiseLearningReport report;
  IniDocument config;              ///< the learnt scenario.ini, parsed
  std::vector<std::string> files;  ///< OUT/scenario.ini, OUT/learn.json (and learn-batch.json)
  /// The batch's own noise, when [learn] batch_likelihood_spacing asked for it.
  std::optional<NoiseLearningReport> batch_report;
};

/// Learns the noise of `model` (read from `input` over `dataset`) and writes
/// out_dir/scenario.ini and out_dir/learn.json with `options`
/// (the [learn] options, or the caller's; [learn] likelihood_channels, the
/// channels the likelihood counts by name, unless the options name them).
/// Refuses an out_dir that is the dataset's
/// folder (its scenario.ini would be overwritten).
LearnResult learnAndWrite(const Model& model, const IniDocument& input, const Dataset& dataset,
                          const std::string& out_dir, const NoiseLearningOptions& options);

/// The batch's own noise ([learn] batch_likelihood_spacing): learnt over
/// `dataset` from `learnt` (the scenario as learnt for the other methods)
/// as the batch reads it (`[batch.section]` over `[section]`: a warm start
/// there is where it starts) with `options` (their likelihood_spacing the
/// batch's); its values written to `[batch.section]` of
/// out_dir/scenario.ini, its report to out_dir/learn-batch.json. The
/// smoother bridges a gap from both ends, and the likelihood of every
/// measurement can serve it where one of a horizon serves the online
/// methods (docs/DESIGN.md §10).
LearnResult learnBatchNoiseAndWrite(const IniDocument& learnt, const Dataset& dataset, const std::string& out_dir,
                                    const NoiseLearningOptions& options);

/// The options the batch's own noise is learnt with: `settings`' options at
/// its batch_likelihood_spacing; none when that is not given.
std::optional<NoiseLearningOptions> batchNoiseOptions(const LearnSettings& settings);

/// Both of the above as `settings` ask: the noise, then the batch's own
/// when settings.batch_likelihood_spacing is given (config and files then
/// include it).
LearnResult learnScenarioNoise(const Model& model, const IniDocument& input, const Dataset& dataset,
                               const std::string& out_dir, const LearnSettings& settings);

/// What gssm-learn runs: reads data_dir with its scenario.ini (or `config`;
/// a bad row is an InputError naming file:line:column: learning from part of
/// a log is not done silently), learns with its [learn] options (`options`
/// when given) and writes out_dir/scenario.ini and learn.json.
LearnResult learnDataset(const std::string& data_dir, const std::string& out_dir, const std::string& config = "",
                         const std::optional<NoiseLearningOptions>& options = std::nullopt);

}  // namespace gssm::io
