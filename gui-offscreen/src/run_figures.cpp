#include "gssm/plot/run_figures.h"
#include "gssm/plot/learn_figure.h"
#include "gssm/plot/withheld_figures.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "gssm/core/angles.h"
#include "gssm/core/time.h"
#include "gssm/io/config.h"
#include "gssm/io/number_text.h"
#include "gssm/plot/figure.h"

namespace gssm::plot {

namespace {
std::string display(Method method) { return methodInfo(method).label; }

// Column of a stacked component in the truth's rows, or −1 if it has none.
Eigen::Index truthColumn(const Truth* truth, Eigen::Index stacked) {
  if (!truth) return -1;
  if (truth->components.empty()) return stacked;
  const auto it = std::find(truth->components.begin(), truth->components.end(), static_cast<int>(stacked));
  return it == truth->components.end() ? -1 : static_cast<Eigen::Index>(it - truth->components.begin());
}
}  // namespace

namespace {
// One run's estimate of stacked state idx (minus the truth, for a
// time-series state) with its band of ±k σ.
void addStateSeries(Figure& f, const OfflineRun& run, Color c, const Truth* truth, Eigen::Index idx,
                    Eigen::Index tcol, bool constant, bool angle, double k) {
  Series s{display(run.method), {}, {}, c, 2, false};
  Band b{{}, {}, {}, c, 0.15};
  std::optional<TimeMatcher> match;
  if (truth) match.emplace(truth->times);
  for (auto* v : {&s.x, &s.y, &b.x, &b.lo, &b.hi}) v->reserve(run.rows.size());
  for (const auto& row : run.rows) {
    double ref = 0;
    if (!constant) {
      const auto j = match->find(row.t);
      if (!j) continue;  // no truth at this time: no error to draw
      ref = truth->states[*j][tcol];
    }
    double v = row.mean[idx] - ref;
    if (angle) v = wrapAngle(v);
    const double sd = std::sqrt(row.covariance(idx, idx));
    s.x.push_back(row.t);
    s.y.push_back(v);
    b.x.push_back(row.t);
    b.lo.push_back(v - k * sd);
    b.hi.push_back(v + k * sd);
  }
  f.bands.push_back(std::move(b));
  f.series.push_back(std::move(s));
}

// A constant's estimates (with its truth), or a time-series state's errors.
Figure stateFigure(const Model& model, const std::vector<OfflineRun>& runs, const Truth* truth, std::size_t i,
                   const std::string& label, double k) {
  const auto names = model.stackedStateNames();
  const auto idx = static_cast<Eigen::Index>(i);
  const bool constant = static_cast<int>(i) >= model.dims().nc;
  const Eigen::Index tcol = truthColumn(truth, idx);
  const auto& angles = model.angleStates();
  const bool angle = std::find(angles.begin(), angles.end(), static_cast<int>(idx)) != angles.end();
  Figure f;
  const std::string band = io::formatDouble(k) + "-sigma band";
  f.title = constant ? names[i] + ": estimate and " + band + " (" + label + ")"
                     : names[i] + " error: estimate - truth, with " + band + " (" + label + ")";
  f.xlabel = "time t (s)";
  f.ylabel = constant ? names[i] : names[i] + " error";
  for (std::size_t r = 0; r < runs.size(); ++r)
    addStateSeries(f, runs[r], paletteColor(r), truth, idx, tcol, constant, angle, k);
  if (constant && tcol >= 0) {
    Series t{"truth", truth->times, {}, Color{0, 0, 0}, 1, true};
    for (const auto& z : truth->states) t.y.push_back(z[tcol]);
    f.series.push_back(std::move(t));
  } else if (!constant) {
    f.series.push_back(
        {"zero error", {runs.front().rows.front().t, runs.front().rows.back().t}, {0, 0}, Color{0, 0, 0}, 1, true});
  }
  return f;
}

// The plan view: truth, estimates, other paths, landmarks.
Figure planFigure(const std::vector<std::string>& names, const std::vector<OfflineRun>& runs, const Truth* truth,
                  const PlanView& plan, const std::string& label) {
  const Eigen::Index ix = plan.x, iy = plan.y;
  Figure f;
  f.equal_aspect = true;
  f.title = "trajectory, plan view (" + label + ")";
  f.xlabel = names.at(static_cast<std::size_t>(ix)) + " (m)";
  f.ylabel = names.at(static_cast<std::size_t>(iy)) + " (m)";
  f.robust_quantile = 0.0;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    Series s{display(runs[r].method), {}, {}, paletteColor(r), 2, false};
    for (const auto& row : runs[r].rows) {
      s.x.push_back(row.mean[ix]);
      s.y.push_back(row.mean[iy]);
    }
    f.series.push_back(std::move(s));
  }
  const Eigen::Index tx = truthColumn(truth, ix), ty = truthColumn(truth, iy);
  if (tx >= 0 && ty >= 0) {
    Series t{"truth", {}, {}, Color{0, 0, 0}, 1, true};
    for (const auto& z : truth->states) {
      t.x.push_back(z[tx]);
      t.y.push_back(z[ty]);
    }
    f.series.push_back(std::move(t));
  }
  for (const auto& [path_label, path] : plan.paths) {
    Series p{path_label, {}, {}, Color{150, 150, 150}, 1, false};
    for (const auto& q : path) {
      p.x.push_back(q.x());
      p.y.push_back(q.y());
    }
    f.series.push_back(std::move(p));
  }
  // A small square marker per landmark, drawn as a closed series: 1.2% of
  // the drawing's extent (3 m on Plaza's 250 m, 12 cm in a 10 m room).
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& s : f.series)
    for (std::size_t i = 0; i < s.x.size(); ++i)
      lo = std::min({lo, s.x[i], s.y[i]}), hi = std::max({hi, s.x[i], s.y[i]});
  for (const auto& c : plan.landmarks) lo = std::min({lo, c.x(), c.y()}), hi = std::max({hi, c.x(), c.y()});
  const double h = hi > lo ? 0.012 * (hi - lo) : 1.0;
  for (std::size_t b = 0; b < plan.landmarks.size(); ++b) {
    const Eigen::Vector2d c = plan.landmarks[b];
    Series m{b == 0 ? plan.landmark_label : "", {c.x() - h, c.x() + h, c.x() + h, c.x() - h, c.x() - h},
             {c.y() - h, c.y() - h, c.y() + h, c.y() + h, c.y() - h}, Color{200, 0, 0}, 3, false};
    f.series.push_back(std::move(m));
  }
  // Headroom above the data for the legend (it would hide a beacon).
  double ylo = INFINITY, yhi = -INFINITY;
  for (const auto& s : f.series)
    for (double y : s.y) ylo = std::min(ylo, y), yhi = std::max(yhi, y);
  if (yhi > ylo) f.ylim = std::make_pair(ylo - 0.05 * (yhi - ylo), yhi + 0.55 * (yhi - ylo));
  return f;
}

// The planar position error over time (the truth has the position).
Figure positionErrorFigure(const std::vector<OfflineRun>& runs, const Truth& truth, Eigen::Index ix, Eigen::Index iy,
                           Eigen::Index tx, Eigen::Index ty, const std::string& label) {
  Figure e;
  e.title = "position error |estimate - truth| (" + label + ")";
  e.xlabel = "time t (s)";
  e.ylabel = "position error (m)";
  for (std::size_t r = 0; r < runs.size(); ++r) {
    Series s{display(runs[r].method), {}, {}, paletteColor(r), 2, false};
    TimeMatcher match(truth.times);
    for (const auto& row : runs[r].rows) {
      const auto j = match.find(row.t);
      if (!j) continue;
      s.x.push_back(row.t);
      s.y.push_back(std::hypot(row.mean[ix] - truth.states[*j][tx], row.mean[iy] - truth.states[*j][ty]));
    }
    e.series.push_back(std::move(s));
  }
  return e;
}

// Histograms of the per-update latency; none without two updates.
std::optional<Figure> latencyFigure(const std::vector<OfflineRun>& runs, const std::string& label) {
  std::vector<std::pair<std::string, std::vector<double>>> lat;
  for (const auto& r : runs)
    if (r.update_seconds.size() > 1) {
      std::vector<double> us;
      for (double s : r.update_seconds) us.push_back(std::log10(std::max(s * 1e6, 1e-3)));
      lat.emplace_back(display(r.method), us);
    }
  if (lat.empty()) return std::nullopt;
  return histogram(lat, 40, "per-update latency (" + label + ")",
                   "log10 of latency in microseconds (1 = 10 us, 2 = 100 us); slowest 1% not shown");
}
}  // namespace

std::vector<FigureJob> runFigureJobs(const Model& model, const std::vector<OfflineRun>& runs, const Truth* truth,
                                     const std::string& dir, const std::string& scenario_label,
                                     const std::optional<PlanView>& plan, double band_sigmas) {
  namespace fs = std::filesystem;
  std::vector<FigureJob> jobs;
  const auto add = [&](std::function<Figure()> make, const std::string& name) {
    jobs.push_back({std::move(make), (fs::path(dir) / name).string()});
  };
  const auto names = model.stackedStateNames();
  for (std::size_t i = 0; i < names.size(); ++i) {
    const bool constant = static_cast<int>(i) >= model.dims().nc;
    if (!constant && truthColumn(truth, static_cast<Eigen::Index>(i)) < 0) continue;  // an error needs the truth
    add([&model, &runs, truth, i, scenario_label, band_sigmas] {
          return stateFigure(model, runs, truth, i, scenario_label, band_sigmas);
        },
        "fig-" + names[i] + (constant ? "" : "-error") + ".png");
  }
  if (plan) {
    add([names, &runs, truth, &plan, scenario_label] { return planFigure(names, runs, truth, *plan, scenario_label); },
        "fig-trajectory.png");
    const Eigen::Index tx = truthColumn(truth, plan->x), ty = truthColumn(truth, plan->y);
    if (tx >= 0 && ty >= 0)
      add([&runs, truth, &plan, tx, ty, scenario_label] {
        return positionErrorFigure(runs, *truth, plan->x, plan->y, tx, ty, scenario_label);
      }, "fig-position-error.png");
  }
  if (auto latency = latencyFigure(runs, scenario_label))
    add([figure = std::move(*latency)] { return figure; }, "fig-latency.png");
  return jobs;
}

std::vector<std::string> writeRunFigures(const Model& model, const std::vector<OfflineRun>& runs,
                                         const Truth* truth, const std::string& dir,
                                         const std::string& scenario_label, const std::optional<PlanView>& plan,
                                         int threads, double band_sigmas) {
  const std::vector<FigureJob> jobs = runFigureJobs(model, runs, truth, dir, scenario_label, plan, band_sigmas);
  drawPngs(jobs, threads);
  std::vector<std::string> written;
  for (const auto& j : jobs) written.push_back(j.path);
  return written;
}

namespace {
// The tracks of the points the body carries (a trolley's tags), from the
// last run's estimates.
void addBodyPointTracks(const Model& model, const io::ProcessResult& r, PlanView& plan) {
  const auto names = model.bodyPointNames();
  if (names.empty() || r.runs.empty()) return;
  std::vector<std::vector<Eigen::Vector2d>> tracks(names.size());
  const auto nc = static_cast<Eigen::Index>(model.dims().nc);
  for (const auto& row : r.runs.back().rows) {
    const auto points = model.bodyPoints(row.mean.head(nc));
    for (std::size_t i = 0; i < points.size() && i < tracks.size(); ++i) tracks[i].push_back(points[i]);
  }
  for (std::size_t i = 0; i < names.size(); ++i)
    plan.paths.emplace_back(names[i] + " (" + display(r.runs.back().method) + ")", std::move(tracks[i]));
}
}  // namespace

std::vector<std::string> writeProcessFigures(const io::ProcessResult& r, const std::string& dir, int threads) {
  const Model& model = *r.model;
  std::optional<PlanView> plan;
  const auto names = model.stackedStateNames();
  const auto px = std::find(names.begin(), names.end(), "px"), py = std::find(names.begin(), names.end(), "py");
  if (px != names.end() && py != names.end()) {
    plan = PlanView{px - names.begin(), py - names.begin(), model.landmarks(), "beacons", {}};
    if (r.dead_reckoning) {
      std::vector<Eigen::Vector2d> path;
      for (const auto& row : r.dead_reckoning->rows) path.emplace_back(row.mean[plan->x], row.mean[plan->y]);
      plan->paths.emplace_back("dead reckoning", std::move(path));
    }
    addBodyPointTracks(model, r, *plan);
  }
  // One list, drawn `threads` at a time: the run figures, the learning's,
  // the constants against their reference.
  std::vector<FigureJob> jobs =
      runFigureJobs(model, r.runs, r.dataset.truth ? &*r.dataset.truth : nullptr, dir, r.label, plan,
                    io::figureBandSigmas(r.config));
  if (r.learnt) jobs.push_back(learningFigureJob(*r.learnt, dir, r.label));
  for (auto& job : withheldFigureJobs(r, dir)) jobs.push_back(std::move(job));
  if (r.dataset.constants_reference && !r.runs.empty() && model.dims().nb > 0) {
    const auto batch = std::find_if(r.runs.begin(), r.runs.end(), [](const OfflineRun& x) { return x.method == Method::Batch; });
    const OfflineRun& run = batch != r.runs.end() ? *batch : r.runs.back();
    if (!run.rows.empty())
      jobs.push_back(constantsReferenceFigureJob(model, run, *r.dataset.constants_reference,
                                                 r.dataset.truth ? &*r.dataset.truth : nullptr, dir, r.label));
  }
  drawPngs(jobs, threads);
  std::vector<std::string> files;
  for (const auto& j : jobs) files.push_back(j.path);
  return files;
}

}  // namespace gssm::plot
