// gssm.learn: noise learnt from a log (docs/DESIGN.md §10), over a model and
// a dataset, or over a dataset folder (what gssm-learn runs).
#include "bindings.h"
#include "gssm/core/error.h"
#include "gssm/io/learn_config.h"
#include "gssm/learn/noise_learning.h"

namespace gssm::python {

namespace {
void bindReport(py::module_& m) {
  py::class_<LearntParameter>(m, "LearntParameter", "One learnt σ: its start, value and standard error.")
      .def_property_readonly("name", &LearntParameter::name, "'range_sd', 'Q[1]', 'channel.gps R[0]'")
      .def_readonly("section", &LearntParameter::section)
      .def_readonly("key", &LearntParameter::key)
      .def_readonly("index", &LearntParameter::index, "diagonal entry of a matrix; -1 for a σ")
      .def_readonly("given", &LearntParameter::given, "the model's σ before learning")
      .def_readonly("start", &LearntParameter::start)
      .def_readonly("value", &LearntParameter::value, "the learnt σ")
      .def_readonly("standard_error", &LearntParameter::standard_error, "NaN where the log does not determine it")
      .def_readonly("identifiable", &LearntParameter::identifiable)
      .def_readonly("note", &LearntParameter::note, "why it is flagged")
      .def_readonly("method", &LearntParameter::method,
                    "'likelihood' (the EKF's prediction errors) or 'em' (a σ of the constants' prior)")
      .def("__repr__", [](const LearntParameter& p) {
        return "<gssm.LearntParameter " + p.name() + " = " + std::to_string(p.value) + ">";
      });
  py::class_<NoiseLearningReport>(m, "LearnReport", "What gssm.learn found.")
      .def_readonly("parameters", &NoiseLearningReport::parameters)
      .def_property_readonly("log_likelihood", [](const NoiseLearningReport& r) { return toArray(r.log_likelihood); },
                             "the best log-likelihood after each iteration (never decreasing)")
      .def_readonly("given_log_likelihood", &NoiseLearningReport::given_log_likelihood)
      .def_readonly("start_log_likelihood", &NoiseLearningReport::start_log_likelihood)
      .def_readonly("final_log_likelihood", &NoiseLearningReport::final_log_likelihood)
      .def_readonly("evaluations", &NoiseLearningReport::evaluations, "EKF passes")
      .def_readonly("optimizer", &NoiseLearningReport::optimizer, "'nelder-mead' or 'scoring'")
      .def_readonly("iterations", &NoiseLearningReport::iterations)
      .def_readonly("restarts", &NoiseLearningReport::restarts)
      .def_readonly("converged", &NoiseLearningReport::converged)
      .def_readonly("prior_iterations", &NoiseLearningReport::prior_iterations,
                    "EM's E-steps (batch solves) for the constants' prior; 0: none learnt")
      .def_readonly("prior_converged", &NoiseLearningReport::prior_converged)
      .def_readonly("seconds", &NoiseLearningReport::seconds)
      .def_property_readonly("model", [](const NoiseLearningReport& r) { return std::const_pointer_cast<Model>(r.model); },
                             "the learnt model")
      .def_property_readonly("params", [](const NoiseLearningReport& r) { return modelParams(*r.model); },
                             "the learnt model's parameters, as its class's keywords")
      .def("__str__", &NoiseLearningReport::toString);
}

NoiseLearningOptions learnOptions(const std::vector<std::string>& parameters, double start, double search_range,
                                  int max_evaluations, double tolerance, int max_restarts, bool standard_errors,
                                  const std::string& optimizer) {
  NoiseLearningOptions o;
  o.parameters = parameters, o.start = start, o.search_range = search_range, o.max_evaluations = max_evaluations;
  o.tolerance = tolerance, o.max_restarts = max_restarts, o.standard_errors = standard_errors;
  o.optimizer = optimizer;
  return o;
}
}  // namespace

void bindLearn(py::module_& m) {
  bindReport(m);
  m.def(
      "_learn_model",
      [](const std::shared_ptr<Model>& model, const PyDataset& d, const std::vector<std::string>& parameters,
         double start, double search_range, int max_evaluations, double tolerance, int max_restarts,
         bool standard_errors, const std::string& optimizer, int threads) {
        NoiseLearningOptions o = learnOptions(parameters, start, search_range, max_evaluations, tolerance,
                                              max_restarts, standard_errors, optimizer);
        o.threads = o.batch.threads = threads;
        py::gil_scoped_release release;  // registered models are C++ (a Python model has no registered type)
        return learnNoise(*model, d.data.measurements, d.data.inputs, d.data.t0, o);
      },
      py::arg("model"), py::arg("data"), py::arg("parameters"), py::arg("start"), py::arg("search_range"),
      py::arg("max_evaluations"), py::arg("tolerance"), py::arg("max_restarts"), py::arg("standard_errors"),
      py::arg("optimizer"), py::arg("threads"));
  m.def(
      "_learn_family",
      [](const py::function& make, const std::vector<std::string>& names, const Eigen::VectorXd& given,
         const PyDataset& d, double start, double search_range, int max_evaluations, double tolerance,
         int max_restarts, bool standard_errors, const std::string& optimizer) {
        NoiseFamily family;
        family.names = names;
        family.given = given;
        // Called with the GIL held: a Python model's f and h are Python too.
        family.make = [&make](const Eigen::VectorXd& sigmas) -> std::shared_ptr<const Model> {
          auto model = make(sigmas).cast<std::shared_ptr<Model>>();
          if (!model) throw InvalidArgument("gssm.learn: the model factory returned None");
          return model;
        };
        // one pass at a time: the factory and the models' f and h take the GIL
        const NoiseLearningOptions o = learnOptions({}, start, search_range, max_evaluations, tolerance, max_restarts,
                                                    standard_errors, optimizer);
        return learnNoise(family, d.data.measurements, d.data.inputs, d.data.t0, o);
      },
      py::arg("make"), py::arg("names"), py::arg("given"), py::arg("data"), py::arg("start"), py::arg("search_range"),
      py::arg("max_evaluations"), py::arg("tolerance"), py::arg("max_restarts"), py::arg("standard_errors"),
      py::arg("optimizer"));
  m.def(
      "_learn_folder",
      [](const std::string& data, const std::string& out, const std::string& config) {
        py::gil_scoped_release release;
        return io::learnDataset(data, out, config).report;
      },
      py::arg("data"), py::arg("out"), py::arg("config"));
}

}  // namespace gssm::python
