#pragma once
// Errors at single measurements as a CSV: t, horizontal_error (the norm of
// the first two components), then error_0, error_1, ... (prediction −
// measurement, in the channel's components). gssm-process writes each
// method's errors at a log's withheld measurements (withheld-<method>.csv)
// and --causal-map's (causal-map.csv) with it, so that any part of a log
// (one outage) can be scored from them.
#include <string>
#include <vector>

#include "gssm/analysis/metrics.h"

namespace gssm::io {

/// Writes `errors` to `path`; InputError if it cannot be written.
void writePointErrorsCsv(const std::string& path, const std::vector<PointError>& errors);

}  // namespace gssm::io
