#pragma once
// The standard figures of one dataset processed by several estimators:
// each constant's estimate vs time with ±3σ bands and the truth (the paper's
// Figs. 9 and 10 for the radar), each time-series state's error vs time, and
// a per-update latency histogram.
#include <string>
#include <vector>

#include "gssm/io/dataset.h"
#include "gssm/model.h"
#include "gssm/offline.h"

namespace gssm::plot {

/// Writes fig-<constant>.png, fig-<state>-error.png (with truth) and
/// fig-latency.png into `dir`; returns the paths written.
std::vector<std::string> writeRunFigures(const Model& model, const std::vector<OfflineRun>& runs,
                                         const io::Truth* truth, const std::string& dir,
                                         const std::string& scenario_label);

}  // namespace gssm::plot
