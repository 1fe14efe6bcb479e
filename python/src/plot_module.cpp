// gssm._plot: the figures of gssm.process, drawn offscreen with MRPT as
// gssm-process draws them (gssm::plot). A module of its own, imported only
// when figures are asked for: MRPT's image library is large.
#include "bindings.h"
#include "gssm/core/error.h"
#include "gssm/plot/run_figures.h"

PYBIND11_MODULE(_plot, m) {
  m.doc() = "Figures of gssm.process (MRPT, offscreen).";
  m.def(
      "write_process_figures",
      [](const gssm::python::PyProcessResult& r, const std::string& dir, int threads) {
        if (threads < 1) throw gssm::InvalidArgument("write_process_figures: threads must be >= 1, got " + std::to_string(threads));
        py::gil_scoped_release release;
        return gssm::plot::writeProcessFigures(*r.result, dir, threads);
      },
      py::arg("result"), py::arg("dir"), py::arg("threads") = 1,
      "fig-*.png as gssm-process writes them, up to `threads` drawn at a time; returns their paths");
}
