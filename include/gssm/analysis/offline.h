#pragma once
// Runs an estimator over a recorded sequence of measurements in streaming
// order and collects what it reports after each one: the common back end of
// the dataset processor and the Monte Carlo runner.
#include <Eigen/Core>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "gssm/solvers/batch_solver.h"
#include "gssm/core/data.h"
#include "gssm/solvers/ekf.h"
#include "gssm/estimator/estimator.h"
#include "gssm/model/model.h"

namespace gssm {

/// The estimate of the stacked state [x_c(k); x_b] at one measurement time.
struct EstimateRow {
  double t = 0;
  Eigen::VectorXd mean;        ///< stacked [x_c; x_b]
  Eigen::MatrixXd covariance;  ///< stacked, (n_c + n_b)²
};

struct OfflineRun {
  Method method = Method::Ekf;
  std::vector<EstimateRow> rows;       ///< one per measurement (plus none for t0)
  std::vector<double> update_seconds;  ///< wall time of each update
  std::vector<double> nis;             ///< NIS of each measurement (streaming runs with compute_nis)
  double total_seconds = 0;            ///< the estimator's time: the loop, without the recorder's writing and checkpoints
  int iterations = 0;                  ///< solver iterations (batch), 0 for filters
  std::string summary;                 ///< the solver's own report line
  /// Measurements on robust channels whose weight ρ'(s) was below 1 at the
  /// estimate after their update (streaming) or at the solution (batch).
  std::size_t downweighted = 0;
  std::int64_t rejected = 0;           ///< measurements rejected by an EKF gate
};

/// Where a run reports its estimates: after each measurement (gssm's own
/// datasets), or at each state an input makes (a log's odometry steps).
/// When a streaming run records an estimate row: after every measurement;
/// at every input time (a state an input made, before the next later event);
/// or once per epoch, a distinct measurement time (after its last
/// measurement), as the batch run reports (several sensors sharing a time);
/// or at every state, an input's or an epoch's (after every event at its
/// time: an IMU's samples and each GNSS fix after its update).
enum class RowTimes { Measurements, Inputs, Epochs, States };
/// The RowTimes named "measurements", "inputs", "epochs" or "states" (an
/// INI's [dataset] rows); none for any other name.
std::optional<RowTimes> rowTimesNamed(const std::string& name);

/// Where a streaming run's records go, and what its checkpoints remember of
/// them (docs/DESIGN.md §7). The run keeps them in OfflineRun and hands the
/// new ones to the recorder at each checkpoint (before its mark) and at the
/// end; a recorder writes them somewhere (an application's output files:
/// io::RunFiles) so that a checkpoint needs to hold only how far that got.
class RunRecorder {
 public:
  virtual ~RunRecorder() = default;
  virtual void row(const EstimateRow& row) = 0;
  /// One measurement's update: its wall time and, with compute_nis, its NIS.
  virtual void update(double seconds, std::optional<double> nis) = 0;
  /// Makes every record so far durable (at least against the process
  /// being killed); returns what a checkpoint stores to come back here.
  virtual std::string mark() = 0;
  /// Continues from a mark(): puts the records up to it into run.rows,
  /// run.update_seconds and run.nis, and records on from there. Throws
  /// CheckpointError naming what does not match.
  virtual void resume(const std::string& mark, OfflineRun& run) = 0;
};

/// Checkpoints of a streaming run (checkpoint.h): each holds the estimator,
/// the run's counters and the `recorder`'s mark, so a resumed run ends with
/// the same rows, bit for bit, as an uninterrupted one. Without a recorder
/// the mark is every record so far, (1 + n + n²)·8 bytes per row for a
/// stacked state of size n; with one (gssm-process's output files) a
/// checkpoint's size does not grow with the run (the estimator's own state
/// aside: the full-history smoother's does).
struct StreamingCheckpoints {
  std::string path;         ///< file written every `every` measurements ("" = none)
  std::size_t every = 0;
  std::string resume_from;  ///< checkpoint to continue from ("" = start at the beginning)
  RunRecorder* recorder = nullptr;  ///< also gets every record; its mark() goes in the checkpoint
};

/// Streams the measurements (and inputs, in time order) through a streaming
/// estimator made by makeEstimator(model, options); rows hold current()
/// after each measurement.
/// `progress(done, total)`, if set, is called every 1% of the measurements.
/// With `checkpoints.resume_from`, the estimator and the rows so far come
/// from that checkpoint, which must have been written by a run of the same
/// method on the same measurements (CheckpointError otherwise).
OfflineRun runStreaming(const Model& model, const EstimatorOptions& options,
                        const std::vector<Measurement>& measurements,
                        const std::vector<Input>& inputs = {},
                        const std::function<void(std::size_t, std::size_t)>& progress = {},
                        const StreamingCheckpoints& checkpoints = {}, RowTimes rows = RowTimes::Measurements);

/// The batch MAP of the whole run, from `start` (every state of the run
/// and the constants: a solution of a nearby model, such as learning's
/// last E-step) or else from an EKF pass with default options; rows hold
/// the smoothed estimate at each measurement time with its marginal
/// covariance. InvalidArgument if `start` holds other variables.
OfflineRun runBatch(const Model& model, const EstimatorOptions& options,
                    const std::vector<Measurement>& measurements,
                    const std::vector<Input>& inputs = {}, RowTimes rows = RowTimes::Measurements,
                    const Values* start = nullptr);

/// options.method over the whole recording: runBatch for the batch (from
/// `batch_start` when given), runStreaming for the others (progress and
/// checkpoints apply to those).
OfflineRun runOffline(const Model& model, const EstimatorOptions& options,
                      const std::vector<Measurement>& measurements,
                      const std::vector<Input>& inputs = {},
                      const std::function<void(std::size_t, std::size_t)>& progress = {},
                      const StreamingCheckpoints& checkpoints = {}, RowTimes rows = RowTimes::Measurements,
                      const Values* batch_start = nullptr);

}  // namespace gssm
