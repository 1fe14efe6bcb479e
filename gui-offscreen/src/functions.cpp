#include "gssm/plot/functions.h"

#include "gssm/plot/learn_figure.h"
#include "gssm/plot/run_figures.h"

namespace {
std::vector<std::string> writeProcessFiguresEntry(const gssm::io::ProcessResult& result, const std::string& dir,
                                                  int threads) {
  return gssm::plot::writeProcessFigures(result, dir, threads);
}
}  // namespace

extern "C" const gssm::plot::PlotFunctions* gssm_plot_functions() {
  static const gssm::plot::PlotFunctions functions{&writeProcessFiguresEntry, &gssm::plot::writeLearningFigure};
  return &functions;
}
