#pragma once
// Dataset folders: measurements.csv (t,<measurement names>, rows k = 1..N),
// truth.csv (t,<state names>,<constant names>, rows k = 0..N, optional) and
// scenario.ini (model, priors, truth settings, seed), and inputs.csv
// (t,<input names>) for models with inputs.
#include <optional>
#include <string>
#include <vector>

#include "gssm/core/data.h"
#include "gssm/analysis/offline.h"  // RowTimes
#include "gssm/io/ini.h"
#include "gssm/io/ini_keys.h"
#include "gssm/model/model.h"
#include "gssm/model/simulation.h"

namespace gssm::io {

struct Dataset {
  std::string dir;
  double t0 = 0;  ///< time of x_c(0)
  /// When estimate rows are reported ([dataset] rows): per measurement, per
  /// input time (a log's odometry steps), or per epoch (a distinct
  /// measurement time: several sensors at once).
  RowTimes rows = RowTimes::Measurements;
  IniDocument scenario;
  std::vector<Measurement> measurements;
  std::vector<Input> inputs;  ///< inputs.csv (`t,<input names>`), if the model has inputs
  std::optional<Truth> truth;
  /// The constants a calibration file implies ([dataset] constants_reference,
  /// Model::referenceConstants; NaN where it says nothing): for judging only.
  std::optional<Eigen::VectorXd> constants_reference;
  /// Bad rows of measurements.csv (malformed number, NaN, wrong field count,
  /// time not increasing), in file order. With BadRows::Stop only the rows
  /// before the first one are kept; with Skip every good row is kept.
  std::vector<std::string> row_errors;
  /// Rows dropped as non-physical ([dataset] drop_at_or_below), file:line each.
  std::vector<std::string> dropped;
  /// Measurement rows that came after a later time in the file (put in
  /// time order, [dataset] out_of_order = sort), and the largest lateness (s).
  std::size_t late_rows = 0;
  double max_lateness = 0;
  /// GNSS fixes inside [dataset] gnss_outages, withheld from the estimators
  /// (on the GNSS channel, in the model's frame): the truth to score against.
  std::vector<Measurement> withheld;
  /// Those outages' (start, end) times (s), as the file gives them.
  std::vector<std::pair<double, double>> outages;
  /// GNSS fixes dropped for their quality ([dataset] gnss_max_quality).
  std::size_t gnss_dropped = 0;
};

enum class BadRows {
  Throw,  ///< throw InputError at the first bad row
  Stop,   ///< keep the rows before the first bad row, record it
  Skip,   ///< keep every good row, record each bad one
};

/// The measurements used on the channel of `d.withheld` (the fixes outside
/// the outages, to score and draw beside the withheld ones); none when
/// nothing is withheld.
std::vector<Measurement> usedOnWithheldChannel(const Dataset& d);

/// Reads scenario.ini (or `config_override` when non-empty).
IniDocument readScenario(const std::string& dir, const std::string& config_override = "");
/// [dataset]'s keys, with type, default and meaning (the reader accepts these only).
std::vector<IniKey> datasetIniKeys();
/// Reads a dataset of a model's shape, naming file, line and column in
/// every error. Two layouts:
/// * gssm's own (no [dataset] section in `config`): measurements.csv
///   (`t,<channel 0 names>`), inputs.csv, truth.csv (`t,<stacked names>`);
/// * one CSV per sensor stream, described by the config's [dataset]:
///     inputs = FILE, input_columns = NAMES, input_kind = rates | increments
///       (increments: each row's change over the interval since the
///       previous row, turned into rates held over that interval)
///     measurements = FILE, measurement_columns = NAMES, channel_column =
///       NAME and channel_prefix = TEXT (channel = prefix + that column's
///       value; channel_by = index: the column holds the channel's index;
///       without channel_column the default channel)
///     truth = FILE, truth_columns = NAMES (stacked components it gives)
///     start_time = truth | first | first_input | NUMBER (t0; first: a
///       nominal step before the first measurement; first_input: the first
///       input row's time), rows = measurements | inputs | epochs | states
///     constants_reference = FILE (a calibration of the constants, judged against)
///     gnss = FILE (an RTKLIB .pos: each fix a measurement on channel
///       gnss_channel, default "gnss", mapped by Model::localPosition, with
///       the fix's own covariance; gnss_max_quality: the worst Q used, default
///       1 = RTK-fixed; gnss_float_scale: σ factor of float fixes, default 3;
///       gnss_outages = FILE: rows start,end (s) whose fixes are withheld
///       (a missing file withholds nothing, noted in `dropped`);
///       fixes at or before t0 are dropped and listed in `dropped`;
///       gnss_still_channel = NAME: a zero measurement on that channel at
///       every used fix whose own velocity is under gnss_still_speed, m/s,
///       default 0.05: a zero-velocity update where the receiver saw the
///       vehicle stand; gnss_still_rates = NAME: there too, a measurement
///       on that channel of the inputs' mean over the interval since the
///       previous fix, their first components, as many as it has: the
///       gyro's reading while standing)
///     zero_channels = NAMES, zero_rate = HZ: a zero measurement on each of
///       those channels every 1/rate s after t0 (a vehicle's non-holonomic
///       constraint stated as a channel of the model); zero_at_inputs =
///       true: each at the input reading nearest its time, or at a
///       measurement within half a reading's interval of that reading (no
///       state of its own between readings: docs/DESIGN.md §12)
void readDatasetData(const std::string& dir, const Model& model, Dataset& out,
                     BadRows bad_rows = BadRows::Throw, const IniDocument* config = nullptr);

/// The dataset as a run with its truth (true x_c(k) per truth row, x_b from
/// the first row), for analyses that need the true trajectory. Throws
/// InputError when the dataset has no truth.csv.
SimulatedRun recordedRun(const Model& model, const Dataset& dataset);

/// Writes measurements.csv, truth.csv (inputs.csv) and scenario.ini; for a
/// model with several channels, measurements.csv has a channel column and
/// scenario.ini a [dataset] section describing the files.
void writeDataset(const std::string& dir, const Model& model, const SimulatedRun& run,
                  const IniDocument& scenario);

}  // namespace gssm::io
