#include "gssm/plot/withheld_figures.h"

#include <cmath>
#include <filesystem>

#include "gssm/analysis/metrics.h"

namespace gssm::plot {

namespace {
// Fixes as east/north markers: a short cross each.
Series markers(const std::string& label, const std::vector<Measurement>& ms, Color c, double h) {
  Series s{label, {}, {}, c, 1, false};
  for (const Measurement& m : ms) {
    const double e = m.y[1], n = m.y[0], nan = std::nan("");
    s.x.insert(s.x.end(), {e - h, e + h, nan, e, e, nan});
    s.y.insert(s.y.end(), {n, n, nan, n - h, n + h, nan});
  }
  return s;
}

Figure trackFigure(const io::ProcessResult& r) {
  const Model& model = *r.model;
  const int nc = model.dims().nc, nb = model.dims().nb, channel = r.dataset.withheld.front().channel;
  Figure f;
  f.equal_aspect = true;
  f.robust_quantile = 0.0;
  f.title = "antenna track, outages withheld (" + r.label + ")";
  f.xlabel = "east (m)";
  f.ylabel = "north (m)";
  f.series.push_back(markers("fixes used", io::usedOnWithheldChannel(r.dataset), Color{170, 170, 170}, 0.6));
  Series truth = markers("fixes withheld (truth)", r.dataset.withheld, Color{0, 0, 0}, 0.6);
  truth.width = 3;
  f.series.push_back(std::move(truth));
  for (std::size_t k = 0; k < r.runs.size(); ++k) {
    Series s{methodInfo(r.runs[k].method).label, {}, {}, paletteColor(k), 2, false};
    for (const EstimateRow& row : r.runs[k].rows) {
      const Eigen::VectorXd y = model.h(channel, row.mean.head(nc), row.mean.tail(nb));
      s.x.push_back(y[1]), s.y.push_back(y[0]);
    }
    f.series.push_back(std::move(s));
  }
  return f;
}

// One outage up close: each method's antenna error north (solid) and east
// (dashed) at the withheld fixes, against the time since the outage began.
Figure outageFigure(const io::ProcessResult& r, std::size_t k) {
  const auto [from, to] = r.dataset.outages[k];
  std::vector<Measurement> inside;
  for (const Measurement& m : r.dataset.withheld)
    if (m.t >= from && m.t < to) inside.push_back(m);
  Figure f;
  f.robust_quantile = 0.0;
  f.title = "outage " + std::to_string(k + 1) + ": antenna error north (solid), east (dashed) (" + r.label + ")";
  f.xlabel = "time since the outage began (s)";
  f.ylabel = "error (m)";
  for (std::size_t j = 0; j < r.runs.size(); ++j) {
    const std::string label = methodInfo(r.runs[j].method).label;
    Series north{label, {}, {}, paletteColor(j), 2, false}, east{"", {}, {}, paletteColor(j), 2, true};
    for (const PointError& p : predictionErrorSeries(*r.model, r.runs[j], r.dataset.inputs, inside)) {
      north.x.push_back(p.t - from), north.y.push_back(p.error[0]);
      east.x.push_back(p.t - from), east.y.push_back(p.error[1]);
    }
    f.series.push_back(std::move(north));
    f.series.push_back(std::move(east));
  }
  return f;
}

Figure errorFigure(const io::ProcessResult& r) {
  const double t0 = r.dataset.t0;
  Figure f;
  f.title = "antenna horizontal error at each RTK fix, outages shaded (" + r.label + ")";
  f.xlabel = "time since the start (s)";
  f.ylabel = "horizontal error (m)";
  f.robust_quantile = 0.0;
  std::vector<Measurement> all = io::usedOnWithheldChannel(r.dataset);
  all.insert(all.end(), r.dataset.withheld.begin(), r.dataset.withheld.end());
  std::sort(all.begin(), all.end(), [](const Measurement& a, const Measurement& b) { return a.t < b.t; });
  double top = 0;
  for (std::size_t k = 0; k < r.runs.size(); ++k) {
    Series s{methodInfo(r.runs[k].method).label, {}, {}, paletteColor(k), 2, false};
    for (const PointError& p : predictionErrorSeries(*r.model, r.runs[k], r.dataset.inputs, all)) {
      s.x.push_back(p.t - t0);
      s.y.push_back(p.error.head<2>().norm());
      top = std::max(top, s.y.back());
    }
    f.series.push_back(std::move(s));
  }
  for (const auto& [a, b] : r.dataset.outages)
    f.bands.push_back({{a - t0, b - t0}, {0.0, 0.0}, {1.05 * top, 1.05 * top}, Color{120, 120, 120}, 0.15});
  return f;
}
}  // namespace

std::vector<FigureJob> withheldFigureJobs(const io::ProcessResult& r, const std::string& dir) {
  if (r.dataset.withheld.empty() || r.runs.empty() || r.dataset.withheld.front().y.size() < 2) return {};
  const auto path = [&](const char* name) { return (std::filesystem::path(dir) / name).string(); };
  std::vector<FigureJob> jobs{{[&r] { return trackFigure(r); }, path("fig-track.png")},
                              {[&r] { return errorFigure(r); }, path("fig-horizontal-error.png")}};
  for (std::size_t k = 0; k < r.dataset.outages.size(); ++k)
    jobs.push_back({[&r, k] { return outageFigure(r, k); },
                    path(("fig-outage-" + std::to_string(k + 1) + ".png").c_str())});
  return jobs;
}

}  // namespace gssm::plot
