// gssm._plot: the figures of gssm.process, drawn offscreen with MRPT as
// gssm-process draws them (gssm::plot). A module of its own, imported only
// when figures are asked for: MRPT's image library is large.
#include "bindings.h"
#include "gssm/plot/run_figures.h"

PYBIND11_MODULE(_plot, m) {
  m.doc() = "Figures of gssm.process (MRPT, offscreen).";
  m.def(
      "write_process_figures",
      [](const gssm::python::PyProcessResult& r, const std::string& dir) {
        py::gil_scoped_release release;
        return gssm::plot::writeProcessFigures(*r.result, dir);
      },
      py::arg("result"), py::arg("dir"), "fig-*.png as gssm-process writes them; returns their paths");
}
