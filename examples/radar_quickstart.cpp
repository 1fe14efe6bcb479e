// The README's first lines of C++, as a program: the paper's radar example
// streamed through the fixed-lag smoother, checkpointed and continued.
// Run from the repository root (ctest does): reads datasets/radar-paper.
// Exit code 0 when the continued run ends where the uninterrupted one does.
#include <cstdio>
#include <iostream>

#include "gssm/checkpoint/checkpoint.h"

// [quickstart]
#include <gssm/estimator/estimator.h>
#include <gssm/io/dataset.h>
#include <gssm/models/radar2d.h>
// [/quickstart]

int main() {
  // [quickstart]
  gssm::models::Radar2D radar;                          // the paper's settings
  gssm::io::Dataset data;
  gssm::io::readDatasetData("datasets/radar-paper", radar, data);
  gssm::EstimatorOptions opts;
  opts.method = gssm::Method::FixedLag;                 // or Ekf | Incremental | PaperWindow
  opts.fixed_lag.window = 10;
  auto est = gssm::makeEstimator(radar, opts);          // same model object for every method
  for (const auto& m : data.measurements)
    est->addMeasurement(m.t, m.y);                      // strong exception guarantee
  gssm::StateEstimate e = est->current();               // [x; xdot; h] and its covariance
  std::cout << e.mean.transpose() << "\n" << e.covariance << "\n" << est->report().detail << "\n";
  // [/quickstart]

  // [checkpoint]
  gssm::saveCheckpoint(*est, "run.ckpt");                  // atomic: temp file + rename
  auto again = gssm::restoreCheckpoint(radar, "run.ckpt");  // continues with the same bits
  // [/checkpoint]
  std::remove("run.ckpt");
  const double t = data.measurements.back().t + radar.noise().T;
  const Eigen::VectorXd y = data.measurements.back().y;
  est->addMeasurement(t, y);
  again->addMeasurement(t, y);
  const bool same = est->current().mean == again->current().mean;
  std::cout << (same ? "the restored estimator continues with the same bits\n" : "restored run differs\n");
  return same ? 0 : 1;
}
