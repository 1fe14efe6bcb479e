// gssm.process: the offline dataset processor in this process
// (io::processDataset, as gssm-process runs it), and gssm.Method: the
// method table as an enum, so Python dispatches on values, not on text.
#include <cctype>

#include "bindings.h"
#include "gssm/core/error.h"

namespace gssm::python {

namespace {

// "fixed-lag" → "FIXED_LAG": the enum's value name.
std::string enumName(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '-' ? '_' : static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

void bindMethod(py::module_& m) {
  py::enum_<Method> e(m, "Method", "The estimation methods (gssm.methods() gives their names as gssm-process takes them).");
  for (const auto& info : methods()) e.value(enumName(info.name).c_str(), info.method);
  e.def_property_readonly("text", [](Method x) { return std::string(methodName(x)); }, "its name: 'fixed-lag'")
      .def_property_readonly("label", [](Method x) { return std::string(methodInfo(x).label); })
      .def_property_readonly("streaming", [](Method x) { return methodInfo(x).streaming; },
                             "False for the batch solver, which needs the whole run")
      .def_static("named", &methodFromName, py::arg("text"), "the method called `text` ('fixed-lag')");
}

io::ProcessOptions processOptions(const std::string& data, const std::string& out, const std::vector<Method>& methods,
                                  const std::string& config, std::optional<int> window,
                                  std::size_t checkpoint_every, const std::string& resume, bool skip_bad_rows,
                                  std::optional<bool> learn) {
  io::ProcessOptions o;
  o.data_dir = data;
  o.out_dir = out;
  o.config = config;
  o.methods = methods;
  o.window = window;
  o.checkpoint_every = checkpoint_every;
  o.resume = resume;
  o.skip_bad_rows = skip_bad_rows;
  o.learn = learn;
  return o;
}

PyProcessResult process(const std::string& data, const std::string& out, const std::vector<Method>& methods,
                        const std::string& config, std::optional<int> window, std::size_t checkpoint_every,
                        const std::string& resume, bool skip_bad_rows, const py::object& progress,
                        std::optional<bool> learn, std::size_t threads) {
  io::ProcessOptions o =
      processOptions(data, out, methods, config, window, checkpoint_every, resume, skip_bad_rows, learn);
  o.threads = threads;
  io::ProcessCallbacks cb;
  if (!progress.is_none())  // from whichever thread runs the method (one at a time): take the GIL
    cb.progress = [&progress](Method m, std::size_t done, std::size_t total) {
      py::gil_scoped_acquire gil;
      progress(m, done, total);
    };
  PyProcessResult r;
  py::gil_scoped_release release;  // the models an INI describes are C++
  r.result = std::make_shared<io::ProcessResult>(io::processDataset(o, cb));
  return r;
}

std::vector<PyRun> runsOf(const PyProcessResult& r) {
  std::vector<PyRun> out;
  for (const auto& run : r.result->runs) out.push_back({run, r.result->model->stackedStateNames()});
  return out;
}

void bindProcessResult(py::module_& m) {
  py::class_<PyProcessResult>(m, "ProcessResult", "What gssm.process ran and wrote.")
      .def_property_readonly("runs", &runsOf, "one gssm.Run per method, in order")
      .def_property_readonly("methods", [](const PyProcessResult& r) {
        std::vector<Method> out;
        for (const auto& run : r.result->runs) out.push_back(run.method);
        return out;
      })
      .def_property_readonly("model", [](const PyProcessResult& r) { return std::const_pointer_cast<Model>(r.result->model); })
      .def_property_readonly("metrics_json", [](const PyProcessResult& r) { return r.result->metrics_json; },
                             "metrics.json as written")
      .def_property_readonly("files", [](const PyProcessResult& r) { return r.result->files; }, "the files written")
      .def_property_readonly("label", [](const PyProcessResult& r) { return r.result->label; })
      .def_property_readonly("partial", [](const PyProcessResult& r) { return r.result->status.partial; },
                             "a bad row stopped it (what came before was processed and written)")
      .def_property_readonly("stopped_at", [](const PyProcessResult& r) { return r.result->status.stopped_at; })
      .def_property_readonly("skipped", [](const PyProcessResult& r) { return r.result->status.skipped; })
      .def_property_readonly("learnt", [](const PyProcessResult& r) -> py::object {
        return r.result->learnt ? py::cast(*r.result->learnt) : py::none();
      }, "the noise learning's gssm.LearnReport, when it ran")
      .def_property_readonly("learnt_batch", [](const PyProcessResult& r) -> py::object {
        return r.result->learnt_batch ? py::cast(*r.result->learnt_batch) : py::none();
      }, "the batch's own noise ([learn] batch_likelihood_spacing), when learnt: its gssm.LearnReport")
      .def("_add_files", [](PyProcessResult& r, const std::vector<std::string>& f) {
        r.result->files.insert(r.result->files.end(), f.begin(), f.end());
      })
      .def("__repr__", [](const PyProcessResult& r) {
        return "<gssm.ProcessResult " + r.result->label + ": " + std::to_string(r.result->runs.size()) + " runs, " +
               std::to_string(r.result->files.size()) + " files" + (r.result->status.partial ? ", partial" : "") + ">";
      });
}
}  // namespace

void bindProcess(py::module_& m) {
  bindMethod(m);
  bindProcessResult(m);
  m.def("process_dataset", &process, py::arg("data"), py::arg("out"), py::arg("methods"), py::arg("config") = "",
        py::arg("window") = py::none(), py::arg("checkpoint_every") = 0, py::arg("resume") = "",
        py::arg("skip_bad_rows") = false, py::arg("progress") = py::none(), py::arg("learn") = py::none(),
        py::arg("threads") = 1,
        "gssm.process without keyword conveniences");
}

}  // namespace gssm::python
