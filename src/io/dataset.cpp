#include "gssm/io/dataset.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <limits>
#include <optional>

#include "gssm/core/angles.h"
#include "gssm/core/error.h"
#include "gssm/model/packed_inputs.h"
#include "gssm/io/config.h"
#include "gssm/core/time.h"
#include "gssm/io/csv.h"
#include "io/gnss_measurements.h"
#include "io/input_window.h"

namespace gssm::io {

namespace fs = std::filesystem;

namespace {
// Checks that the header is exactly t,<names>.
void checkHeader(const CsvTable& t, const std::vector<std::string>& names) {
  std::vector<std::string> expected{"t"};
  expected.insert(expected.end(), names.begin(), names.end());
  if (t.header != expected) {
    std::string want, got;
    for (const auto& n : expected) want += (want.empty() ? "" : ",") + n;
    for (const auto& n : t.header) got += (got.empty() ? "" : ",") + n;
    throw InputError(t.source + ":1: header is '" + got + "', expected '" + want + "'");
  }
}

// ... and that times increase strictly.
void checkTable(const CsvTable& t, const std::vector<std::string>& names) {
  checkHeader(t, names);
  for (std::size_t r = 1; r < t.rows.size(); ++r)
    if (!(t.rows[r][0] > t.rows[r - 1][0]))
      throw InputError(t.source + ":" + std::to_string(t.line_of_row[r]) + ": column 't': time " +
                       formatDouble(t.rows[r][0]) + " is not after the previous row's " +
                       formatDouble(t.rows[r - 1][0]) +
                       (t.rows[r][0] == t.rows[r - 1][0] ? " (duplicated timestamp)" : ""));
}
}  // namespace

std::vector<IniKey> datasetIniKeys() {
  return {
      {"inputs", "file", "", "the inputs' CSV (odometry, IMU): a column t and the input columns"},
      {"input_columns", "words", "", "the inputs' columns, in the model's input order"},
      {"input_kind", "word", "rates", "rates (held over each interval) or increments (summed over it)"},
      {"measurements", "file", "measurements.csv", "the measurements' CSV: a column t and the measurement columns"},
      {"measurement_columns", "words", "", "the columns of one measurement, in the channel's component order"},
      {"channel_column", "words", "", "the column(s) naming each row's channel: beacon → <prefix><value>; tag anchor → <prefix><tag>_<anchor>"},
      {"channel_prefix", "word", "", "put before the channel column's value to make a channel name"},
      {"channel_by", "word", "name", "the channel column holds the channel's name or its index"},
      {"truth", "file", "", "the truth's CSV: never given to an estimator, only compared with"},
      {"truth_columns", "words", "", "the states the truth gives: px, px=x (another column), yaw=yaw(qw,qx,qy,qz)"},
      {"truth_interpolate", "flag", "false", "the truth linearly interpolated to each estimate time (angles wrapped)"},
      {"start_time", "number or word", "0", "t0: a number, truth (its first time), first (a step before the first measurement), first_input"},
      {"rows", "word", "measurements", "estimate rows at measurements, inputs, epochs (distinct measurement times) or states"},
      {"drop_at_or_below", "number", "-inf", "values at or below this are dropped as non-physical, listed in metrics.json"},
      {"out_of_order", "word", "sort", "rows going back in time: sort (read in time order, counted) or error"},
      {"constants_reference", "file", "", "a calibration of the constants to compare with (never used by an estimator)"},
      {"gnss", "file", "", "an RTKLIB .pos solution file (latitude/longitude/height), its fixes a channel"},
      {"gnss_channel", "word", "gnss", "the channel of the GNSS fixes"},
      {"gnss_max_quality", "integer", "1", "fixes of RTKLIB quality above this are dropped (1 fixed, 2 float, 5 single)"},
      {"gnss_float_scale", "number", "3", "σ factor of the fixes kept above quality 1"},
      {"gnss_outages", "file", "", "a CSV of start,end times: the fixes inside are withheld and scored (metrics.json withheld)"},
      {"gnss_still_channel", "word", "", "a zero-velocity measurement on this channel at every fix slower than gnss_still_speed"},
      {"gnss_still_speed", "number", "0.05", "a fix's own speed (m/s) below which the vehicle is standing"},
      {"gnss_still_rates", "word", "", "while standing, the mean of the inputs' first components since the previous fix on this channel"},
      {"gnss_velocity_channel", "word", "", "each used fix's own velocity on this channel, with the inputs' mean reading around it and the velocity's rate of change"},
      {"gnss_velocity_window", "number", "0.1", "the span (s) around a velocity fix over which the inputs are averaged"},
      {"zero_channels", "words", "",
       "channels measured as zero at zero_rate (vehicle constraints; a channel that reads known values gets the "
       "inputs' mean over each zero's interval)"},
      {"zero_rate", "number", "0", "rate (Hz) of the zero_channels' pseudo-measurements"},
      {"zero_at_inputs", "bool", "false", "each zero measurement at the input reading nearest its time (no state of its own between readings)"}};
}

IniDocument readScenario(const std::string& dir, const std::string& config_override) {
  const std::string path = config_override.empty() ? (fs::path(dir) / "scenario.ini").string()
                                                   : config_override;
  IniDocument ini = IniDocument::load(path);
  requireScenarioKeys(ini);
  return ini;
}

namespace {
// Words separated by blanks or commas (not inside parentheses: "yaw(qw,qx,qy,qz)").
std::vector<std::string> words(const std::string& s) {
  std::vector<std::string> out;
  std::string w;
  int depth = 0;
  for (char c : s + " ") {
    depth += c == '(' ? 1 : c == ')' ? -1 : 0;
    if (depth == 0 && (c == ' ' || c == '\t' || c == ',')) {
      if (!w.empty()) out.push_back(w);
      w.clear();
    } else {
      w += c;
    }
  }
  return out;
}

int requireColumn(const CsvTable& t, const std::string& name, const std::string& why) {
  const int c = t.column(name);
  if (c < 0) {
    std::string have;
    for (const auto& h : t.header) have += (have.empty() ? "" : ",") + h;
    throw InputError(t.source + ":1: no column '" + name + "' (" + why + "); the header is '" + have + "'");
  }
  return c;
}

void requireIncreasing(const CsvTable& t, std::size_t r, double prev, double now) {
  if (!(now > prev))
    throw InputError(t.source + ":" + std::to_string(t.line_of_row[r]) + ": column 't': time " + formatDouble(now) +
                     (now == prev ? " repeats the previous row's (duplicated timestamp)"
                                  : " is before the previous row's " + formatDouble(prev)));
}

// One entry of [dataset] truth_columns: a state, and where its truth is: a
// column of the same name ("px"), another column ("px=x"), or the yaw of a
// quaternion's columns, scalar first ("yaw=yaw(qw,qx,qy,qz)").
struct TruthColumn {
  int state = -1;
  std::vector<int> columns;  // one; or four: a quaternion
  double value(const CsvRows::Row& row) const {
    if (columns.size() == 1) return row[static_cast<std::size_t>(columns[0])];
    const double w = row[static_cast<std::size_t>(columns[0])], x = row[static_cast<std::size_t>(columns[1])],
                 y = row[static_cast<std::size_t>(columns[2])], z = row[static_cast<std::size_t>(columns[3])];
    return std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z));
  }
};

TruthColumn truthColumn(const std::string& entry, const CsvTable& truth, const IniDocument& ini, const Model& model) {
  const auto names = model.stackedStateNames();
  const auto eq = entry.find('=');
  const std::string state = entry.substr(0, eq), source = eq == std::string::npos ? state : entry.substr(eq + 1);
  const auto it = std::find(names.begin(), names.end(), state);
  if (it == names.end())
    throw InputError(ini.where("dataset", "truth_columns") + ": '" + state + "' is not a state of model '" +
                     model.name() + "'");
  TruthColumn c;
  c.state = static_cast<int>(it - names.begin());
  if (source.rfind("yaw(", 0) == 0 && source.back() == ')') {
    std::string args = source.substr(4, source.size() - 5);
    std::replace(args.begin(), args.end(), ',', ' ');
    for (const auto& q : words(args)) c.columns.push_back(requireColumn(truth, q, "[dataset] truth_columns " + entry));
    if (c.columns.size() != 4)
      throw InputError(ini.where("dataset", "truth_columns") + ": '" + entry + "': yaw(qw,qx,qy,qz) takes four columns");
    return c;
  }
  c.columns.push_back(requireColumn(truth, source, "[dataset] truth_columns"));
  return c;
}

// [dataset] truth: the true values of the named states, by time.
void readTruth(const std::string& path, const IniDocument& ini, const Model& model, Dataset& out) {
  const CsvTable truth = readCsv(path);
  const int tc = requireColumn(truth, "t", "the time");
  Truth tr;
  std::vector<TruthColumn> cols;
  for (const auto& entry : words(ini.getString("dataset", "truth_columns"))) {
    cols.push_back(truthColumn(entry, truth, ini, model));
    tr.components.push_back(cols.back().state);
  }
  for (std::size_t r = 0; r < truth.rows.size(); ++r) {
    const double t = truth.rows[r][static_cast<std::size_t>(tc)];
    if (r) requireIncreasing(truth, r, tr.times.back(), t);
    Eigen::VectorXd z(static_cast<Eigen::Index>(cols.size()));
    for (std::size_t i = 0; i < cols.size(); ++i) z[static_cast<Eigen::Index>(i)] = cols[i].value(truth.rows[r]);
    tr.times.push_back(t);
    tr.states.push_back(std::move(z));
  }
  out.truth = std::move(tr);
}

// The truth at each measurement time, linearly interpolated between its rows
// (angles by their wrapped difference); times outside the truth are left out.
void interpolateTruth(const Model& model, Dataset& out) {
  const Truth& tr = *out.truth;
  Truth at;
  at.components = tr.components;
  const auto& angles = model.angleStates();
  std::size_t k = 0;
  for (const auto& m : out.measurements) {
    if (!at.times.empty() && sameTime(at.times.back(), m.t)) continue;
    while (k + 1 < tr.times.size() && tr.times[k + 1] < m.t) ++k;
    if (k + 1 >= tr.times.size() || m.t < tr.times[k]) {
      at.covers_every_row = false;
      continue;
    }
    const double w = (m.t - tr.times[k]) / (tr.times[k + 1] - tr.times[k]);
    Eigen::VectorXd z = tr.states[k];
    for (Eigen::Index i = 0; i < z.size(); ++i) {
      double d = tr.states[k + 1][i] - tr.states[k][i];
      if (std::find(angles.begin(), angles.end(), tr.components[static_cast<std::size_t>(i)]) != angles.end())
        d = wrapAngle(d);
      z[i] += w * d;
    }
    at.times.push_back(m.t);
    at.states.push_back(std::move(z));
  }
  out.truth = std::move(at);
}

// [dataset] start_time (a number, the truth's first time, "first": one
// nominal step before the first measurement, set once they are read, or
// "first_input": the first input's time, set as they are read) and rows.
void readStartAndRows(const IniDocument& ini, Dataset& out) {
  const std::string start = ini.getString("dataset", "start_time", "0");
  if (start == "first") {
    out.t0 = -std::numeric_limits<double>::infinity();
  } else if (start == "first_input") {
    if (!ini.has("dataset", "inputs"))
      throw InputError(ini.source() + ": [dataset] start_time = first_input, but there is no [dataset] inputs file");
    out.t0 = std::numeric_limits<double>::quiet_NaN();
  } else if (start == "truth") {
    if (!out.truth || out.truth->times.empty())
      throw InputError(ini.source() + ": [dataset] start_time = truth, but there is no truth file with rows");
    out.t0 = out.truth->times.front();
  } else {
    out.t0 = ini.getDouble("dataset", "start_time", 0.0);
  }
  const std::string rows = ini.getString("dataset", "rows", "measurements");
  const std::optional<RowTimes> named = rowTimesNamed(rows);
  if (!named)
    throw InputError(ini.source() + ": [dataset] rows = '" + rows +
                     "': expected measurements, inputs, epochs or states");
  out.rows = *named;
}

// Inputs: rates held from each row's time, or increments over the interval
// ending at each row (held from the previous row's time, t0 for the first).
// The size of one raw input row: the model's input, or one reading of a
// packed one (packed_inputs.h: [dt, reading] per slot).
int rawInputSize(const Model& model) {
  const int n = model.readingsPerStep();
  return n == 1 ? model.dims().nu : static_cast<int>(packedReadingSize(model.dims().nu, n));
}

void readInputs(const std::string& path, const IniDocument& ini, const Model& model, Dataset& out) {
  const CsvTable in = readCsv(path);
  const int tc = requireColumn(in, "t", "the time");
  std::vector<int> cols;
  for (const auto& n : words(ini.getString("dataset", "input_columns")))
    cols.push_back(requireColumn(in, n, "[dataset] input_columns"));
  const int width = rawInputSize(model);
  if (static_cast<int>(cols.size()) != width)
    throw InputError(ini.source() + ": [dataset] input_columns names " + std::to_string(cols.size()) +
                     " columns; model '" + model.name() + "' has " + std::to_string(width) + " inputs");
  const std::string kind = ini.getString("dataset", "input_kind", "rates");
  if (kind != "rates" && kind != "increments")
    throw InputError(ini.source() + ": [dataset] input_kind = '" + kind + "': expected rates or increments");
  if (std::isnan(out.t0)) {  // start_time = first_input
    if (in.rows.empty()) throw InputError(in.source + ": no rows: [dataset] start_time = first_input needs one");
    out.t0 = in.rows[0][static_cast<std::size_t>(tc)];
  }
  double prev = out.t0;
  // Rows before the start describe motion before the run: dropped, listed
  // (increments ending at t0 too; a rate may start at t0).
  auto before = [&](double t) { return kind == "increments" ? t <= out.t0 : t < out.t0; };
  std::size_t first = 0;
  for (; first < in.rows.size() && before(in.rows[first][static_cast<std::size_t>(tc)]); ++first) {
    if (first > 0) requireIncreasing(in, first, in.rows[first - 1][static_cast<std::size_t>(tc)], in.rows[first][static_cast<std::size_t>(tc)]);
    out.dropped.push_back(in.source + ":" + std::to_string(in.line_of_row[first]) + ": time " +
                          formatDouble(in.rows[first][static_cast<std::size_t>(tc)]) + " is not after the start " +
                          formatDouble(out.t0) + " (dropped: before the run)");
  }
  for (std::size_t r = first; r < in.rows.size(); ++r) {
    const double t = in.rows[r][static_cast<std::size_t>(tc)];
    if (r > first || kind == "increments" || t < prev) requireIncreasing(in, r, prev, t);
    Eigen::VectorXd u(width);
    for (std::size_t i = 0; i < cols.size(); ++i) u[static_cast<Eigen::Index>(i)] = in.rows[r][static_cast<std::size_t>(cols[i])];
    if (kind == "increments") {
      out.inputs.push_back({prev, u / (t - prev)});
    } else {
      out.inputs.push_back({t, u});
    }
    prev = t;
  }
  // Increments: a last zero input makes the state at the last row's time.
  if (kind == "increments" && !out.inputs.empty()) out.inputs.push_back({prev, Eigen::VectorXd::Zero(width)});
}

// A model taking packed inputs: the raw rows packed into its steps, one
// ending at every measurement the estimators see (the scores carry a state
// to a withheld fix's time by f, over the first part of a pack).
void packModelInputs(const Model& model, Dataset& out) {
  if (model.readingsPerStep() == 1 || out.inputs.empty()) return;
  std::vector<double> cuts;
  for (const auto& m : out.measurements) cuts.push_back(m.t);
  out.inputs = packInputs(out.inputs, std::move(cuts), model.readingsPerStep(), out.t0);
}

// How a measurement row names its channel: [dataset] channel_column,
// channel_prefix, channel_by.
// channel_column may name several columns (a link named by its tag and its
// anchor): the channel is then prefix + their values joined by '_'.
struct ChannelColumn {
  std::vector<int> columns;  // none: every row is the default channel
  std::string prefix, by;
  static std::string text(double v) {
    return v == std::floor(v) ? std::to_string(static_cast<long long>(v)) : formatDouble(v);
  }
  // The row's channel, or −1 with `problem` set. A log names its few
  // channels again on every row (UWB: 24 links over 323,514 rows): each one
  // is matched by name once, then found by its column values.
  int of(const CsvTable& m, const CsvRows::Row& row, const Model& model, std::string& problem) {
    if (columns.empty()) return 0;
    key.resize(columns.size());
    for (std::size_t i = 0; i < columns.size(); ++i) key[i] = row[static_cast<std::size_t>(columns[i])];
    for (const auto& [values, c] : seen)
      if (values == key) return c;
    const int channel = byName(m, row, model, problem);
    if (channel >= 0) seen.emplace_back(key, channel);
    return channel;
  }

 private:
  std::vector<double> key;                             // this row's channel columns
  std::vector<std::pair<std::vector<double>, int>> seen;  // the column values of each channel found so far
  int byName(const CsvTable& m, const CsvRows::Row& row, const Model& model, std::string& problem) const {
    const double v = row[static_cast<std::size_t>(columns[0])];
    std::string name = by == "index" ? "number " + formatDouble(v) : prefix + text(v);
    for (std::size_t i = 1; i < columns.size(); ++i) name += "_" + text(row[static_cast<std::size_t>(columns[i])]);
    int channel = -1;
    for (int c = 0; c < model.numChannels(); ++c)
      if (by == "index" ? v == c : model.channel(c).name == name) channel = c;
    if (channel < 0) {
      std::string cols, values;
      for (int c : columns) {
        cols += (cols.empty() ? "" : ", ") + m.header[static_cast<std::size_t>(c)];
        values += (values.empty() ? "" : ", ") + formatDouble(row[static_cast<std::size_t>(c)]);
      }
      problem = std::string(columns.size() > 1 ? "columns '" : "column '") + cols + "': '" + values +
                "' names channel '" + name + "', which model '" + model.name() + "' does not have";
    }
    return channel;
  }
};

ChannelColumn channelColumn(const IniDocument& ini, const CsvTable& m) {
  ChannelColumn cc;
  if (ini.has("dataset", "channel_column"))
    for (const auto& name : words(ini.getString("dataset", "channel_column")))
      cc.columns.push_back(requireColumn(m, name, "[dataset] channel_column"));
  cc.prefix = ini.getString("dataset", "channel_prefix", "");
  cc.by = ini.getString("dataset", "channel_by", "name");
  if (cc.by != "name" && cc.by != "index")
    throw InputError(ini.source() + ": [dataset] channel_by = '" + cc.by + "': expected name or index");
  if (cc.by == "index" && cc.columns.size() > 1)
    throw InputError(ini.where("dataset", "channel_column") + ": channel_by = index takes one column");
  return cc;
}

// [dataset] out_of_order: sort (the default: rows that go back in time are
// put in time order, counted) or error (today's strict reading).
bool strictTimeOrder(const IniDocument& ini) {
  const std::string mode = ini.getString("dataset", "out_of_order", "sort");
  if (mode != "sort" && mode != "error")
    throw InputError(ini.where("dataset", "out_of_order") + " = '" + mode + "': expected sort or error");
  return mode == "error";
}

// Measurements: one channel per row, named by a column (or the default).
void readMeasurements(const std::string& path, const IniDocument& ini, const Model& model, Dataset& out,
                      BadRows bad_rows) {
  std::vector<CsvRowError> errors;
  const CsvTable m = readCsv(path, bad_rows == BadRows::Throw ? nullptr : &errors);
  const int tc = requireColumn(m, "t", "the time");
  std::vector<int> cols;
  for (const auto& n : words(ini.getString("dataset", "measurement_columns")))
    cols.push_back(requireColumn(m, n, "[dataset] measurement_columns"));
  ChannelColumn channels = channelColumn(ini, m);
  const double drop_at_or_below = ini.getDouble("dataset", "drop_at_or_below", -std::numeric_limits<double>::infinity());
  const bool strict = strictTimeOrder(ini);
  double latest = -std::numeric_limits<double>::infinity();
  std::size_t next_error = 0;
  out.measurements.reserve(m.rows.size());
  for (std::size_t r = 0; r < m.rows.size(); ++r) {
    const int line = m.line_of_row[r];
    if (bad_rows == BadRows::Stop && next_error < errors.size() && errors[next_error].line < line) break;
    while (next_error < errors.size() && errors[next_error].line < line) ++next_error;
    const auto& row = m.rows[r];
    const double t = row[static_cast<std::size_t>(tc)];
    std::string problem;
    const int channel = channels.of(m, row, model, problem);
    if (problem.empty() && static_cast<int>(cols.size()) != model.channel(channel).dim())
      throw InputError(ini.source() + ": [dataset] measurement_columns names " + std::to_string(cols.size()) +
                       " columns; channel '" + model.channel(channel).name + "' has " +
                       std::to_string(model.channel(channel).dim()) + " components");
    if (problem.empty() && strict && !out.measurements.empty() && t < out.measurements.back().t)
      problem = "column 't': time " + formatDouble(t) + " is before the previous row's " +
                formatDouble(out.measurements.back().t) + " ([dataset] out_of_order = error)";
    if (problem.empty() && !(t > out.t0)) {  // before the run (a log whose truth starts later): dropped, listed
      out.dropped.push_back(m.source + ":" + std::to_string(line) + ": time " + formatDouble(t) +
                            " is not after the start " + formatDouble(out.t0) + " (dropped: before the run)");
      continue;
    }
    if (!problem.empty()) {
      const std::string msg = m.source + ":" + std::to_string(line) + ": " + problem;
      if (bad_rows == BadRows::Throw) throw InputError(msg);
      errors.insert(errors.begin() + static_cast<long>(next_error), {line, msg});
      ++next_error;
      if (bad_rows == BadRows::Stop) break;
      continue;
    }
    Eigen::VectorXd y(static_cast<Eigen::Index>(cols.size()));
    for (std::size_t i = 0; i < cols.size(); ++i) y[static_cast<Eigen::Index>(i)] = row[static_cast<std::size_t>(cols[i])];
    if (y.minCoeff() <= drop_at_or_below) {  // non-physical (a range of 0): an outlier, dropped and counted
      out.dropped.push_back(m.source + ":" + std::to_string(line) + ": value " + formatDouble(y.minCoeff()) +
                            " is at or below [dataset] drop_at_or_below = " + formatDouble(drop_at_or_below) +
                            " (dropped as non-physical)");
      continue;
    }
    if (t < latest) ++out.late_rows, out.max_lateness = std::max(out.max_lateness, latest - t);
    latest = std::max(latest, t);
    out.measurements.push_back({t, y, channel, {}});
  }
  // Rows written late (blocks, buffers): in time order, equal times in file order.
  if (out.late_rows > 0)
    std::stable_sort(out.measurements.begin(), out.measurements.end(),
                     [](const Measurement& a, const Measurement& b) { return a.t < b.t; });
  std::sort(errors.begin(), errors.end(), [](const CsvRowError& a, const CsvRowError& b) { return a.line < b.line; });
  for (const auto& e : errors) {
    out.row_errors.push_back(e.message);
    if (bad_rows == BadRows::Stop) break;
  }
}

// [dataset] constants_reference: a calibration file of the model's own
// columns, turned into the constants it implies along the (raw) truth.
void readConstantsReference(const std::string& path, const IniDocument& ini, const Model& model, Dataset& out) {
  const std::vector<std::string> names = model.referenceColumns();
  if (names.empty())
    throw InputError(ini.where("dataset", "constants_reference") + ": model '" + model.name() +
                     "' reads no calibration reference");
  if (!out.truth) throw InputError(ini.where("dataset", "constants_reference") + ": needs [dataset] truth");
  const CsvTable table = readCsv(path);
  std::vector<int> cols;
  for (const auto& n : names) cols.push_back(requireColumn(table, n, "[dataset] constants_reference"));
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(table.rows.size()), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t r = 0; r < table.rows.size(); ++r)
    for (std::size_t c = 0; c < cols.size(); ++c)
      rows(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = table.rows[r][static_cast<std::size_t>(cols[c])];
  try {
    out.constants_reference = model.referenceConstants(rows, *out.truth);
  } catch (const InputError& e) {
    throw InputError(table.source + ": " + e.what());
  }
}

// Of the times `at` (ascending, by `time`), the nearest to t (the earlier
// on a tie), and its distance to its nearest neighbour there; t and +∞
// when there are none.
template <class T, class Time>
std::pair<double, double> nearestOf(const std::vector<T>& at, double t, Time time) {
  const auto after = std::lower_bound(at.begin(), at.end(), t, [&](const T& a, double x) { return time(a) < x; });
  if (at.empty()) return {t, INFINITY};
  auto k = after == at.end() || (after != at.begin() && t - time(*std::prev(after)) <= time(*after) - t)
               ? std::prev(after) : after;
  double gap = INFINITY;
  if (k != at.begin()) gap = time(*k) - time(*std::prev(k));
  if (std::next(k) != at.end()) gap = std::min(gap, time(*std::next(k)) - time(*k));
  return {time(*k), gap};
}

// Where a zero measurement due at t goes with zero_at_inputs: the input
// reading nearest t, or a measurement within half a reading's interval of
// that reading (its state is then the zero's too).
double zeroTimeAtInputs(const Dataset& d, double t) {
  const auto [reading, interval] = nearestOf(d.inputs, t, [](const Input& u) { return u.t; });
  const double m = nearestOf(d.measurements, reading, [](const Measurement& z) { return z.t; }).first;
  return std::abs(m - reading) < 0.5 * interval ? m : reading;
}

// [dataset] zero_channels = NAMES, zero_rate = Hz: a zero measurement on
// each of those channels every 1/rate s after t0 until the last input or
// measurement (a constraint the model states as a channel: a car's
// non-holonomic velocity), merged in time order with the data. With
// zero_at_inputs, each at the input reading nearest its time, or at a
// measurement next to that reading: a state starts at every measurement,
// so a zero between two readings made one of its own, most within a few ms
// of a step's end (on the GNSS/INS drive 2406 of 5521 steps were under 10
// ms, down to 0.14 ms: a position's process noise ∝ dt³ then dwarfs the
// data's information in rounding, and a batch ending in an outage did not
// factor). A channel whose h reads known values (a vehicle constraint at a
// point off the IMU: the body's rate) gets the mean of the inputs' first
// ones over the zero's interval, t ± 0.5/rate (none without a reading).
void addZeroMeasurements(const IniDocument& ini, const Model& model, Dataset& out) {
  const double rate = ini.getDouble("dataset", "zero_rate", 0.0);
  if (!(rate > 0) || !std::isfinite(rate))
    throw InputError(ini.source() + ": [dataset] zero_channels needs zero_rate, a positive rate (Hz)");
  std::vector<int> channels;
  for (const auto& name : words(ini.getString("dataset", "zero_channels"))) channels.push_back(model.channelIndex(name));
  double end = out.t0;
  if (!out.inputs.empty()) end = std::max(end, out.inputs.back().t);
  if (!out.measurements.empty()) end = std::max(end, out.measurements.back().t);
  const bool at_inputs = ini.getBool("dataset", "zero_at_inputs", false);
  std::vector<Measurement> zeros;
  double last = out.t0;
  for (std::int64_t k = 1;; ++k) {
    double t = out.t0 + static_cast<double>(k) / rate;  // no drift over a long log
    if (t > end) break;
    if (at_inputs) t = zeroTimeAtInputs(out, t);
    if (!(t > last)) continue;  // at or before t0, or two on one reading (a gap in the inputs)
    last = t;
    for (int c : channels) {
      Eigen::VectorXd known;  // a channel that reads the inputs: their mean over the zero's interval
      if (const int k = model.channel(c).regressors; k > 0) {
        auto first = std::lower_bound(out.inputs.begin(), out.inputs.end(), t - 0.5 / rate,
                                      [](const Input& u, double x) { return u.t < x; });
        const int n = sumInputs(first, out.inputs, t + 0.5 / rate, k, known);
        if (n == 0) continue;  // no reading to read
        known /= n;
      }
      zeros.emplace_back(t, Eigen::VectorXd::Zero(model.channel(c).dim()), c, Eigen::MatrixXd(), known);
    }
  }
  std::vector<Measurement> merged;
  merged.reserve(out.measurements.size() + zeros.size());
  std::merge(out.measurements.begin(), out.measurements.end(), zeros.begin(), zeros.end(), std::back_inserter(merged),
             [](const Measurement& a, const Measurement& b) { return a.t < b.t; });
  out.measurements = std::move(merged);
}

// One CSV per sensor stream, as the config's [dataset] describes.
void readStreams(const std::string& dir, const IniDocument& ini, const Model& model, Dataset& out, BadRows bad_rows) {
  ini.requireOnlyKeys("dataset", iniKeyNames(datasetIniKeys()));
  const auto file = [&](const std::string& key) { return (fs::path(dir) / ini.getString("dataset", key)).string(); };
  out.truth.reset();
  if (ini.has("dataset", "truth")) readTruth(file("truth"), ini, model, out);  // first: it may give t0
  out.constants_reference.reset();
  if (ini.has("dataset", "constants_reference")) readConstantsReference(file("constants_reference"), ini, model, out);
  readStartAndRows(ini, out);
  out.inputs.clear();
  out.dropped.clear();
  if (ini.has("dataset", "inputs")) readInputs(file("inputs"), ini, model, out);
  out.measurements.clear();
  out.row_errors.clear();
  out.late_rows = 0;
  out.max_lateness = 0;
  out.withheld.clear();
  out.outages.clear();
  out.gnss_dropped = 0;
  if (ini.has("dataset", "measurements")) readMeasurements(file("measurements"), ini, model, out, bad_rows);
  if (ini.has("dataset", "gnss"))
    readGnssMeasurements(file("gnss"), ini.has("dataset", "gnss_outages") ? file("gnss_outages") : "", ini, model, out);
  if (std::isinf(out.t0))  // start_time = first
    out.t0 = out.measurements.empty() ? 0.0 : out.measurements.front().t - model.nominalStep();
  if (ini.has("dataset", "zero_channels")) addZeroMeasurements(ini, model, out);
  packModelInputs(model, out);
  if (out.truth && ini.getBool("dataset", "truth_interpolate", false)) interpolateTruth(model, out);
}
}  // namespace

std::vector<Measurement> usedOnWithheldChannel(const Dataset& d) {
  std::vector<Measurement> used;
  if (d.withheld.empty()) return used;
  for (const Measurement& m : d.measurements)
    if (m.channel == d.withheld.front().channel) used.push_back(m);
  return used;
}

void readDatasetData(const std::string& dir, const Model& model, Dataset& out, BadRows bad_rows,
                     const IniDocument* config) {
  out.dir = dir;
  if (config && config->hasSection("dataset")) {
    readStreams(dir, *config, model, out, bad_rows);
    return;
  }
  out.row_errors.clear();
  std::vector<CsvRowError> errors;
  const CsvTable m = readCsv((fs::path(dir) / "measurements.csv").string(),
                             bad_rows == BadRows::Throw ? nullptr : &errors);
  checkHeader(m, model.names().measurement);
  out.measurements.clear();
  out.measurements.reserve(m.rows.size());
  // Good rows in file order, with time-order errors found as we go.
  std::size_t next_error = 0;
  for (std::size_t r = 0; r < m.rows.size(); ++r) {
    const int line = m.line_of_row[r];
    if (bad_rows == BadRows::Stop && next_error < errors.size() && errors[next_error].line < line) break;
    const double t = m.rows[r][0];
    if (!out.measurements.empty() && !(t > out.measurements.back().t)) {
      const double prev = out.measurements.back().t;
      const std::string msg = m.source + ":" + std::to_string(line) + ": column 't': time " + formatDouble(t) +
                              (t == prev ? " repeats the previous row's (duplicated timestamp; put several "
                                           "channels in one row)"
                                         : " is before the previous row's " + formatDouble(prev));
      if (bad_rows == BadRows::Throw) throw InputError(msg);
      errors.insert(errors.begin() + static_cast<long>(next_error), {line, msg});
      if (bad_rows == BadRows::Stop) break;
      ++next_error;
      continue;
    }
    while (next_error < errors.size() && errors[next_error].line < line) ++next_error;
    out.measurements.push_back({t, Eigen::Map<const Eigen::VectorXd>(m.rows[r].data() + 1, model.dims().ny)});
  }
  std::sort(errors.begin(), errors.end(), [](const CsvRowError& a, const CsvRowError& b) { return a.line < b.line; });
  for (const auto& e : errors) {
    out.row_errors.push_back(e.message);
    if (bad_rows == BadRows::Stop) break;
  }
  out.inputs.clear();
  const fs::path ip = fs::path(dir) / "inputs.csv";
  if (model.dims().nu > 0) {
    if (!fs::exists(ip))
      throw InputError(ip.string() + ": missing; model '" + model.name() + "' has inputs (" +
                       std::to_string(model.dims().nu) + " columns after t)");
    const CsvTable in = readCsv(ip.string());
    checkTable(in, model.names().input);
    for (const auto& row : in.rows)
      out.inputs.push_back({row[0], Eigen::Map<const Eigen::VectorXd>(row.data() + 1, model.dims().nu)});
  }
  out.truth.reset();
  const fs::path tp = fs::path(dir) / "truth.csv";
  if (fs::exists(tp)) {
    const CsvTable t = readCsv(tp.string());
    checkTable(t, model.stackedStateNames());
    Truth truth;
    const int n = model.dims().nc + model.dims().nb;
    truth.times.reserve(t.rows.size());
    truth.states.reserve(t.rows.size());
    for (const auto& row : t.rows) {
      truth.times.push_back(row[0]);
      truth.states.push_back(Eigen::Map<const Eigen::VectorXd>(row.data() + 1, n));
    }
    out.truth = std::move(truth);
  }
}

SimulatedRun recordedRun(const Model& model, const Dataset& ds) {
  if (!ds.truth) throw InputError(ds.dir + ": no truth.csv: the analysis needs the true trajectory");
  SimulatedRun run;
  const int nc = model.dims().nc, nb = model.dims().nb;
  for (std::size_t k = 0; k < ds.truth->times.size(); ++k) {
    run.times.push_back(ds.truth->times[k]);
    run.states.push_back(ds.truth->states[k].head(nc));
  }
  run.constants = ds.truth->states.front().tail(nb);
  run.measurements = ds.measurements;
  run.inputs = ds.inputs;
  return run;
}

void writeDataset(const std::string& dir, const Model& model, const SimulatedRun& run,
                  const IniDocument& scenario_in) {
  fs::create_directories(dir);
  IniDocument scenario = scenario_in;
  std::vector<std::string> mh{"t"};
  std::vector<std::vector<double>> rows;
  if (model.numChannels() > 1) {
    // Several channels: one row per measurement with its channel's index,
    // described by a [dataset] section (channels of one dimension).
    const int dim = model.channel(0).dim();
    for (int c = 0; c < model.numChannels(); ++c)
      if (model.channel(c).dim() != dim)
        throw InvalidArgument("writeDataset: channels of different dimensions need one file each");
    mh.push_back("channel");
    std::string cols;
    for (int i = 1; i <= dim; ++i) {
      mh.push_back("y" + std::to_string(i));
      cols += (i > 1 ? " y" : "y") + std::to_string(i);
    }
    for (const auto& m : run.measurements) {
      std::vector<double> r{m.t, static_cast<double>(m.channel)};
      r.insert(r.end(), m.y.data(), m.y.data() + m.y.size());
      rows.push_back(std::move(r));
    }
    std::string inputs, truth;
    for (const auto& n : model.names().input) inputs += (inputs.empty() ? "" : " ") + n;
    for (const auto& n : model.stackedStateNames()) truth += (truth.empty() ? "" : " ") + n;
    scenario.set("dataset", "measurements", "measurements.csv");
    scenario.set("dataset", "measurement_columns", cols);
    scenario.set("dataset", "channel_column", "channel");
    scenario.set("dataset", "channel_by", "index");
    if (!run.inputs.empty()) {
      scenario.set("dataset", "inputs", "inputs.csv");
      scenario.set("dataset", "input_columns", inputs);
      scenario.set("dataset", "input_kind", "rates");
    }
    scenario.set("dataset", "truth", "truth.csv");
    scenario.set("dataset", "truth_columns", truth);
  } else {
    for (const auto& n : model.names().measurement) mh.push_back(n);
    for (const auto& m : run.measurements) {
      std::vector<double> r{m.t};
      r.insert(r.end(), m.y.data(), m.y.data() + m.y.size());
      rows.push_back(std::move(r));
    }
  }
  writeCsv((fs::path(dir) / "measurements.csv").string(), mh, rows);

  std::vector<std::string> th{"t"};
  for (const auto& n : model.stackedStateNames()) th.push_back(n);
  rows.clear();
  for (std::size_t k = 0; k < run.states.size(); ++k) {
    std::vector<double> r{run.times[k]};
    r.insert(r.end(), run.states[k].data(), run.states[k].data() + run.states[k].size());
    r.insert(r.end(), run.constants.data(), run.constants.data() + run.constants.size());
    rows.push_back(std::move(r));
  }
  writeCsv((fs::path(dir) / "truth.csv").string(), th, rows);
  if (!run.inputs.empty()) {
    std::vector<std::string> ih{"t"};
    for (const auto& n : model.names().input) ih.push_back(n);
    rows.clear();
    for (const auto& in : run.inputs) {
      std::vector<double> r{in.t};
      r.insert(r.end(), in.u.data(), in.u.data() + in.u.size());
      rows.push_back(std::move(r));
    }
    writeCsv((fs::path(dir) / "inputs.csv").string(), ih, rows);
  }
  scenario.save((fs::path(dir) / "scenario.ini").string());
}

}  // namespace gssm::io
