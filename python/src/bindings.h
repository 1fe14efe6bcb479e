#pragma once
// The gssm Python module (_gssm, wrapped by the pure-Python package gssm/):
// one bind function per layer of the C++ library (docs/DESIGN.md §3), each
// in its own file. Arrays cross as NumPy (pybind11/eigen.h copies them).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>

#include "gssm/analysis/offline.h"
#include "gssm/estimator/estimator.h"
#include "gssm/io/dataset.h"
#include "gssm/io/process.h"
#include "gssm/model/model.h"
#include "gssm/model/simulation.h"

namespace py = pybind11;

namespace gssm::python {

void bindErrors(py::module_& m);
void bindModels(py::module_& models);
/// The registered model types as gssm.models._types/_make (model_params.cpp).
void bindModelRegistry(py::module_& models);
/// A registered model's parameters as a dict of its class's keywords.
py::dict modelParams(const Model& model);
void bindEstimator(py::module_& m);
void bindIo(py::module_& io);
void bindAnalysis(py::module_& analysis);
void bindCampaign(py::module_& campaign);

/// A std::vector<double> as a 1-D NumPy array (a copy).
inline py::array_t<double> toArray(const std::vector<double>& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

/// The time stamps (member t) of measurements, inputs or estimate rows, as a 1-D array.
template <class Record>
Eigen::VectorXd timesOf(const std::vector<Record>& records) {
  Eigen::VectorXd t(static_cast<Eigen::Index>(records.size()));
  for (std::size_t i = 0; i < records.size(); ++i) t[static_cast<Eigen::Index>(i)] = records[i].t;
  return t;
}

/// True when the model calls back into Python (a gssm.models.PythonModel):
/// such a model needs the GIL held while it runs, so loops over it cannot
/// release it.
bool callsPython(const Model& model);

/// The N(0, 1) source of a seed that gssm-simulate and gssm-montecarlo use
/// (MRPT's generator), so Python simulations give their bytes (io.cpp).
NormalSampler simulationSampler(unsigned seed);

/// The method named `name` (every name gssm-process takes); InvalidArgument
/// naming the valid ones otherwise.
Method methodFromName(const std::string& name);

/// A dataset as Python sees it: the C++ dataset, the model its scenario.ini
/// describes (when read from a folder or simulated), and the simulated run
/// with the whole true trajectory (when simulated).
struct PyDataset {
  io::Dataset data;
  std::shared_ptr<Model> model;
  std::shared_ptr<SimulatedRun> simulated;
};

/// An offline run with the names of its columns (gssm.Run).
struct PyRun {
  OfflineRun run;
  std::vector<std::string> names;
};

/// A processed dataset (gssm.process): the C++ result, shared with the
/// plotting extension (gssm._plot) that draws its figures.
struct PyProcessResult {
  std::shared_ptr<io::ProcessResult> result;
};

void bindProcess(py::module_& m);
void bindLearn(py::module_& m);

}  // namespace gssm::python
