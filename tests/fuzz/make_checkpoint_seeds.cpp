// Writes the checkpoint fuzzer's seed corpus: one checkpoint per method of a
// 6-step radar run (window 3). Run after a format change (with a new
// kCheckpointVersion):  make_checkpoint_seeds tests/fuzz/corpus/checkpoint
#include <random>
#include <string>

#include "gssm/checkpoint/checkpoint.h"
#include "gssm/models/radar2d.h"
#include "gssm/model/simulation.h"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const gssm::models::Radar2D radar;
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  gssm::SimulationSpec spec;
  spec.steps = 8;
  const auto run = gssm::simulate(radar, spec, [&] { return normal(rng); });
  for (const auto& method : gssm::streamingMethods()) {
    gssm::EstimatorOptions o;
    o.method = method;
    o.fixed_lag.window = o.paper_window.window = 3;
    auto est = gssm::makeEstimator(radar, o);
    for (int k = 0; k < 6; ++k) est->addMeasurement(run.measurements[k].t, run.measurements[k].y);
    gssm::saveCheckpoint(*est, std::string(argv[1]) + "/radar-" + gssm::methodName(method) + ".ckpt", "seed");
  }
  return 0;
}
