#pragma once
// Checkpoint and restore of a streaming estimator (docs/DESIGN.md §7).
//
// A checkpoint holds the estimator's whole state: its options, the step
// counter and time, the input in force, and the method's state (EKF: mean
// and covariance; smoothers: every factor with its linearization, the Bayes
// tree's conditionals, the current values, the marginal priors of the fixed
// lag; paper window: its factors, priors and values). Restoring it and
// continuing gives the same bits as the uninterrupted run, for the same
// build.
//
//   auto est = gssm::makeEstimator(radar, {gssm::Method::FixedLag});
//   ...                                  // feed data
//   gssm::saveCheckpoint(*est, "run.ckpt");
//   auto again = gssm::restoreCheckpoint(radar, "run.ckpt");   // continue
//
// File format (version 2; docs/DESIGN.md §7): "GSSMCKPT", u32 version, u64 payload size, u64
// FNV-1a checksum of the payload, then the payload; scalars little-endian
// IEEE-754. A truncated, corrupted or foreign file, a newer version, or a
// checkpoint written with another model is rejected with a CheckpointError
// that says which and where; nothing is half-restored.
#include <cstdint>
#include <memory>
#include <string>

#include "gssm/core/error.h"
#include "gssm/estimator/estimator.h"

namespace gssm {

/// Version 2 added the EKF's count of gated measurements, version 3 the
/// counts of late measurements and EstimatorOptions::drop_late; older files
/// still restore (those start at 0 and false). Version 4 the smoothers'
/// full-pass schedule (SmootherOptions::full_pass_growth and its counts;
/// older files resume with growth 1, a pass whenever the constants moved).
/// Version 5 the point of the paper window's kept factorization (its last
/// Gauss–Newton step is not relinearized; older files use the window's
/// values). Version 6 SmootherOptions::full_pass_rounds (older files: 1).
constexpr std::uint32_t kCheckpointVersion = 6;

/// What a checkpoint says about itself (filled by restore).
struct CheckpointInfo {
  std::uint32_t version = 0;
  Method method = Method::FixedLag;  ///< estimator method
  std::string model;         ///< Model::name() of the model that wrote it
  std::int64_t step = 0;     ///< the estimator's step counter
  double time = 0;           ///< time of its newest state
  std::string user_data;     ///< opaque bytes the application stored with it
};

/// The checkpoint of `estimator` as bytes; `user_data` is stored verbatim
/// (an application's own progress, e.g. rows consumed).
std::string checkpointBytes(const Estimator& estimator, const std::string& user_data = "");
/// Writes the checkpoint to `path` atomically (a temporary file renamed over
/// it), so a crash while writing leaves the previous checkpoint intact.
void saveCheckpoint(const Estimator& estimator, const std::string& path,
                    const std::string& user_data = "");

/// A new estimator on `model` in the state the checkpoint holds. `source`
/// names the bytes in error messages. The model must be the one that wrote
/// the checkpoint (same name, dimensions and noise/prior parameters).
std::unique_ptr<Estimator> restoreCheckpointBytes(const Model& model, const std::string& bytes,
                                                  const std::string& source = "checkpoint",
                                                  CheckpointInfo* info = nullptr);
std::unique_ptr<Estimator> restoreCheckpoint(const Model& model, const std::string& path,
                                             CheckpointInfo* info = nullptr);

}  // namespace gssm
