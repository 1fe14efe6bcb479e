#include "plot_library.h"

#include <dlfcn.h>

#include <stdexcept>

namespace gssm::apps {
namespace {

// dlopen searches the executable's RUNPATH: the build tree's plot library,
// or $ORIGIN/../lib once installed. Every symbol is bound now, off the main
// thread; the library stays loaded until the process ends.
const plot::PlotFunctions* loadPlotLibrary() {
  void* handle = dlopen(GSSM_PLOT_LIBRARY, RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw std::runtime_error(std::string("cannot load the plotting library: ") + dlerror());
  using Entry = const plot::PlotFunctions* (*)();
  auto entry = reinterpret_cast<Entry>(dlsym(handle, "gssm_plot_functions"));
  if (!entry)
    throw std::runtime_error(std::string(GSSM_PLOT_LIBRARY) + " has no gssm_plot_functions: " + dlerror());
  return entry();
}

}  // namespace

PlotLibrary::PlotLibrary() : loading_(std::async(std::launch::async, loadPlotLibrary)) {}

const plot::PlotFunctions& PlotLibrary::functions() {
  if (!functions_) functions_ = loading_.get();
  return *functions_;
}

}  // namespace gssm::apps
