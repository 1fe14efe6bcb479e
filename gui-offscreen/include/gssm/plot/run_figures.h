#pragma once
// The standard figures of one dataset processed by several estimators:
// each constant's estimate vs time with ±3σ bands and the truth (the paper's
// Figs. 9 and 10 for the radar), each time-series state's error vs time, and
// a per-update latency histogram.
#include <string>
#include <vector>

#include <Eigen/Core>
#include <optional>

#include "gssm/core/data.h"
#include "gssm/model/model.h"
#include "gssm/analysis/offline.h"
#include "gssm/io/process.h"
#include "gssm/plot/figure.h"

namespace gssm::plot {

/// A plan view (top-down map) of a 2-D position: which stacked-state
/// components are x and y, and fixed landmarks to mark (e.g. beacons).
struct PlanView {
  Eigen::Index x = 0, y = 1;
  std::vector<Eigen::Vector2d> landmarks;
  std::string landmark_label = "beacons";
  /// Further paths drawn thin and grey (e.g. dead reckoning), with labels.
  std::vector<std::pair<std::string, std::vector<Eigen::Vector2d>>> paths;
};

/// Writes `fig-<constant>.png`, `fig-<state>-error.png` (with truth; each
/// with its band of ±band_sigmas σ), fig-trajectory.png (with a plan view)
/// and fig-latency.png into `dir`, drawing up to `threads` at a time
/// (savePngs); returns the paths written.
std::vector<std::string> writeRunFigures(const Model& model, const std::vector<OfflineRun>& runs,
                                         const Truth* truth, const std::string& dir,
                                         const std::string& scenario_label,
                                         const std::optional<PlanView>& plan = std::nullopt, int threads = 1,
                                         double band_sigmas = 3);

/// The figures writeRunFigures draws, to draw (drawPngs); the arguments
/// must outlive them.
std::vector<FigureJob> runFigureJobs(const Model& model, const std::vector<OfflineRun>& runs, const Truth* truth,
                                     const std::string& dir, const std::string& scenario_label,
                                     const std::optional<PlanView>& plan = std::nullopt, double band_sigmas = 3);

/// fig-constants-vs-reference.png, to draw: the run's final constants ±2σ,
/// in the reference's terms along `truth` (Model::comparableConstants),
/// against a calibration reference (NaN entries left out). The arguments
/// must outlive it.
FigureJob constantsReferenceFigureJob(const Model& model, const OfflineRun& run, const Eigen::VectorXd& reference,
                                      const Truth* truth, const std::string& dir, const std::string& label);

/// The figures of a processed dataset (gssm-process's, gssm.process's):
/// writeRunFigures, its bands as wide as the run's config asks ([scenario]
/// band_sigmas), with a plan view when the model has px and py (its
/// landmarks, and the dead reckoning when the rows are at inputs), and the
/// learning's log-likelihood figure when the noise was learnt, and the
/// constants against their calibration reference when the dataset has one
/// (the batch run's, else the last run's). The run figures are drawn up to
/// `threads` at a time.
std::vector<std::string> writeProcessFigures(const io::ProcessResult& result, const std::string& dir, int threads = 1);

}  // namespace gssm::plot
