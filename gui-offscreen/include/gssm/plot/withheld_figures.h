#pragma once
// Figures of a log whose fixes inside outages were withheld from the
// estimators (a GNSS/INS drive, issue #37): the antenna's track per method
// in east/north with the used and the withheld fixes, and each method's
// horizontal error at every fix over time with the outages shaded.
#include <string>
#include <vector>

#include "gssm/io/process.h"
#include "gssm/plot/figure.h"

namespace gssm::plot {

/// fig-track.png, fig-horizontal-error.png and `fig-outage-<k>.png` (each
/// outage up close), to draw; none when the dataset withholds nothing. `r`
/// must outlive them.
std::vector<FigureJob> withheldFigureJobs(const io::ProcessResult& r, const std::string& dir);

}  // namespace gssm::plot
