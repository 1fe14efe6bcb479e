#pragma once
// A bundled dataset as gssm-process reads it: its model, data and estimator
// options from its own scenario.ini (the benches on real logs load this way).
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "gssm/estimator/estimator.h"
#include "gssm/io/config.h"
#include "gssm/io/dataset.h"

namespace gssm::bench {

struct BundledDataset {
  std::unique_ptr<Model> model;
  io::Dataset data;
  EstimatorOptions options;  ///< from the scenario.ini, t0 the data's
};

/// datasets/<name> of this source tree (GSSM_SOURCE_DIR), with `changes`
/// ({section, key, value}) made to its scenario.ini.
inline BundledDataset loadBundledDataset(const std::string& name,
                                         const std::vector<std::array<std::string, 3>>& changes = {}) {
  BundledDataset d;
  const std::string dir = std::string(GSSM_SOURCE_DIR) + "/datasets/" + name;
  io::IniDocument ini = io::readScenario(dir);
  for (const auto& [section, key, value] : changes) ini.set(section, key, value);
  d.model = io::makeModel(ini, dir);
  io::readDatasetData(dir, *d.model, d.data, io::BadRows::Throw, &ini);
  d.options = io::estimatorOptions(ini, *d.model);
  d.options.t0 = d.data.t0;
  return d;
}

}  // namespace gssm::bench
