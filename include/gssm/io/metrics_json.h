#pragma once
// metrics.json: the metrics of several runs of one dataset, and how much of
// the dataset they cover.
#include <string>
#include <vector>

#include "gssm/analysis/metrics.h"

namespace gssm::io {

/// How much of the dataset the runs cover.
struct DatasetStatus {
  bool partial = false;               ///< processing stopped at a bad row
  std::string stopped_at;             ///< the error that stopped it
  std::vector<std::string> skipped;   ///< rows skipped (--skip-bad-rows)
  std::size_t late_rows = 0;          ///< rows out of time order, put in order
  double max_lateness = 0;            ///< the latest of them, s
};

/// metrics.json for several runs of one dataset.
std::string metricsJson(const std::vector<RunMetrics>& runs, const std::string& dataset,
                        const DatasetStatus& status = {});

}  // namespace gssm::io
