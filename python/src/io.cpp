// gssm.io: datasets as NumPy arrays. Reading goes through the same
// io::readScenario / io::makeModel / io::readDatasetData as gssm-process
// (every layout it reads); simulation through the built-in scenarios and
// MRPT's seeded generator, as gssm-simulate (same seed, same bytes).
#include <mrpt/random/RandomGenerators.h>

#include "bindings.h"
#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/io/ini_keys.h"
#include "gssm/io/ini.h"
#include "gssm/model/registry.h"
#include "gssm/model/simulation.h"

namespace gssm::python {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

MatrixXd stackRows(const std::vector<VectorXd>& rows, const char* what) {
  if (rows.empty()) return MatrixXd(0, 0);
  const Eigen::Index n = rows.front().size();
  MatrixXd m(static_cast<Eigen::Index>(rows.size()), n);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != n)
      throw InvalidArgument(std::string(what) + ": rows of different sizes (channels of different dimensions); " +
                            "use Dataset.measurements for them one by one");
    m.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
  }
  return m;
}

PyDataset simulateScenario(const std::string& name, unsigned seed, int steps) {
  PyDataset out;
  out.data.scenario = io::builtinScenario(name, seed, steps);
  out.model = std::shared_ptr<Model>(io::makeModel(out.data.scenario));
  out.simulated = std::make_shared<SimulatedRun>(
      simulate(*out.model, io::simulationSpec(out.data.scenario, *out.model), simulationSampler(seed)));
  return out;
}

void fillFromSimulation(PyDataset& d) {
  const SimulatedRun& run = *d.simulated;
  d.data.measurements = run.measurements;
  d.data.inputs = run.inputs;
  d.data.truth = run.truth();
  d.data.t0 = run.times.empty() ? 0.0 : run.times.front();
  const std::string rows = d.data.scenario.getString("dataset", "rows", "measurements");
  d.data.rows = rowTimesNamed(rows).value_or(RowTimes::Measurements);
}

PyDataset datasetFromArrays(const VectorXd& t, const MatrixXd& y, const std::optional<Eigen::VectorXi>& channel,
                            const std::optional<VectorXd>& input_t, const std::optional<MatrixXd>& u,
                            const std::optional<VectorXd>& truth_t, const std::optional<MatrixXd>& truth_x,
                            const std::vector<int>& truth_components, double t0, bool rows_at_inputs,
                            std::shared_ptr<Model> model) {
  PyDataset d;
  const Eigen::Index N = t.size();
  // A 1-D y of N values is N scalar measurements.
  MatrixXd Y = (y.cols() == N && y.rows() == 1 && N != 1) ? MatrixXd(y.transpose()) : y;
  if (Y.rows() != N)
    throw InvalidArgument("from_arrays: t has " + std::to_string(N) + " entries but y has " + std::to_string(Y.rows()) +
                          " rows");
  if (channel && channel->size() != N)
    throw InvalidArgument("from_arrays: channel has " + std::to_string(channel->size()) + " entries, t has " +
                          std::to_string(N));
  for (Eigen::Index i = 0; i < N; ++i)
    d.data.measurements.emplace_back(t[i], VectorXd(Y.row(i).transpose()), channel ? (*channel)[i] : 0);
  if (input_t || u) {
    if (!input_t || !u || u->rows() != input_t->size())
      throw InvalidArgument("from_arrays: input_t (M,) and u (M, n_u) go together");
    for (Eigen::Index i = 0; i < input_t->size(); ++i) d.data.inputs.push_back({(*input_t)[i], VectorXd(u->row(i).transpose())});
  }
  if (truth_t || truth_x) {
    if (!truth_t || !truth_x || truth_x->rows() != truth_t->size())
      throw InvalidArgument("from_arrays: truth_t (K,) and truth_x (K, m) go together");
    Truth tr;
    for (Eigen::Index i = 0; i < truth_t->size(); ++i) {
      tr.times.push_back((*truth_t)[i]);
      tr.states.emplace_back(truth_x->row(i).transpose());
    }
    tr.components = truth_components;
    d.data.truth = std::move(tr);
  }
  d.data.t0 = t0;
  d.data.rows = rows_at_inputs ? RowTimes::Inputs : RowTimes::Measurements;
  d.model = std::move(model);
  return d;
}

PyDataset readDatasetFolder(const std::string& dir, const std::string& config, const std::string& bad_rows) {
  io::BadRows mode = io::BadRows::Throw;
  if (bad_rows == "stop") mode = io::BadRows::Stop;
  else if (bad_rows == "skip") mode = io::BadRows::Skip;
  else if (bad_rows != "raise")
    throw InvalidArgument("read_dataset: bad_rows '" + bad_rows + "': expected raise, stop or skip");
  PyDataset d;
  const io::IniDocument ini = io::readScenario(dir, config);
  d.model = std::shared_ptr<Model>(io::makeModel(ini, dir));
  io::readDatasetData(dir, *d.model, d.data, mode, &ini);
  d.data.scenario = ini;
  return d;
}

PyDataset simulateModel(std::shared_ptr<Model> model, unsigned seed, int steps, const std::optional<VectorXd>& x0,
                        const std::optional<VectorXd>& xb, int measure_every, const std::vector<py::object>& channels) {
  if (steps < 1) throw InvalidArgument("simulate: steps must be >= 1");
  PyDataset d;
  d.model = model;
  SimulationSpec spec;
  spec.steps = steps;
  spec.x0 = x0;
  spec.xb = xb;
  spec.measure_every = measure_every;
  if (!channels.empty()) {
    spec.channels.clear();
    for (const auto& c : channels)
      spec.channels.push_back(py::isinstance<py::str>(c) ? model->channelIndex(c.cast<std::string>()) : c.cast<int>());
  }
  d.simulated = std::make_shared<SimulatedRun>(simulate(*model, spec, simulationSampler(seed)));
  if (modelTypeOf(*model)) io::writeModel(*model, d.data.scenario);  // a registered type has an INI form
  fillFromSimulation(d);
  return d;
}

EstimatorOptions datasetOptions(const PyDataset& d, const std::string& method, std::shared_ptr<Model> model) {
  if (!model) model = d.model;
  if (!model) throw InvalidArgument("Dataset.options: the dataset has no model; pass model=");
  EstimatorOptions o = io::estimatorOptions(d.data.scenario, *model, methodFromName(method));
  o.t0 = d.data.t0;
  return o;
}

}  // namespace

NormalSampler simulationSampler(unsigned seed) {
  auto rng = std::make_shared<mrpt::random::CRandomGenerator>(seed);
  return [rng] { return rng->drawGaussian1D_normalized(); };
}

namespace {
void bindDataset(py::module_& io) {
  py::class_<PyDataset>(io, "Dataset",
                        "Measurements (with channels), inputs and optional truth of one run, with the model and "
                        "settings of its scenario.ini when it came from a folder or a simulation.")
      .def_property_readonly("t", [](const PyDataset& d) { return timesOf(d.data.measurements); },
                             "(N,) measurement times")
      .def_property_readonly("y",
                             [](const PyDataset& d) {
                               std::vector<VectorXd> rows;
                               for (const auto& m : d.data.measurements) rows.push_back(m.y);
                               return stackRows(rows, "Dataset.y");
                             }, "(N, n_y) measurements")
      .def_property_readonly("channel",
                             [](const PyDataset& d) {
                               Eigen::VectorXi c(static_cast<Eigen::Index>(d.data.measurements.size()));
                               for (std::size_t i = 0; i < d.data.measurements.size(); ++i)
                                 c[static_cast<Eigen::Index>(i)] = d.data.measurements[i].channel;
                               return c;
                             }, "(N,) channel index of each measurement")
      .def_property_readonly("measurements",
                             [](const PyDataset& d) {
                               py::list out;
                               for (const auto& m : d.data.measurements)
                                 out.append(py::make_tuple(m.t, m.y, m.channel));
                               return out;
                             }, "[(t, y, channel), ...]")
      .def_property_readonly("input_t", [](const PyDataset& d) { return timesOf(d.data.inputs); },
                             "(M,) input times")
      .def_property_readonly("u",
                             [](const PyDataset& d) {
                               std::vector<VectorXd> rows;
                               for (const auto& u : d.data.inputs) rows.push_back(u.u);
                               return stackRows(rows, "Dataset.u");
                             }, "(M, n_u) inputs")
      .def_property_readonly("has_truth", [](const PyDataset& d) { return d.data.truth.has_value(); })
      .def_property_readonly("truth_t",
                             [](const PyDataset& d) -> py::object {
                               if (!d.data.truth) return py::none();
                               return toArray(d.data.truth->times);
                             }, "(K,) truth times, or None")
      .def_property_readonly("truth_x",
                             [](const PyDataset& d) -> py::object {
                               if (!d.data.truth) return py::none();
                               return py::cast(stackRows(d.data.truth->states, "Dataset.truth_x"));
                             }, "(K, m) true values of the components truth_components, or None")
      .def_property_readonly("truth_components",
                             [](const PyDataset& d) -> py::object {
                               if (!d.data.truth) return py::none();
                               if (!d.data.truth->components.empty()) return py::cast(d.data.truth->components);
                               std::vector<int> all;
                               const auto n = d.data.truth->states.empty() ? 0 : d.data.truth->states.front().size();
                               for (int i = 0; i < n; ++i) all.push_back(i);
                               return py::cast(all);
                             }, "the stacked components truth_x gives")
      .def_property_readonly("t0", [](const PyDataset& d) { return d.data.t0; }, "time of x_c(0)")
      .def_property_readonly("rows_at_inputs", [](const PyDataset& d) { return d.data.rows == RowTimes::Inputs; },
                             "estimates are reported at the input times (odometry-driven logs)")
      .def_property_readonly("dir", [](const PyDataset& d) { return d.data.dir; })
      .def_property_readonly("model", [](const PyDataset& d) { return d.model; },
                             "the model its scenario.ini describes (None for a dataset from arrays)")
      .def_property_readonly("scenario", [](const PyDataset& d) { return d.data.scenario.toString(); },
                             "its scenario.ini text")
      .def_property_readonly("row_errors", [](const PyDataset& d) { return d.data.row_errors; },
                             "bad rows skipped or stopped at (bad_rows='skip' or 'stop')")
      .def("options", &datasetOptions, py::arg("method") = "fixed-lag", py::arg("model") = nullptr,
          "the settings gssm-process uses on this dataset for `method` (its INI sections, its t0)")
      .def("__len__", [](const PyDataset& d) { return d.data.measurements.size(); })
      .def("__repr__", [](const PyDataset& d) {
        return "<gssm.io.Dataset " + (d.data.dir.empty() ? std::string("(arrays)") : d.data.dir) + ": " +
               std::to_string(d.data.measurements.size()) + " measurements, " + std::to_string(d.data.inputs.size()) +
               " inputs" + (d.data.truth ? ", truth" : "") + (d.model ? ", model " + d.model->name() : "") + ">";
      });

}

void bindDatasetFiles(py::module_& io) {
  io.def("from_arrays", &datasetFromArrays,
      py::arg("t"), py::arg("y"), py::arg("channel") = py::none(), py::arg("input_t") = py::none(),
      py::arg("u") = py::none(), py::arg("truth_t") = py::none(), py::arg("truth_x") = py::none(),
      py::arg("truth_components") = std::vector<int>{}, py::arg("t0") = 0.0, py::arg("rows_at_inputs") = false,
      py::arg("model") = nullptr,
      "A dataset from arrays: t (N,), y (N, n_y) or (N,), optional channel (N,), inputs, truth.");

  io.def("read_dataset", &readDatasetFolder,
      py::arg("dir"), py::arg("config") = "", py::arg("bad_rows") = "raise",
      "A dataset folder (scenario.ini, measurements, optional inputs and truth; every layout gssm-process "
      "reads). config: an INI file to use instead of its scenario.ini. bad_rows: 'raise' (gssm.InputError "
      "naming file:line:column), 'stop' (keep the rows before it) or 'skip'.");

  io.def(
      "write_dataset",
      [](const std::string& dir, const PyDataset& d) {
        if (!d.model) throw InvalidArgument("write_dataset: the dataset has no model (read or simulate one)");
        const SimulatedRun run = d.simulated ? *d.simulated : io::recordedRun(*d.model, d.data);
        io::writeDataset(dir, *d.model, run, d.data.scenario);
      },
      py::arg("dir"), py::arg("data"),
      "Writes measurements.csv, truth.csv, inputs.csv and scenario.ini as gssm-simulate does.");

  io.def("ini_option_keys", &io::estimatorIniKeys,
         "[(section, [keys])] of every estimator section of a scenario.ini, as the INI reader takes them");
  io.def("ini_reference", &io::iniReferenceMarkdown,
         "The INI reference (Markdown): every section and key the readers accept, with type, default and meaning");
}

void bindSimulation(py::module_& io) {
  io.def("scenarios", &io::scenarioNames, "the built-in scenario names");
  io.def(
      "scenario_ini", [](const std::string& name, unsigned seed, int steps) {
        return io::builtinScenario(name, seed, steps).toString();
      },
      py::arg("name"), py::arg("seed") = 1, py::arg("steps") = 400, "a built-in scenario's scenario.ini text");

  io.def(
      "simulate_scenario",
      [](const std::string& name, unsigned seed, int steps) {
        PyDataset d = simulateScenario(name, seed, steps);
        fillFromSimulation(d);
        return d;
      },
      py::arg("scenario") = "paper", py::arg("seed") = 1, py::arg("steps") = 400,
      "A built-in scenario simulated with seed (the bytes gssm-simulate writes for the same arguments).");

  io.def("simulate_model", &simulateModel,
      py::arg("model"), py::arg("seed") = 1, py::arg("steps") = 400, py::arg("x0") = py::none(),
      py::arg("xb") = py::none(), py::arg("measure_every") = 1, py::arg("channels") = std::vector<py::object>{},
      "A run of `model` simulated with seed (x0, xb drawn from the priors unless given); channels: the "
      "channels (names or indices) measured in turn (default: the first).");
}
}  // namespace

void bindIo(py::module_& io) {
  bindDataset(io);
  bindDatasetFiles(io);
  bindSimulation(io);
}

}  // namespace gssm::python
