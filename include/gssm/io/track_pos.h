#pragma once
// A run's track as an RTKLIB solution file (track-<method>.pos, plottable by
// RTKPLOT; issue #37, point 6): one epoch per estimate row, from what the
// model reports (Model::report: lat, lon, height and, when reported, vn, ve,
// vd) with their standard deviations; Q = 1 where the horizontal sd is under
// 5 cm, 2 elsewhere (an outage's dead reckoning).
#include <string>

#include "gssm/analysis/offline.h"
#include "gssm/model/model.h"

namespace gssm::io {

/// Whether the model reports lat, lon and height.
bool reportsGeodeticTrack(const Model& model);
/// Writes the run's rows to `path`; InputError if it cannot be written.
void writeTrackPos(const std::string& path, const Model& model, const OfflineRun& run);

}  // namespace gssm::io
