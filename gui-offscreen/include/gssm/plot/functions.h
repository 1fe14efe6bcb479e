#pragma once
// The figure functions an application calls, as one table it can fetch from
// the plotting library after loading it with dlopen: the library brings
// MRPT's ~160 shared libraries, whose loading (~0.2 s) an app overlaps with
// its reading and estimating instead of paying it before main (PlotLibrary
// in apps/).
#include <string>
#include <vector>

#include "gssm/io/process.h"
#include "gssm/learn/noise_learning.h"

namespace gssm::plot {

struct PlotFunctions {
  std::vector<std::string> (*write_process_figures)(const io::ProcessResult& result, const std::string& dir,
                                                    int threads);
  std::string (*write_learning_figure)(const NoiseLearningReport& report, const std::string& dir,
                                       const std::string& label);
};

}  // namespace gssm::plot

/// The table, by a C name that dlsym finds.
extern "C" const gssm::plot::PlotFunctions* gssm_plot_functions();
