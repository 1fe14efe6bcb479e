// The C++ half of gssm.campaign: a Monte Carlo scenario built from INI text
// (so it ships to Dask workers as text), one seed at a time
// (runMonteCarloSeed, GIL released) and the summary of seeds in seed order
// (summarizeMonteCarlo) — the same functions gssm-montecarlo's runMonteCarlo
// calls, so a campaign equals it bit for bit however its seeds were spread.
#include "bindings.h"
#include "gssm/analysis/montecarlo.h"
#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/io/ini.h"

namespace gssm::python {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// A scenario, its models and the methods to run, rebuilt from text.
struct PyScenario {
  std::string scenario_ini, estimator_ini;
  std::vector<std::string> method_names;
  int window = 0;  // 0: the scenario's
  io::LoadedScenario loaded;
  MonteCarloOptions options;

  PyScenario(std::string ini, std::string est, std::vector<std::string> methods, int w)
      : scenario_ini(std::move(ini)), estimator_ini(std::move(est)), method_names(std::move(methods)), window(w) {
    const io::IniDocument s = io::IniDocument::parse(scenario_ini, "<scenario>");
    if (estimator_ini.empty()) {
      loaded = io::loadScenario(s);
    } else {
      const io::IniDocument e = io::IniDocument::parse(estimator_ini, "<estimator config>");
      loaded = io::loadScenario(s, &e);
    }
    if (window > 0) loaded.scenario.options.fixed_lag.window = loaded.scenario.options.paper_window.window = window;
    if (!method_names.empty()) {
      options.methods.clear();
      for (const auto& m : method_names) options.methods.push_back(methodFromName(m));
    }
    options.seeds = 1;
    validateMonteCarlo(loaded.scenario, options);
  }
};

py::tuple seedState(const MonteCarloSeedResult& r) {
  py::list methods;
  for (const auto& m : r.methods)
    methods.append(py::make_tuple(static_cast<int>(m.method), m.ok, m.error, m.sq, m.nees, m.nis, m.rmse,
                                  m.final_error));
  return py::make_tuple(r.seed, r.times, methods);
}

MonteCarloSeedResult seedFromState(const py::tuple& t) {
  MonteCarloSeedResult r;
  r.seed = t[0].cast<unsigned>();
  r.times = t[1].cast<std::vector<double>>();
  for (const py::handle h : t[2].cast<py::list>()) {
    const py::tuple m = h.cast<py::tuple>();
    MonteCarloSeedResult::PerMethod p;
    p.method = static_cast<Method>(m[0].cast<int>());
    p.ok = m[1].cast<bool>();
    p.error = m[2].cast<std::string>();
    p.sq = m[3].cast<std::vector<VectorXd>>();
    p.nees = m[4].cast<std::vector<double>>();
    p.nis = m[5].cast<std::vector<double>>();
    p.rmse = m[6].cast<VectorXd>();
    p.final_error = m[7].cast<VectorXd>();
    r.methods.push_back(std::move(p));
  }
  return r;
}

MatrixXd rowsOf(const std::vector<VectorXd>& v) {
  if (v.empty()) return {};
  MatrixXd m(static_cast<Eigen::Index>(v.size()), v.front().size());
  for (std::size_t i = 0; i < v.size(); ++i) m.row(static_cast<Eigen::Index>(i)) = v[i].transpose();
  return m;
}

// The result of `method` (a gssm.Method or its name) on this seed.
const MonteCarloSeedResult::PerMethod& methodResult(const MonteCarloSeedResult& r, const py::object& method) {
  const Method wanted = py::isinstance<py::str>(method) ? methodFromName(method.cast<std::string>()) : method.cast<Method>();
  for (const auto& m : r.methods)
    if (m.method == wanted) return m;
  throw InvalidArgument(std::string("SeedResult: no method '") + methodName(wanted) + "' in this result");
}

bool sameSeedResult(const MonteCarloSeedResult& a, const MonteCarloSeedResult& b) {
  if (a.seed != b.seed || a.times != b.times || a.methods.size() != b.methods.size()) return false;
  for (std::size_t i = 0; i < a.methods.size(); ++i) {
    const auto &x = a.methods[i], &y = b.methods[i];
    if (x.method != y.method || x.ok != y.ok || x.error != y.error || x.sq != y.sq || x.nees != y.nees ||
        x.rmse != y.rmse || x.final_error != y.final_error || x.nis.size() != y.nis.size())
      return false;
    for (std::size_t k = 0; k < x.nis.size(); ++k)  // NaN-aware, bit for bit
      if (!(x.nis[k] == y.nis[k] || (std::isnan(x.nis[k]) && std::isnan(y.nis[k])))) return false;
  }
  return true;
}

void bindSeedResult(py::module_& c) {
  py::class_<MonteCarloSeedResult>(c, "SeedResult", "One seed's run estimated by every method (picklable).")
      .def_readonly("seed", &MonteCarloSeedResult::seed)
      .def_property_readonly("times", [](const MonteCarloSeedResult& r) { return toArray(r.times); })
      .def_property_readonly("methods",
                             [](const MonteCarloSeedResult& r) {
                               std::vector<std::string> out;
                               for (const auto& m : r.methods) out.push_back(methodName(m.method));
                               return out;
                             })
      .def(
          "rmse",
          [](const MonteCarloSeedResult& r, const py::object& method) -> py::object {
            const auto& m = methodResult(r, method);
            return m.ok ? py::cast(m.rmse) : py::none();
          },
          py::arg("method"))
      .def(
          "error", [](const MonteCarloSeedResult& r, const py::object& method) { return methodResult(r, method).error; },
          py::arg("method"), "what the method threw on this seed ('' if it ran)")
      .def(py::pickle(&seedState, &seedFromState))
      .def("__eq__", &sameSeedResult);
}

void bindSummaries(py::module_& c) {
  py::class_<MethodSummary>(c, "MethodSummary", "One method's row of the Monte Carlo table, with its curves.")
      .def_property_readonly("method", [](const MethodSummary& m) { return std::string(methodName(m.method)); })
      .def_readonly("mean_rmse", &MethodSummary::mean_rmse)
      .def_readonly("rms_final_error", &MethodSummary::rms_final_error)
      .def_readonly("mean_nees", &MethodSummary::mean_nees)
      .def_readonly("nees_step_in_interval", &MethodSummary::nees_step_in_interval)
      .def_readonly("beats_ekf", &MethodSummary::beats_ekf)
      .def_property_readonly("times", [](const MethodSummary& m) { return toArray(m.times); })
      .def_property_readonly("rmse_over_time", [](const MethodSummary& m) { return rowsOf(m.rmse_over_time); },
                             "(steps, n)")
      .def_readonly("consistency", &MethodSummary::consistency)
      .def_readonly("mean_nis", &MethodSummary::mean_nis)
      .def_readonly("nis_consistency", &MethodSummary::nis_consistency)
      .def_readonly("nis_step_in_interval", &MethodSummary::nis_step_in_interval)
      .def_readonly("failures", &MethodSummary::failures)
      .def_readonly("first_failure", &MethodSummary::first_failure);

  py::class_<MonteCarloResult>(c, "MonteCarloResult", "The Monte Carlo table of one scenario.")
      .def_readonly("scenario", &MonteCarloResult::scenario)
      .def_readonly("seeds", &MonteCarloResult::seeds)
      .def_readonly("steps", &MonteCarloResult::steps)
      .def_readonly("dof", &MonteCarloResult::dof)
      .def_readonly("nees_lo", &MonteCarloResult::nees_lo)
      .def_readonly("nees_hi", &MonteCarloResult::nees_hi)
      .def_readonly("nis_dof", &MonteCarloResult::nis_dof)
      .def_readonly("nis_lo", &MonteCarloResult::nis_lo)
      .def_readonly("nis_hi", &MonteCarloResult::nis_hi)
      .def_readonly("state_names", &MonteCarloResult::state_names)
      .def_readonly("methods", &MonteCarloResult::methods)
      .def_readwrite("seconds", &MonteCarloResult::seconds)
      .def("markdown", &MonteCarloResult::markdown, "the Markdown table gssm-montecarlo writes");
}

void bindScenario(py::module_& c) {
  py::class_<PyScenario, std::shared_ptr<PyScenario>>(c, "Scenario",
                                                      "A Monte Carlo scenario from scenario.ini text (picklable).")
      .def(py::init<std::string, std::string, std::vector<std::string>, int>(), py::arg("scenario_ini"),
           py::arg("estimator_ini") = "", py::arg("methods") = std::vector<std::string>{}, py::arg("window") = 0)
      .def_property_readonly("name", [](const PyScenario& s) { return s.loaded.scenario.name; })
      .def_property_readonly("methods",
                             [](const PyScenario& s) {
                               std::vector<std::string> out;
                               for (auto m : s.options.methods) out.push_back(methodName(m));
                               return out;
                             })
      .def_property_readonly("steps", [](const PyScenario& s) { return s.loaded.scenario.spec.steps; })
      .def(
          "run_seed",
          [](const PyScenario& s, unsigned seed) {
            py::gil_scoped_release release;
            return runMonteCarloSeed(s.loaded.scenario, s.options, seed, simulationSampler(seed));
          },
          py::arg("seed"), "simulate seed `seed` (MRPT's generator, as gssm-montecarlo) and run every method")
      .def(
          "summarize",
          [](const PyScenario& s, const std::vector<MonteCarloSeedResult>& results) {
            MonteCarloOptions o = s.options;
            o.seeds = static_cast<int>(results.size());
            o.first_seed = results.empty() ? 1 : results.front().seed;
            return summarizeMonteCarlo(s.loaded.scenario, o, results);
          },
          py::arg("results"), "the table of consecutive seeds' results, given in seed order")
      .def(
          "run_local",
          [](const PyScenario& s, int seeds, unsigned first_seed, int threads) {
            MonteCarloOptions o = s.options;
            o.seeds = seeds;
            o.first_seed = first_seed;
            o.threads = threads;
            py::gil_scoped_release release;
            return runMonteCarlo(s.loaded.scenario, o, simulationSampler);
          },
          py::arg("seeds"), py::arg("first_seed") = 1, py::arg("threads") = 1,
          "the whole campaign in this process (gssm-montecarlo's runMonteCarlo)")
      .def(py::pickle(
          [](const PyScenario& s) {
            return py::make_tuple(s.scenario_ini, s.estimator_ini, s.method_names, s.window);
          },
          [](const py::tuple& t) {
            return std::make_shared<PyScenario>(t[0].cast<std::string>(), t[1].cast<std::string>(),
                                                t[2].cast<std::vector<std::string>>(), t[3].cast<int>());
          }));
}
}  // namespace

void bindCampaign(py::module_& c) {
  bindSeedResult(c);
  bindSummaries(c);
  bindScenario(c);
}

}  // namespace gssm::python
