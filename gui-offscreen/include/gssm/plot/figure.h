#pragma once
// Offscreen PNG figures drawn with MRPT's CImage canvas (no display, no window
// system): title, axis labels, round-number ticks, grid, legend, line series,
// shaded ±kσ bands, truth as a reference line, and an automatic y range that a
// first-step outlier cannot squash.
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace gssm::plot {

struct Color {
  unsigned char r = 0, g = 0, b = 0;
};

/// A qualitative palette (Tableau 10), by index.
Color paletteColor(std::size_t i);

struct Series {
  std::string label;
  std::vector<double> x, y;
  Color color;
  int width = 2;
  bool dashed = false;
};

/// A shaded band between lo(x) and hi(x), e.g. estimate ± 3σ.
struct Band {
  std::vector<double> x, lo, hi;
  Color color;
  double alpha = 0.18;
};

struct Bar {
  double x0, x1, height;
  Color color;
};

struct Figure {
  std::string title, xlabel, ylabel;
  std::vector<Band> bands;      ///< drawn first
  std::vector<Bar> bars;
  std::vector<Series> series;   ///< drawn in order, legend in order
  std::optional<std::pair<double, double>> xlim, ylim;  ///< fixed ranges
  /// Automatic y range from the [q, 1−q] quantiles of the series' values
  /// (bands excluded), so a start-up transient does not squash the rest.
  double robust_quantile = 0.01;
  bool legend = true;
  /// One unit is the same length on both axes (a plan view: a circle stays
  /// a circle); the shorter range is widened about its centre.
  bool equal_aspect = false;
};

/// Draws the figure into a PNG of the given size; throws std::runtime_error
/// if the file cannot be written.
void savePng(const Figure& fig, const std::string& path, int width = 960, int height = 600);
/// A figure to draw into `path`, built by `make` on the thread that draws
/// it: building one reads a column of every row of every run (a UWB run's
/// 13,500 rows × 5 methods, each row's covariance a heap block of its own),
/// as much work as drawing it.
struct FigureJob {
  std::function<Figure()> make;
  std::string path;
};
/// Builds and draws each job's figure (savePng), up to `threads` at a time
/// in the jobs' order: the same files as one after another. An error is
/// rethrown once every figure was tried.
void drawPngs(const std::vector<FigureJob>& jobs, int threads);
/// drawPngs of figures already built.
void savePngs(const std::vector<std::pair<Figure, std::string>>& figures, int threads);

/// A histogram figure of `values` (e.g. latencies) with `bins` bins per group;
/// each group is one labelled colour.
Figure histogram(const std::vector<std::pair<std::string, std::vector<double>>>& groups, int bins,
                 const std::string& title, const std::string& xlabel);

}  // namespace gssm::plot
