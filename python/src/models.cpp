// gssm.models: the Model interface, and models written in Python
// (FunctionModel over Python callables; central differences where no
// Jacobian is given). The registered model types (Radar2D, Linear, ...)
// are bound generically from the registry (model_params.cpp). Registered
// models pickle through their INI form (io::writeModel / io::makeModel);
// the Python package pickles PythonModel from its constructor arguments.
#include <pybind11/functional.h>

#include "bindings.h"
#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/io/ini.h"
#include "gssm/models/function_model.h"

namespace gssm::python {

bool callsPython(const Model& model) { return dynamic_cast<const models::FunctionModel*>(&model) != nullptr; }

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// A callable's result as a vector of `n` values (a float is a 1-vector),
/// or an InvalidArgument naming the model and the function.
VectorXd vectorResult(const py::object& r, Eigen::Index n, const std::string& model, const char* fn) {
  VectorXd v;
  if (py::isinstance<py::float_>(r) || py::isinstance<py::int_>(r)) {
    v = VectorXd::Constant(1, r.cast<double>());
  } else {
    try {
      v = r.cast<VectorXd>();
    } catch (const py::cast_error&) {
      throw InvalidArgument("model '" + model + "': " + fn + " returned " +
                            py::str(py::type::of(r).attr("__name__")).cast<std::string>() +
                            ", expected a 1-D array of " + std::to_string(n) + " floats");
    }
  }
  if (v.size() != n)
    throw InvalidArgument("model '" + model + "': " + fn + " returned " + std::to_string(v.size()) +
                          " values, expected " + std::to_string(n));
  return v;
}

MatrixXd matrixResult(const py::handle& r, Eigen::Index rows, Eigen::Index cols, const std::string& model,
                      const std::string& what) {
  if (r.is_none() && (rows == 0 || cols == 0)) return MatrixXd::Zero(rows, cols);
  MatrixXd m;
  try {
    m = r.cast<MatrixXd>();
  } catch (const py::cast_error&) {
    throw InvalidArgument("model '" + model + "': " + what + " is not a 2-D array of floats");
  }
  if (rows * cols == 0 && m.size() == 0) return MatrixXd::Zero(rows, cols);
  if (m.rows() != rows || m.cols() != cols)
    throw InvalidArgument("model '" + model + "': " + what + " has shape (" + std::to_string(m.rows()) + ", " +
                          std::to_string(m.cols()) + "), expected (" + std::to_string(rows) + ", " +
                          std::to_string(cols) + ")");
  return m;
}

void jacobianPair(const py::object& r, Eigen::Index rows, const ModelDims& d, const std::string& model,
                  const char* fn, MatrixXd& J_xc, MatrixXd& J_xb) {
  if (!py::isinstance<py::tuple>(r) && !py::isinstance<py::list>(r))
    throw InvalidArgument("model '" + model + "': " + fn + " must return a pair (J_xc, J_xb)");
  const py::sequence s = r;
  if (s.size() != 2) throw InvalidArgument("model '" + model + "': " + fn + " must return a pair (J_xc, J_xb)");
  J_xc = matrixResult(s[0], rows, d.nc, model, std::string(fn) + "[0] (J_xc)");
  J_xb = matrixResult(s[1], rows, d.nb, model, std::string(fn) + "[1] (J_xb)");
}

Gaussian gaussian(const std::optional<VectorXd>& mean, const std::optional<MatrixXd>& cov, int n) {
  Gaussian g;
  g.mean = mean ? *mean : VectorXd::Zero(n);
  g.covariance = cov ? *cov : MatrixXd::Identity(n, n);
  return g;
}

std::shared_ptr<models::FunctionModel> makePythonModel(
    int nc, int nb, int nu, int ny, py::function f, py::function h, const MatrixXd& Q, const MatrixXd& R, double T,
    const std::optional<VectorXd>& prior_state_mean, const std::optional<MatrixXd>& prior_state_cov,
    const std::optional<VectorXd>& prior_constants_mean, const std::optional<MatrixXd>& prior_constants_cov,
    const py::object& jacobian_f, const py::object& jacobian_h, const std::string& name,
    const std::vector<std::string>& state_names, const std::vector<std::string>& constant_names,
    const std::vector<std::string>& input_names, const std::vector<std::string>& measurement_names,
    bool verify_jacobians) {
  if (nc < 1 || nb < 0 || nu < 0 || ny < 1)
    throw InvalidArgument("PythonModel '" + name + "': need nc >= 1, nb >= 0, nu >= 0, ny >= 1");
  ModelDims d{nc, nb, nu, ny};
  auto numbered = [](const std::vector<std::string>& given, const char* prefix, int n, const char* what) {
    if (!given.empty() && static_cast<int>(given.size()) != n)
      throw InvalidArgument(std::string("PythonModel: ") + what + " has " + std::to_string(given.size()) +
                            " names, expected " + std::to_string(n));
    if (!given.empty()) return given;
    std::vector<std::string> out;
    for (int i = 1; i <= n; ++i) out.push_back(prefix + std::to_string(i));
    return out;
  };
  ModelNames names{numbered(state_names, "x", nc, "state_names"), numbered(constant_names, "b", nb, "constant_names"),
                   numbered(input_names, "u", nu, "input_names"),
                   numbered(measurement_names, "y", ny, "measurement_names")};
  ModelNoise noise;
  noise.T = T;
  noise.Q = Q;
  noise.R = R;
  noise.prior_state = gaussian(prior_state_mean, prior_state_cov, nc);
  noise.prior_constants = gaussian(prior_constants_mean, prior_constants_cov, nb);
  requireCovariance(Q, nc, "PythonModel '" + name + "': Q");
  requireCovariance(R, ny, "PythonModel '" + name + "': R");
  requireVector(noise.prior_state.mean, nc, "PythonModel '" + name + "': prior_state mean");
  requireCovariance(noise.prior_state.covariance, nc, "PythonModel '" + name + "': prior_state covariance");
  requireVector(noise.prior_constants.mean, nb, "PythonModel '" + name + "': prior_constants mean");
  if (nb > 0)
    requireCovariance(noise.prior_constants.covariance, nb, "PythonModel '" + name + "': prior_constants covariance");

  models::ModelFunctions fns;
  fns.name = name;
  fns.f = [f, d, name](const VectorXd& xc, const VectorXd& xb, const VectorXd& u, double dt) {
    return vectorResult(f(xc, xb, u, dt), d.nc, name, "f");
  };
  fns.h = [h, d, name](const VectorXd& xc, const VectorXd& xb) { return vectorResult(h(xc, xb), d.ny, name, "h"); };
  if (!jacobian_f.is_none()) {
    py::function jf = jacobian_f;
    fns.jacobians_f = [jf, d, name](const VectorXd& xc, const VectorXd& xb, const VectorXd& u, double dt,
                                    MatrixXd& J_xc, MatrixXd& J_xb) {
      jacobianPair(jf(xc, xb, u, dt), d.nc, d, name, "jacobian_f", J_xc, J_xb);
    };
  }
  if (!jacobian_h.is_none()) {
    py::function jh = jacobian_h;
    fns.jacobians_h = [jh, d, name](const VectorXd& xc, const VectorXd& xb, MatrixXd& J_xc, MatrixXd& J_xb) {
      jacobianPair(jh(xc, xb), d.ny, d, name, "jacobian_h", J_xc, J_xb);
    };
  }
  fns.verify_jacobians = verify_jacobians;
  return std::make_shared<models::FunctionModel>(d, std::move(names), std::move(noise), std::move(fns));
}

std::string modelIni(const Model& m) {
  io::IniDocument ini;
  io::writeModel(m, ini);
  return ini.toString();
}

void bindChannel(py::module_& models) {
  py::class_<MeasurementChannel>(models, "Channel", "A sensor of a model: its name, components, noise and loss.")
      .def_readonly("name", &MeasurementChannel::name)
      .def_readonly("components", &MeasurementChannel::components)
      .def_readonly("R", &MeasurementChannel::R)
      .def_property_readonly("loss", [](const MeasurementChannel& c) { return RobustLoss::name(c.loss.kind); })
      .def_property_readonly("loss_scale", [](const MeasurementChannel& c) { return c.loss.scale; })
      .def_readonly("angles", &MeasurementChannel::angles)
      .def_readonly("ekf_gate", &MeasurementChannel::ekf_gate)
      .def_readonly("own_R_scale", &MeasurementChannel::own_R_scale,
                    "variance factor on the covariance a measurement brings (R it gives times this)")
      .def_readonly("regressors", &MeasurementChannel::regressors,
                    "known values a measurement on it carries beside y, which h reads (0 on most channels)")
      .def_property_readonly("dim", &MeasurementChannel::dim)
      .def("__repr__", [](const MeasurementChannel& c) {
        return "Channel(name='" + c.name + "', dim=" + std::to_string(c.dim()) + ", loss='" +
               RobustLoss::name(c.loss.kind) + "')";
      });
}

// The Model's read-only description: sizes, names, noise, priors, channels.
py::class_<Model, std::shared_ptr<Model>> bindModelProperties(py::module_& models) {
  auto cls = py::class_<Model, std::shared_ptr<Model>>(models, "Model",
                                            "A GSSM: x_c(k+1) = f(x_c(k), x_b, u, dt) + q, y = h(x_c, x_b) + r "
                                            "(docs/DESIGN.md §2). Abstract: use a built-in model or PythonModel.")
      .def_property_readonly("name", &Model::name)
      .def_property_readonly("nc", [](const Model& m) { return m.dims().nc; }, "size of the time-series state x_c")
      .def_property_readonly("nb", [](const Model& m) { return m.dims().nb; }, "size of the constant state x_b")
      .def_property_readonly("nu", [](const Model& m) { return m.dims().nu; }, "size of the input u")
      .def_property_readonly("ny", [](const Model& m) { return m.dims().ny; }, "size of the default channel's y")
      .def_property_readonly("state_names", [](const Model& m) { return m.names().state; })
      .def_property_readonly("constant_names", [](const Model& m) { return m.names().constants; })
      .def_property_readonly("input_names", [](const Model& m) { return m.names().input; })
      .def_property_readonly("measurement_names", [](const Model& m) { return m.names().measurement; })
      .def_property_readonly("stacked_state_names", &Model::stackedStateNames, "names of [x_c; x_b]")
      .def_property_readonly("T", &Model::nominalStep, "nominal step (s)")
      .def_property_readonly("Q", [](const Model& m) { return m.processNoise(m.nominalStep()); },
                             "process noise covariance of one nominal step T")
      .def_property_readonly("R", &Model::measurementNoise, "noise covariance of the default channel")
      .def_property_readonly("prior_state",
                             [](const Model& m) { return py::make_tuple(m.priorState().mean, m.priorState().covariance); },
                             "(mean, covariance) of x_c(0)")
      .def_property_readonly(
          "prior_constants",
          [](const Model& m) { return py::make_tuple(m.priorConstants().mean, m.priorConstants().covariance); },
          "(mean, covariance) of x_b")
      .def_property_readonly("channels",
                             [](const Model& m) {
                               std::vector<MeasurementChannel> out;
                               for (int c = 0; c < m.numChannels(); ++c) out.push_back(m.channel(c));
                               return out;
                             })
      .def("channel_index", &Model::channelIndex, py::arg("name"), "index of the channel called `name`")
      .def_property_readonly("angle_states", &Model::angleStates, "stacked components that are angles")
      .def_property_readonly("rotation_blocks", &Model::rotationBlocks,
                             "first stacked components of the rotation vectors (each three; updated by R·Exp(δ))");
  cls.def_property_readonly("landmarks", [](const Model& m) {
        Eigen::MatrixXd out(static_cast<Eigen::Index>(m.landmarks().size()), 2);
        for (std::size_t i = 0; i < m.landmarks().size(); ++i) out.row(static_cast<Eigen::Index>(i)) = m.landmarks()[i];
        return out;
      }, "fixed points its measurements refer to (beacons), one row (x, y) each")
      .def_property_readonly("params", &modelParams,
                             "a registered model's parameters, as the keywords of its class");
  return cls;
}

// Evaluating the model: f, h with their Jacobians, Q(dt), the Jacobian check.
void bindModelFunctions(py::class_<Model, std::shared_ptr<Model>>& cls) {
  cls      .def(
          "f",
          [](const Model& m, const VectorXd& xc, const VectorXd& xb, const VectorXd& u, double dt,
             bool jacobians) -> py::object {
            const auto d = m.dims();
            requireVector(xc, d.nc, "f: xc");
            requireVector(xb, d.nb, "f: xb");
            const VectorXd uu = u.size() == 0 ? VectorXd::Zero(d.nu) : u;
            requireVector(uu, d.nu, "f: u");
            if (!jacobians) return py::cast(m.f(xc, xb, uu, dt));
            MatrixXd J_xc, J_xb;
            VectorXd v = m.f(xc, xb, uu, dt, &J_xc, &J_xb);
            return py::make_tuple(v, J_xc, J_xb);
          },
          py::arg("xc"), py::arg("xb"), py::arg("u") = VectorXd(), py::arg("dt") = std::nan(""),
          py::arg("jacobians") = false,
          "x_c(k+1) without noise; with jacobians=True the tuple (value, J_f_xc, J_f_xb). dt defaults to T.")
      .def(
          "h",
          [](const Model& m, const VectorXd& xc, const VectorXd& xb, const py::object& channel, bool jacobians,
             const std::optional<VectorXd>& regressors) -> py::object {
            const auto d = m.dims();
            requireVector(xc, d.nc, "h: xc");
            requireVector(xb, d.nb, "h: xb");
            const int c = py::isinstance<py::str>(channel) ? m.channelIndex(channel.cast<std::string>())
                                                             : channel.cast<int>();
            if (c < 0 || c >= m.numChannels())
              throw InvalidArgument("h: channel " + std::to_string(c) + " out of range (the model has " +
                                    std::to_string(m.numChannels()) + ")");
            const VectorXd known = regressors ? *regressors : VectorXd();
            if (!jacobians) return py::cast(m.hWith(c, known, xc, xb));
            MatrixXd J_xc, J_xb;
            VectorXd v = m.hWith(c, known, xc, xb, &J_xc, &J_xb);
            return py::make_tuple(v, J_xc, J_xb);
          },
          py::arg("xc"), py::arg("xb"), py::arg("channel") = 0, py::arg("jacobians") = false,
          py::arg("regressors") = py::none(),
          "y without noise on `channel` (index or name); with jacobians=True (value, J_h_xc, J_h_xb); `regressors`: "
          "the known values a channel with Channel.regressors > 0 reads")
      .def("process_noise", &Model::processNoise, py::arg("dt"), "Q for a step of dt")
      .def(
          "check_jacobians",
          [](const Model& m, const VectorXd& xc, const VectorXd& xb, const VectorXd& u, double dt, double eps) {
            const JacobianCheck c = checkJacobians(m, xc, xb, u.size() ? u : VectorXd::Zero(m.dims().nu),
                                                   std::isnan(dt) ? m.nominalStep() : dt, eps);
            py::dict d;
            d["max_abs_error"] = c.max_abs_error;
            d["max_rel_error"] = c.max_rel_error;
            d["worst"] = c.worst;
            return d;
          },
          py::arg("xc"), py::arg("xb"), py::arg("u") = VectorXd(), py::arg("dt") = std::nan(""),
          py::arg("eps") = 1e-6, "analytic Jacobians against central differences at one point")
      ;
}

// The model as INI text, pickling, repr.
void bindModelText(py::class_<Model, std::shared_ptr<Model>>& cls) {
  cls.def("to_ini", &modelIni, "the model's INI form ([model], [noise], [prior]), as gssm-process reads it")
      .def("__reduce__",
           [](const Model& m) {
             return py::make_tuple(py::module_::import("gssm.models").attr("_from_ini_pickled"),
                                   py::make_tuple(modelIni(m)));
           })
      .def("__repr__", [](const Model& m) {
        const auto d = m.dims();
        return "<gssm.models." + m.name() + " nc=" + std::to_string(d.nc) + " nb=" + std::to_string(d.nb) +
               " nu=" + std::to_string(d.nu) + " ny=" + std::to_string(d.ny) + " channels=" +
               std::to_string(m.numChannels()) + ">";
      });
}

void bindFunctionModel(py::module_& models) {
  py::class_<models::FunctionModel, Model, std::shared_ptr<models::FunctionModel>>(
      models, "_FunctionModel", "Base of gssm.models.PythonModel (use that).")
      .def(py::init(&makePythonModel), py::arg("nc"), py::arg("nb"), py::arg("nu"), py::arg("ny"), py::arg("f"),
           py::arg("h"), py::arg("Q"), py::arg("R"), py::arg("T"), py::arg("prior_state_mean") = py::none(),
           py::arg("prior_state_cov") = py::none(), py::arg("prior_constants_mean") = py::none(),
           py::arg("prior_constants_cov") = py::none(), py::arg("jacobian_f") = py::none(),
           py::arg("jacobian_h") = py::none(), py::arg("name") = "user",
           py::arg("state_names") = std::vector<std::string>{}, py::arg("constant_names") = std::vector<std::string>{},
           py::arg("input_names") = std::vector<std::string>{},
           py::arg("measurement_names") = std::vector<std::string>{}, py::arg("verify_jacobians") = false)
      .def_property_readonly("jacobian_source", &models::FunctionModel::jacobianSource);
}
}  // namespace

void bindModels(py::module_& models) {
  bindChannel(models);
  auto cls = bindModelProperties(models);
  bindModelFunctions(cls);
  bindModelText(cls);
  models.def(
      "from_ini",
      [](const std::string& text, const std::string& data_dir) -> std::shared_ptr<Model> {
        return std::shared_ptr<Model>(io::makeModel(io::IniDocument::parse(text, "<ini text>"), data_dir));
      },
      py::arg("text"), py::arg("data_dir") = "",
      "The model an INI text describes (as in a dataset's scenario.ini); file names in it are read from data_dir.");
  bindFunctionModel(models);
  bindModelRegistry(models);
}

}  // namespace gssm::python
