#pragma once
// Internal: GNSS fixes of an RTKLIB .pos as a model's measurements ([dataset]
// gnss and its keys; include/gssm/io/dataset.h).
#include <string>

#include "gssm/io/dataset.h"
#include "gssm/io/ini.h"

namespace gssm::io {

/// Appends the fixes of `path` to out.measurements (in time order with
/// what is there), those inside the outages of `outages_path` (empty: none)
/// to out.withheld. InputError naming the file and what is wrong (a model
/// without a geodetic frame, an unknown channel, a malformed outage row).
void readGnssMeasurements(const std::string& path, const std::string& outages_path, const IniDocument& ini,
                          const Model& model, Dataset& out);

}  // namespace gssm::io
