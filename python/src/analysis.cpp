// gssm.analysis: what gssm-process and gssm-analyze compute, as arrays:
// errors against the truth (angles wrapped) with the NEES of each row, the
// metrics of metrics.json, the posterior Cramér–Rao bound, the constants'
// identifiability and the χ² intervals the consistency verdicts use.
#include "bindings.h"
#include "gssm/analysis/bounds.h"
#include "gssm/analysis/errors.h"
#include "gssm/analysis/metrics.h"
#include "gssm/analysis/montecarlo.h"
#include "gssm/core/error.h"
#include "gssm/io/metrics_json.h"

namespace gssm::python {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

py::array_t<double> cube(const std::vector<MatrixXd>& ms) {
  const py::ssize_t n = ms.empty() ? 0 : ms.front().rows();
  py::array_t<double> a({static_cast<py::ssize_t>(ms.size()), n, n});
  auto v = a.mutable_unchecked<3>();
  for (std::size_t k = 0; k < ms.size(); ++k)
    for (py::ssize_t i = 0; i < n; ++i)
      for (py::ssize_t j = 0; j < n; ++j) v(static_cast<py::ssize_t>(k), i, j) = ms[k](i, j);
  return a;
}

const Truth& requireTruth(const PyDataset& d, const char* fn) {
  if (!d.data.truth) throw InvalidArgument(std::string(fn) + ": the dataset has no truth");
  return *d.data.truth;
}

py::dict runErrorsDict(const PyRun& run, const PyDataset& truth, const std::shared_ptr<Model>& model) {
  const std::vector<int> angles = model ? model->angleStates()
                                        : (truth.model ? truth.model->angleStates() : std::vector<int>{});
  const RunErrors e = runErrors(run.run, requireTruth(truth, "errors"), angles);
  MatrixXd err(static_cast<Eigen::Index>(e.error.size()), static_cast<Eigen::Index>(e.components.size()));
  for (std::size_t i = 0; i < e.error.size(); ++i) err.row(static_cast<Eigen::Index>(i)) = e.error[i].transpose();
  py::dict d;
  d["t"] = toArray(e.times);
  d["error"] = err;
  d["nees"] = toArray(e.nees);
  d["rmse"] = e.error.empty() ? VectorXd() : e.rmse();
  d["components"] = e.components;
  return d;
}

py::dict metricsDict(const std::shared_ptr<Model>& model, const PyRun& run, const PyDataset* truth) {
  const Truth* t = truth && truth->data.truth ? &*truth->data.truth : nullptr;
  const RunMetrics m = computeMetrics(*model, run.run, t);
  py::dict d;
  d["method"] = methodName(m.method);
  d["names"] = m.names;
  d["rows"] = m.rows;
  d["has_truth"] = m.has_truth;
  d["rmse"] = m.rmse;
  d["max_abs_error"] = m.max_abs_error;
  d["final_error"] = m.final_error;
  d["mean_nees"] = m.mean_nees;
  d["position_rmse"] = m.position_rmse;
  d["position_max"] = m.position_max;
  d["position_final"] = m.position_final;
  d["constant_names"] = m.constant_names;
  d["constants"] = m.constants;
  d["constants_sd"] = m.constants_sd;
  d["downweighted"] = m.downweighted;
  d["rejected"] = m.rejected;
  d["latency_median"] = m.latency_median;
  d["latency_p99"] = m.latency_p99;
  d["total_seconds"] = m.total_seconds;
  d["iterations"] = m.iterations;
  return d;
}

py::dict cramerRaoDict(const std::shared_ptr<Model>& model, const PyDataset& data, int stride) {
  SimulatedRun run;
  if (data.simulated) run = *data.simulated;
  else run = io::recordedRun(*model, data.data);
  CramerRaoBound b;
  if (callsPython(*model)) {
    b = posteriorCramerRao(*model, run, stride);
  } else {
    py::gil_scoped_release release;
    b = posteriorCramerRao(*model, run, stride);
  }
  py::dict d;
  d["t"] = toArray(b.times);
  d["filtering"] = cube(b.filtering);
  d["smoothing"] = cube(b.smoothing);
  return d;
}

py::dict identifiabilityDict(const std::shared_ptr<Model>& model, const MatrixXd& posterior_constants, double tolerance) {
  const ConstantsIdentifiability c = constantsIdentifiability(*model, posterior_constants, tolerance);
  py::dict d;
  d["eigenvalues"] = c.eigenvalues;
  d["directions"] = c.directions;
  d["rank"] = c.rank;
  d["condition"] = c.condition;
  d["weakest"] = c.weakest;
  d["determined"] = c.determined(tolerance);
  return d;
}

}  // namespace

void bindAnalysis(py::module_& a) {
  a.def("errors", &runErrorsDict,
      py::arg("run"), py::arg("truth"), py::arg("model") = nullptr,
      "Estimate − truth per row on the truth's components (angles wrapped), the NEES of each row and the RMSE: "
      "dict t, error (N, m), nees (N,), rmse (m,), components.");

  a.def("metrics", &metricsDict,
      py::arg("model"), py::arg("run"), py::arg("truth") = nullptr,
      "The numbers gssm-process writes to metrics.json for one run, as a dict of arrays.");

  a.def(
      "metrics_json",
      [](const std::shared_ptr<Model>& model, const std::vector<const PyRun*>& runs, const PyDataset* truth,
         const std::string& dataset) {
        const Truth* t = truth && truth->data.truth ? &*truth->data.truth : nullptr;
        std::vector<RunMetrics> ms;
        for (const PyRun* r : runs) ms.push_back(computeMetrics(*model, r->run, t));
        return io::metricsJson(ms, dataset);
      },
      py::arg("model"), py::arg("runs"), py::arg("truth") = nullptr, py::arg("dataset") = "",
      "metrics.json text for several runs of one dataset, as gssm-process writes it.");

  a.def("cramer_rao", &cramerRaoDict,
      py::arg("model"), py::arg("data"), py::arg("stride") = 1,
      "Posterior Cramér–Rao bound on cov [x_c(k); x_b] along the dataset's true trajectory: dict t, filtering "
      "(N, n, n) (data up to t_k), smoothing (N, n, n) (all data).");

  a.def("identifiability", &identifiabilityDict,
      py::arg("model"), py::arg("posterior_constants"), py::arg("tolerance") = 1e-9,
      "What the data determine about x_b, from its posterior covariance and the model's prior.");

  a.def("chi2_quantile", &chiSquareQuantile, py::arg("p"), py::arg("dof"),
        "χ²_dof quantile (exact: inversion of the regularized incomplete gamma), as the consistency verdicts use");
  a.def(
      "nees_interval",
      [](int dof, int runs, double probability) {
        const double lo = chiSquareQuantile((1 - probability) / 2, dof * runs) / runs;
        const double hi = chiSquareQuantile((1 + probability) / 2, dof * runs) / runs;
        return py::make_tuple(lo, hi);
      },
      py::arg("dof"), py::arg("runs") = 1, py::arg("probability") = 0.95,
      "(lo, hi): the interval of an average of `runs` NEES (or NIS) values of `dof` degrees of freedom");
}

}  // namespace gssm::python
