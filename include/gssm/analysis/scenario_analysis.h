#pragma once
// The analysis behind gssm-analyze: for one scenario, how close each
// estimator gets to the Cramér–Rao bound, whether each is consistent, when
// the constants become determined, and whether the GSSM's filter, fixed-lag
// smoother or full smoother improves on the EKF — with the numbers.
#include <string>
#include <vector>

#include "gssm/analysis/bounds.h"
#include "gssm/analysis/montecarlo.h"

namespace gssm {

struct IdentifiabilityAt {
  double t = 0;
  ConstantsIdentifiability id;
  bool data_dominates = false;  ///< data information ≥ prior information in every direction
};

struct ScenarioAnalysis {
  std::string scenario;
  std::vector<std::string> state_names;
  CramerRaoBound bound;                     ///< along the dataset's true trajectory
  std::vector<IdentifiabilityAt> identifiability;
  double determined_from = -1;              ///< first t with data dominating the prior (−1: never)
  MonteCarloResult montecarlo;
  std::string markdown() const;
};

/// `recorded` is one run with its truth (a dataset with truth.csv, see
/// io::recordedRun), evaluated with the scenario's truth model; the Monte
/// Carlo simulates `scenario`.
ScenarioAnalysis analyzeScenario(const MonteCarloScenario& scenario, const SimulatedRun& recorded,
                                 const MonteCarloOptions& options,
                                 const std::function<NormalSampler(unsigned)>& sampler_for_seed);

}  // namespace gssm
