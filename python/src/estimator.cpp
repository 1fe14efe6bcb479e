// The streaming estimator (makeEstimator), its options and report, offline
// runs over whole arrays (runOffline: the loop in C++, the GIL released for
// C++ models), and checkpoints to files, bytes and pickle.
#include <pybind11/functional.h>

#include <cmath>
#include <sstream>

#include "bindings.h"
#include "gssm/estimator/option_keys.h"
#include "gssm/analysis/offline.h"
#include "gssm/checkpoint/checkpoint.h"
#include "gssm/core/error.h"
#include "gssm/io/config.h"

namespace gssm::python {

Method methodFromName(const std::string& name) {
  if (auto m = methodNamed(name)) return *m;
  throw InvalidArgument("method '" + name + "': expected one of " + methodNameList());
}

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// An estimator with the model it runs on kept alive.
struct PyEstimator {
  std::shared_ptr<const Model> model;
  std::unique_ptr<Estimator> est;
};

int channelOf(const Model& model, const py::object& channel) {
  if (channel.is_none()) return 0;
  if (py::isinstance<py::str>(channel)) return model.channelIndex(channel.cast<std::string>());
  const int c = channel.cast<int>();
  if (c < 0 || c >= model.numChannels())
    throw InvalidArgument("channel " + std::to_string(c) + " out of range: the model '" + model.name() + "' has " +
                          std::to_string(model.numChannels()) + " channel(s)");
  return c;
}

EliminationOrdering orderingFromName(const std::string& s) {
  if (const auto o = orderingNamed(s)) return *o;
  throw InvalidArgument("ordering '" + s + "': expected colamd or time");
}

py::array_t<double> stack(const std::vector<EstimateRow>& rows, Eigen::Index n, bool sd) {
  py::array_t<double> a({static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(n)});
  auto v = a.mutable_unchecked<2>();
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (Eigen::Index i = 0; i < n; ++i)
      v(static_cast<py::ssize_t>(r), i) = sd ? std::sqrt(rows[r].covariance(i, i)) : rows[r].mean[i];
  return a;
}

std::string reportRepr(const EstimatorReport& r) {
  std::ostringstream os;
  os << "EstimatorReport(method='" << methodName(r.method) << "', measurements=" << r.measurements << ", seconds=" << r.seconds
     << ", iterations=" << r.iterations << ", window=" << r.window << ", rejected=" << r.rejected << ", nis=" << r.nis
     << ", detail='" << r.detail << "')";
  return os.str();
}

}  // namespace

namespace {
// An options struct's settings as properties, from the same key list the
// INI reader uses (gssm/estimator/option_keys.h): Python has every INI key
// and no other, with the C++ defaults.
struct OptionGetter {
  const std::string& key;
  py::object value;
  template <class T>
  void operator()(const char* k, T& v, const char*) {
    if (key == k) value = py::cast(v);
  }
  template <class E>
  void operator()(const char* k, Choice<E>& c, const char*) {
    if (key == k) value = py::str(c.name(c.value));
  }
};

struct OptionSetter {
  const std::string& key;
  const py::object& value;
  template <class T>
  void operator()(const char* k, T& v, const char*) {
    if (key != k) return;
    try {
      v = value.cast<T>();
    } catch (const py::cast_error&) {
      throw InvalidArgument("option '" + key + "': cannot take " + py::repr(value).cast<std::string>());
    }
  }
  template <class E>
  void operator()(const char* k, Choice<E>& c, const char*) {
    if (key != k) return;
    const auto named = c.named(py::str(value).cast<std::string>());
    if (!named) throw InvalidArgument("option '" + key + "' = " + py::repr(value).cast<std::string>() + ": expected " + c.expected);
    c.value = *named;
  }
};

// An options group as {key: value} (pickling), and back.
template <class Options>
py::dict optionDict(Options o) {
  py::dict d;
  for (const std::string& key : optionKeyNames<Options>()) {
    OptionGetter get{key, py::none()};
    optionKeys(get, o);
    d[key.c_str()] = get.value;
  }
  return d;
}

template <class Options>
void setOptions(Options& o, const py::dict& d) {
  for (const auto& item : d) {
    const std::string key = py::str(item.first).cast<std::string>();
    const py::object value = py::reinterpret_borrow<py::object>(item.second);
    OptionSetter set{key, value};
    optionKeys(set, o);
  }
}

template <class Options>
void bindOptionFields(py::class_<Options> cls) {
  for (const std::string& key : optionKeyNames<Options>())
    cls.def_property(
        key.c_str(),
        [key](Options& o) {
          OptionGetter get{key, py::none()};
          optionKeys(get, o);
          return get.value;
        },
        [key](Options& o, const py::object& v) {
          OptionSetter set{key, v};
          optionKeys(set, o);
        });
}
}  // namespace

namespace {
void bindOptionGroups(py::module_& m) {
  bindOptionFields(py::class_<ExtendedKalmanFilterOptions>(m, "EkfOptions", "Settings of the EKF baseline ([ekf]).")
                       .def(py::init<>()));
  bindOptionFields(py::class_<SmootherOptions>(m, "SmootherOptions",
                                               "Relinearization policy of the smoothers ([smoother]; its ordering "
                                               "is EstimatorOptions.ordering).")
                       .def(py::init<>()));
  bindOptionFields(py::class_<BatchSolverOptions>(m, "BatchOptions", "Settings of the batch MAP solver ([batch]).")
                       .def(py::init<>()));
}

py::tuple pickledOptions(const EstimatorOptions& o) {
  return py::make_tuple(std::string(methodName(o.method)), o.t0, o.compute_nis, optionDict(o.ekf), optionDict(o.smoother),
                        orderingName(o.incremental.ordering), o.fixed_lag.window, o.paper_window.window,
                        optionDict(o.batch), o.drop_late, o.fixed_lag.constants_check_sigmas);
}

EstimatorOptions unpickledOptions(const py::tuple& t) {
  EstimatorOptions o(methodFromName(t[0].cast<std::string>()));
  o.t0 = t[1].cast<double>();
  o.compute_nis = t[2].cast<bool>();
  setOptions(o.ekf, t[3]);
  setOptions(o.smoother, t[4]);
  o.incremental.ordering = orderingFromName(t[5].cast<std::string>());
  o.fixed_lag.window = t[6].cast<int>();
  o.paper_window.window = t[7].cast<int>();
  setOptions(o.batch, t[8]);
  if (t.size() > 9) o.drop_late = t[9].cast<bool>();
  if (t.size() > 10) o.fixed_lag.constants_check_sigmas = t[10].cast<double>();
  return o;
}

void bindEstimatorOptions(py::module_& m) {
  py::class_<EstimatorOptions>(m, "EstimatorOptions",
                               "Every method's settings; `method` says which run. gssm.make_estimator and gssm.run "
                               "build one from keyword arguments.")
      .def(py::init([](const std::string& method) { return EstimatorOptions(methodFromName(method)); }),
           py::arg("method") = "fixed-lag")
      .def_property(
          "method", [](const EstimatorOptions& o) { return std::string(methodName(o.method)); },
          [](EstimatorOptions& o, const std::string& s) { o.method = methodFromName(s); })
      .def_readwrite("t0", &EstimatorOptions::t0, "time of x_c(0)")
      .def_readwrite("compute_nis", &EstimatorOptions::compute_nis)
      .def_readwrite("drop_late", &EstimatorOptions::drop_late,
                     "drop and count a measurement too late to take (report.late_dropped) instead of refusing it")
      .def_readwrite("ekf", &EstimatorOptions::ekf)
      .def_readwrite("smoother", &EstimatorOptions::smoother)
      .def_readwrite("batch", &EstimatorOptions::batch)
      .def_property(
          "ordering", [](const EstimatorOptions& o) { return orderingName(o.incremental.ordering); },
          [](EstimatorOptions& o, const std::string& s) { o.incremental.ordering = orderingFromName(s); },
          "incremental: elimination ordering, 'colamd' or 'time'")
      .def_property(
          "fixed_lag_window", [](const EstimatorOptions& o) { return o.fixed_lag.window; },
          [](EstimatorOptions& o, int w) { o.fixed_lag.window = w; })
      .def_property(
          "fixed_lag_constants_check_sigmas",
          [](const EstimatorOptions& o) { return o.fixed_lag.constants_check_sigmas; },
          [](EstimatorOptions& o, double v) { o.fixed_lag.constants_check_sigmas = v; },
          "[fixed_lag] constants_check_sigmas: the fixed lag's own, in place of smoother's (NaN: that one)")
      .def_property(
          "paper_window_window", [](const EstimatorOptions& o) { return o.paper_window.window; },
          [](EstimatorOptions& o, int w) { o.paper_window.window = w; })
      .def_property_readonly("window", &EstimatorOptions::window, "the window of a window method, else 0")
      .def(
          "validate",
          [](const EstimatorOptions& o, const Model& model) {
            std::string why;
            if (!o.validate(model, &why)) throw InvalidArgument(why);
          },
          py::arg("model"), "raises gssm.InvalidArgument naming the option at fault")
      .def(py::pickle(&pickledOptions, &unpickledOptions));

  m.def("methods", [](bool streaming_only) {
    std::vector<std::string> out;
    for (const auto& info : gssm::methods())
      if (info.streaming || !streaming_only) out.push_back(info.name);
    return out;
  }, py::arg("streaming_only") = false, "every method name, in the order gssm-process 'all' runs them");
}

void bindEstimates(py::module_& m) {
  py::class_<StateEstimate>(m, "StateEstimate", "The stacked state [x_c(k); x_b] at step k with its covariance.")
      .def_readonly("t", &StateEstimate::t)
      .def_readonly("step", &StateEstimate::step)
      .def_readonly("mean", &StateEstimate::mean)
      .def_readonly("covariance", &StateEstimate::covariance)
      .def_property_readonly("sd", [](const StateEstimate& e) { return VectorXd(e.covariance.diagonal().cwiseSqrt()); })
      .def("__repr__", [](const StateEstimate& e) {
        std::ostringstream os;
        os.precision(6);
        os << "StateEstimate(t=" << e.t << ", step=" << e.step << ", mean=[";
        for (Eigen::Index i = 0; i < e.mean.size(); ++i) os << (i ? ", " : "") << e.mean[i];
        os << "])";
        return os.str();
      });

  py::class_<UpdateReport>(m, "UpdateReport", "What one smoother update did.")
      .def_readonly("new_factors", &UpdateReport::new_factors)
      .def_readonly("new_variables", &UpdateReport::new_variables)
      .def_readonly("cliques_reeliminated", &UpdateReport::cliques_reeliminated)
      .def_readonly("orphans", &UpdateReport::orphans)
      .def_readonly("factors_checked", &UpdateReport::factors_checked)
      .def_readonly("factors_relinearized", &UpdateReport::factors_relinearized)
      .def_readonly("relinearization_pass", &UpdateReport::relinearization_pass)
      .def_readonly("iterations", &UpdateReport::iterations)
      .def_readonly("variables_backsubstituted", &UpdateReport::variables_backsubstituted)
      .def_readonly("variables_marginalized", &UpdateReport::variables_marginalized)
      .def_readonly("num_variables", &UpdateReport::num_variables)
      .def_readonly("num_factors", &UpdateReport::num_factors)
      .def_readonly("num_cliques", &UpdateReport::num_cliques)
      .def_readonly("seconds", &UpdateReport::seconds)
      .def_readonly("note", &UpdateReport::note)
      .def("__repr__", [](const UpdateReport& r) { return "UpdateReport(" + r.toString() + ")"; });
}

py::dict reportDict(const EstimatorReport& r) {
  py::dict d;
  d["method"] = methodName(r.method);
  d["window"] = r.window;
  d["ordering"] = r.ordering ? py::object(py::str(orderingName(*r.ordering))) : py::object(py::none());
  d["measurements"] = r.measurements;
  d["late"] = r.late;
  d["late_dropped"] = r.late_dropped;
  d["seconds"] = r.seconds;
  d["iterations"] = r.iterations;
  d["rejected"] = r.rejected;
  d["detail"] = r.detail;
  d["nis"] = r.nis;
  return d;
}

void bindEstimatorReport(py::module_& m) {
  py::class_<EstimatorReport>(m, "EstimatorReport", "The last call's report (a snapshot).")
      .def_property_readonly("method", [](const EstimatorReport& r) { return std::string(methodName(r.method)); })
      .def_readonly("window", &EstimatorReport::window)
      .def_property_readonly("ordering",
                             [](const EstimatorReport& r) -> py::object {
                               if (!r.ordering) return py::none();
                               return py::str(orderingName(*r.ordering));
                             })
      .def_readonly("measurements", &EstimatorReport::measurements)
      .def_readonly("late", &EstimatorReport::late, "measurements taken out of sequence, at a held state's time")
      .def_readonly("late_dropped", &EstimatorReport::late_dropped, "late measurements dropped (drop_late)")
      .def_readonly("seconds", &EstimatorReport::seconds)
      .def_readonly("iterations", &EstimatorReport::iterations)
      .def_readonly("rejected", &EstimatorReport::rejected)
      .def_readonly("smoother", &EstimatorReport::smoother)
      .def_readonly("detail", &EstimatorReport::detail)
      .def_readonly("nis", &EstimatorReport::nis)
      .def("to_dict", &reportDict)
      .def("__repr__", &reportRepr);
}

// The streaming estimator: feeding it, reading it.
py::class_<PyEstimator> bindStreamingEstimator(py::module_& m) {
  return py::class_<PyEstimator>(m, "Estimator",
                          "A streaming estimator (gssm.make_estimator). Every call that raises leaves it as it was.")
      .def_property_readonly("method", [](const PyEstimator& e) { return std::string(e.est->methodName()); })
      .def_property_readonly("model", [](const PyEstimator& e) { return std::const_pointer_cast<Model>(e.model); })
      .def_property_readonly("options", [](const PyEstimator& e) { return e.est->options(); })
      .def_property_readonly("time", [](const PyEstimator& e) { return e.est->time(); }, "time of the newest state")
      .def_property_readonly("step", [](const PyEstimator& e) { return e.est->step(); }, "its step k")
      .def(
          "add_input", [](PyEstimator& e, double t, const VectorXd& u) { e.est->addInput(t, u); }, py::arg("t"),
          py::arg("u"), "input u held from time t on (zero-order hold)")
      .def(
          "add_measurement",
          [](PyEstimator& e, double t, const VectorXd& y, const py::object& channel,
             const std::optional<MatrixXd>& R, const std::optional<VectorXd>& regressors) {
            const int c = channelOf(*e.model, channel);
            if (c == 0 && !R && !regressors) {
              e.est->addMeasurement(t, y);
              return;
            }
            e.est->addMeasurement(Measurement(t, y, c, R ? *R : MatrixXd(), regressors ? *regressors : VectorXd()));
          },
          py::arg("t"), py::arg("y"), py::arg("channel") = py::none(), py::arg("R") = py::none(),
          py::arg("regressors") = py::none(),
          "measurement y at time t on `channel` (name or index; default the model's first), with its own noise "
          "covariance R when given, and the known values h reads on a channel that takes any (Channel.regressors: "
          "strapdown_ins's gnss_vel: the gyro's mean reading and the velocity's rate of change, NED, at the fix; its nhc "
          "at points off the IMU: the gyro's mean reading)")
      .def("current", [](PyEstimator& e) { return e.est->current(); }, "newest state and constants, joint covariance")
      .def(
          "smoothed", [](PyEstimator& e, std::int64_t k) { return e.est->smoothed(k); }, py::arg("k"),
          "estimate of x_c(k) given all data so far, or None where the method does not keep it")
      .def(
          "marginal_covariance",
          [](PyEstimator& e, const std::vector<std::int64_t>& states, bool constants) {
            std::vector<Key> keys;
            for (auto k : states) keys.push_back(Key::state(k));
            if (constants) keys.push_back(Key::constants());
            return e.est->marginalCovariance(keys);
          },
          py::arg("states") = std::vector<std::int64_t>{}, py::arg("constants") = true,
          "joint marginal covariance of the states x_c(k) for k in `states` and (if constants) x_b, blocks in that "
          "order; None where the method does not hold them all")
      .def("report", [](const PyEstimator& e) { return e.est->report(); }, "the last call's report");
}

// Its checkpoints and pickling.
void bindEstimatorCheckpoints(py::class_<PyEstimator>& cls) {
  cls.def(
          "to_bytes",
          [](const PyEstimator& e, const py::bytes& user_data) {
            return py::bytes(checkpointBytes(*e.est, std::string(user_data)));
          },
          py::arg("user_data") = py::bytes(""), "a checkpoint (gssm.restore reads it back)")
      .def(
          "save", [](const PyEstimator& e, const std::string& path, const py::bytes& user_data) {
            saveCheckpoint(*e.est, path, std::string(user_data));
          },
          py::arg("path"), py::arg("user_data") = py::bytes(""), "a checkpoint file (atomic write)")
      .def("__reduce__",
           [](const PyEstimator& e) {
             return py::make_tuple(py::module_::import("gssm").attr("_restore_pickled"),
                                   py::make_tuple(std::const_pointer_cast<Model>(e.model),
                                                  py::bytes(checkpointBytes(*e.est))));
           })
      .def("__repr__", [](const PyEstimator& e) {
        return "<gssm.Estimator " + std::string(e.est->methodName()) + " on " + e.model->name() +
               ", step " + std::to_string(e.est->step()) + ", t = " + std::to_string(e.est->time()) + ">";
      });
}

py::dict checkpointInfoDict(const CheckpointInfo& info) {
  py::dict d;
  d["version"] = info.version;
  d["method"] = methodName(info.method);
  d["model"] = info.model;
  d["step"] = info.step;
  d["time"] = info.time;
  d["user_data"] = py::bytes(info.user_data);
  return d;
}

// Making and restoring estimators.
void bindEstimatorFactories(py::module_& m) {
  m.def(
      "make_estimator_from_options",
      [](std::shared_ptr<Model> model, const EstimatorOptions& options) {
        return PyEstimator{model, makeEstimator(*model, options)};
      },
      py::arg("model"), py::arg("options"), "gssm.make_estimator without keyword conveniences");

  m.def(
      "restore_bytes",
      [](std::shared_ptr<Model> model, const py::bytes& bytes) {
        return PyEstimator{model, restoreCheckpointBytes(*model, std::string(bytes))};
      },
      py::arg("model"), py::arg("data"), "the estimator a checkpoint (bytes) holds, on `model`");
  m.def(
      "restore_file",
      [](std::shared_ptr<Model> model, const std::string& path) {
        return PyEstimator{model, restoreCheckpoint(*model, path)};
      },
      py::arg("model"), py::arg("path"), "the estimator a checkpoint file holds, on `model`");
  m.def(
      "checkpoint_info",
      [](std::shared_ptr<Model> model, const py::bytes& bytes) {
        CheckpointInfo info;
        restoreCheckpointBytes(*model, std::string(bytes), "checkpoint", &info);
        return checkpointInfoDict(info);
      },
      py::arg("model"), py::arg("data"), "version, method, model, step, time and user_data of a checkpoint");
}

py::array_t<double> runCovariances(const PyRun& r) {
  const auto n = static_cast<py::ssize_t>(r.names.size());
  py::array_t<double> a({static_cast<py::ssize_t>(r.run.rows.size()), n, n});
  auto v = a.mutable_unchecked<3>();
  for (std::size_t k = 0; k < r.run.rows.size(); ++k)
    for (py::ssize_t i = 0; i < n; ++i)
      for (py::ssize_t j = 0; j < n; ++j) v(static_cast<py::ssize_t>(k), i, j) = r.run.rows[k].covariance(i, j);
  return a;
}

PyRun runDataset(std::shared_ptr<Model> model, const PyDataset& data, const EstimatorOptions& options,
                 const std::optional<bool> rows_at_inputs, const std::function<void(std::size_t, std::size_t)>& progress) {
  const RowTimes rows = !rows_at_inputs ? data.data.rows : *rows_at_inputs ? RowTimes::Inputs : RowTimes::Measurements;
  PyRun out;
  out.names = model->stackedStateNames();
  if (callsPython(*model) || progress) {
    // Python code runs inside the loop: keep the GIL.
    out.run = runOffline(*model, options, data.data.measurements, data.data.inputs, progress, {}, rows);
  } else {
    py::gil_scoped_release release;
    out.run = runOffline(*model, options, data.data.measurements, data.data.inputs, {}, {}, rows);
  }
  return out;
}

// Offline runs.
void bindRuns(py::module_& m) {
  py::class_<PyRun>(m, "Run", "An offline run: one row per measurement (or per input for input-driven logs).")
      .def_property_readonly("method", [](const PyRun& r) { return std::string(methodName(r.run.method)); })
      .def_property_readonly("names", [](const PyRun& r) { return r.names; }, "names of the columns of mean and sd")
      .def_property_readonly("t", [](const PyRun& r) { return timesOf(r.run.rows); }, "(N,) row times")
      .def_property_readonly("mean", [](const PyRun& r) {
        return stack(r.run.rows, static_cast<Eigen::Index>(r.names.size()), false);
      }, "(N, n) stacked [x_c; x_b] per row")
      .def_property_readonly("sd", [](const PyRun& r) {
        return stack(r.run.rows, static_cast<Eigen::Index>(r.names.size()), true);
      }, "(N, n) marginal standard deviations")
      .def_property_readonly("covariance", &runCovariances, "(N, n, n)")
      .def_property_readonly("nis", [](const PyRun& r) { return toArray(r.run.nis); }, "NIS per measurement (compute_nis)")
      .def_property_readonly("update_seconds", [](const PyRun& r) { return toArray(r.run.update_seconds); })
      .def_property_readonly("total_seconds", [](const PyRun& r) { return r.run.total_seconds; },
                             "the estimator's own time (the loop in C++)")
      .def_property_readonly("iterations", [](const PyRun& r) { return r.run.iterations; })
      .def_property_readonly("summary", [](const PyRun& r) { return r.run.summary; })
      .def_property_readonly("downweighted", [](const PyRun& r) { return r.run.downweighted; })
      .def_property_readonly("rejected", [](const PyRun& r) { return r.run.rejected; })
      .def("__len__", [](const PyRun& r) { return r.run.rows.size(); })
      .def("__repr__", [](const PyRun& r) {
        return "<gssm.Run " + std::string(methodName(r.run.method)) + ", " + std::to_string(r.run.rows.size()) +
               " rows, " + std::to_string(r.run.total_seconds) + " s>";
      });

  m.def("run_dataset", &runDataset, py::arg("model"), py::arg("data"), py::arg("options"), py::arg("rows_at_inputs") = py::none(),
      py::arg("progress") = nullptr, "gssm.run without keyword conveniences");
}
}  // namespace

void bindEstimator(py::module_& m) {
  bindOptionGroups(m);
  bindEstimatorOptions(m);
  bindEstimates(m);
  bindEstimatorReport(m);
  auto estimator = bindStreamingEstimator(m);
  bindEstimatorCheckpoints(estimator);
  bindEstimatorFactories(m);
  bindRuns(m);
}

}  // namespace gssm::python
