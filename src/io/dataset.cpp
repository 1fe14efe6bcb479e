#include "gssm/io/dataset.h"

#include <algorithm>
#include <filesystem>

#include "gssm/core/error.h"
#include "gssm/io/csv.h"

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

IniDocument readScenario(const std::string& dir, const std::string& config_override) {
  const std::string path = config_override.empty() ? (fs::path(dir) / "scenario.ini").string()
                                                   : config_override;
  return IniDocument::load(path);
}

void readDatasetData(const std::string& dir, const Model& model, Dataset& out, BadRows bad_rows) {
  out.dir = dir;
  out.row_errors.clear();
  std::vector<CsvRowError> errors;
  const CsvTable m = readCsv((fs::path(dir) / "measurements.csv").string(),
                             bad_rows == BadRows::Throw ? nullptr : &errors);
  checkHeader(m, model.names().measurement);
  out.measurements.clear();
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
                  const IniDocument& scenario) {
  fs::create_directories(dir);
  std::vector<std::string> mh{"t"};
  for (const auto& n : model.names().measurement) mh.push_back(n);
  std::vector<std::vector<double>> rows;
  for (const auto& m : run.measurements) {
    std::vector<double> r{m.t};
    r.insert(r.end(), m.y.data(), m.y.data() + m.y.size());
    rows.push_back(std::move(r));
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
