// PYBIND11_MODULE for gssm._gssm: the submodules mirror the C++ layers; the
// pure-Python package (python/gssm/) re-exports them with the helpers that
// are easier written in Python (keyword options, Dask campaigns).
#include "bindings.h"

PYBIND11_MODULE(_gssm, m) {
  m.doc() = "gssm: real-time optimal estimation with the Graphical State Space Model (C++ core).";
  gssm::python::bindErrors(m);
  py::module_ models = m.def_submodule("models", "Built-in models and models written in Python.");
  gssm::python::bindModels(models);
  gssm::python::bindEstimator(m);
  py::module_ io = m.def_submodule("io", "Dataset folders: read, write, simulate.");
  gssm::python::bindIo(io);
  py::module_ analysis = m.def_submodule("analysis", "Errors, NEES/NIS, metrics, bounds, identifiability.");
  gssm::python::bindAnalysis(analysis);
  py::module_ campaign = m.def_submodule("campaign", "Monte Carlo campaigns, seed by seed.");
  gssm::python::bindCampaign(campaign);
  gssm::python::bindProcess(m);
  gssm::python::bindLearn(m);
}
