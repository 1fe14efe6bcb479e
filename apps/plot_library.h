#pragma once
// The plotting library, loaded on a thread of its own from the moment an app
// starts: with it come MRPT's ~160 shared libraries (~0.2 s of the dynamic
// loader), which then overlap the app's reading and estimating instead of
// preceding main. The figures need it only at the end.
#include <future>
#include <string>

#include "gssm/plot/functions.h"

namespace gssm::apps {

class PlotLibrary {
 public:
  PlotLibrary();
  PlotLibrary(const PlotLibrary&) = delete;
  PlotLibrary& operator=(const PlotLibrary&) = delete;
  /// Waits for the loading; throws std::runtime_error naming the library
  /// and the loader's reason if it failed.
  const plot::PlotFunctions& functions();

 private:
  std::future<const plot::PlotFunctions*> loading_;
  const plot::PlotFunctions* functions_ = nullptr;
};

}  // namespace gssm::apps
