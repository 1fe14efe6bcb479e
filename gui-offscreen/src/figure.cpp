#include "gssm/plot/figure.h"

#include <mrpt/img/CImage.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <stdexcept>

#include "gssm/core/parallel.h"
#include "gssm/plot/ticks.h"

namespace gssm::plot {

namespace {
using mrpt::img::TColor;
TColor tc(Color c) { return TColor(c.r, c.g, c.b); }
constexpr int kCharW = 6, kCharH = 13;  // the "6x13" bitmap font

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(pos);
  const auto j = std::min(i + 1, v.size() - 1);
  // Selection, not a sort: O(n) for the 10⁵ latencies of a long run.
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v.end());
  const double vi = v[i];
  const double vj = j == i ? vi : *std::min_element(v.begin() + static_cast<std::ptrdiff_t>(i) + 1, v.end());
  return vi + (pos - static_cast<double>(i)) * (vj - vi);
}

// Maps data to pixels inside the plot rectangle.
struct Axes {
  int left, top, right, bottom;
  double x0, x1, y0, y1;
  double px(double x) const { return left + (x - x0) / (x1 - x0) * (right - left); }
  double py(double y) const { return bottom - (y - y0) / (y1 - y0) * (bottom - top); }
};

// Blends one colour at one opacity into an image's pixels. CImage's
// accessors check the image (loaded, not empty, its size) on every call, and
// a ±2σ band blends tens of thousands of pixels: the size, first row and row
// stride are read once, and each channel's 256 blends are tabulated (the
// same expression, so the same bytes, as computing it per pixel).
class PixelBlender {
 public:
  PixelBlender(mrpt::img::CImage& img, Color c, double a)
      : width_(static_cast<int>(img.getWidth())),
        height_(static_cast<int>(img.getHeight())),
        row0_(img.ptr<uint8_t>(0, 0)),
        stride_(height_ > 1 ? img.ptr<uint8_t>(0, 1) - row0_ : 0) {
    const unsigned char bgr[3] = {c.b, c.g, c.r};  // CImage stores BGR
    for (int k = 0; k < 3; ++k)
      for (int v = 0; v < 256; ++v) table_[k][v] = static_cast<uint8_t>((1 - a) * v + a * bgr[k] + 0.5);  // as lround
  }
  void blend(int x, int y) const {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
    uint8_t* p = row0_ + y * stride_ + 3 * x;
    for (int k = 0; k < 3; ++k) p[k] = table_[k][p[k]];
  }

 private:
  int width_, height_;
  uint8_t* row0_;
  std::ptrdiff_t stride_;
  uint8_t table_[3][256];
};

// Clips segment to the axes rectangle (Liang–Barsky); false if outside.
bool clip(const Axes& ax, double& xa, double& ya, double& xb, double& yb) {
  double t0 = 0, t1 = 1;
  const double dx = xb - xa, dy = yb - ya;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {xa - ax.left, ax.right - xa, ya - ax.top, ax.bottom - ya};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return false;
    } else {
      const double t = q[i] / p[i];
      if (p[i] < 0) t0 = std::max(t0, t);
      else t1 = std::min(t1, t);
    }
  }
  if (t0 > t1) return false;
  xb = xa + t1 * dx;
  yb = ya + t1 * dy;
  xa = xa + t0 * dx;
  ya = ya + t0 * dy;
  return true;
}

void drawSeries(mrpt::img::CImage& img, const Axes& ax, const Series& s) {
  double dash_phase = 0;
  for (std::size_t i = 1; i < s.x.size() && i < s.y.size(); ++i) {
    if (!std::isfinite(s.y[i - 1]) || !std::isfinite(s.y[i])) continue;
    double xa = ax.px(s.x[i - 1]), ya = ax.py(s.y[i - 1]), xb = ax.px(s.x[i]), yb = ax.py(s.y[i]);
    if (!clip(ax, xa, ya, xb, yb)) continue;
    if (!s.dashed) {
      img.line(static_cast<int>(std::lround(xa)), static_cast<int>(std::lround(ya)),
               static_cast<int>(std::lround(xb)), static_cast<int>(std::lround(yb)), tc(s.color),
               static_cast<unsigned>(s.width));
      continue;
    }
    const double len = std::hypot(xb - xa, yb - ya);
    for (double d = 0; d < len; d += 1.0) {  // 8 px on, 5 px off
      if (std::fmod(dash_phase + d, 13.0) < 8.0) {
        const double f = len > 0 ? d / len : 0;
        img.filledRectangle(static_cast<int>(xa + f * (xb - xa)), static_cast<int>(ya + f * (yb - ya)),
                            static_cast<int>(xa + f * (xb - xa)) + s.width - 1,
                            static_cast<int>(ya + f * (yb - ya)) + s.width - 1, tc(s.color));
      }
    }
    dash_phase += len;
  }
}

void drawBand(mrpt::img::CImage& img, const Axes& ax, const Band& b) {
  // Column by column between consecutive samples: each pixel once.
  const PixelBlender pixels(img, b.color, b.alpha);
  int last_col = std::numeric_limits<int>::min();
  for (std::size_t i = 1; i < b.x.size(); ++i) {
    const double xa = ax.px(b.x[i - 1]), xb = ax.px(b.x[i]);
    for (int col = std::max(static_cast<int>(std::ceil(xa)), ax.left);
         col <= std::min(static_cast<int>(std::floor(xb)), ax.right); ++col) {
      if (col <= last_col) continue;
      last_col = col;
      const double f = xb > xa ? (col - xa) / (xb - xa) : 0;
      const double lo = b.lo[i - 1] + f * (b.lo[i] - b.lo[i - 1]);
      const double hi = b.hi[i - 1] + f * (b.hi[i] - b.hi[i - 1]);
      if (!std::isfinite(lo) || !std::isfinite(hi)) continue;
      const int r0 = std::max(ax.top, static_cast<int>(std::lround(ax.py(hi))));
      const int r1 = std::min(ax.bottom, static_cast<int>(std::lround(ax.py(lo))));
      for (int row = r0; row <= r1; ++row) pixels.blend(col, row);
    }
  }
}

// Calls slice(i, j) for each run [i, j) of points whose x falls in one of
// `buckets` equal slices of [x0, x1] (x increasing).
template <class Slice>
void forEachSlice(const std::vector<double>& x, std::size_t n, double x0, double x1, int buckets, Slice slice) {
  auto bucket = [&](double v) { return std::isfinite(v) ? static_cast<long>((v - x0) / (x1 - x0) * buckets) : -1; };
  for (std::size_t i = 0; i < n;) {
    const long b = bucket(x[i]);
    std::size_t j = i + 1;
    while (j < n && bucket(x[j]) == b) ++j;
    slice(i, j);
    i = j;
  }
}

// The finite range of v's first n values (a unit one when they are all equal).
std::pair<double, double> finiteRange(const std::vector<double>& v, std::size_t n) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t i = 0; i < n; ++i)
    if (std::isfinite(v[i])) lo = std::min(lo, v[i]), hi = std::max(hi, v[i]);
  return {lo, hi > lo ? hi : lo + 1};
}

// What a PNG can show of a long series: x increasing, at most first, min,
// max and last of each of `buckets` equal slices of x (the line drawn
// through them covers the same pixels as through all points). Other
// series: a point is kept when it leaves the cell of the last kept one on a
// `buckets` × `buckets` grid over its range.
Series decimated(const Series& s, int buckets) {
  const std::size_t n = std::min(s.x.size(), s.y.size());
  if (n <= static_cast<std::size_t>(4 * buckets)) return s;
  Series out{s.label, {}, {}, s.color, s.width, s.dashed};
  const auto [x0, x1] = finiteRange(s.x, n);
  if (std::is_sorted(s.x.begin(), s.x.begin() + static_cast<std::ptrdiff_t>(n))) {
    forEachSlice(s.x, n, x0, x1, buckets, [&](std::size_t i, std::size_t j) {
      std::size_t lo = i, hi = i;
      for (std::size_t k = i; k < j; ++k) {
        if (!std::isfinite(s.y[k])) continue;
        if (!std::isfinite(s.y[lo]) || s.y[k] < s.y[lo]) lo = k;
        if (!std::isfinite(s.y[hi]) || s.y[k] > s.y[hi]) hi = k;
      }
      std::size_t last = n;
      for (std::size_t k : {i, std::min(lo, hi), std::max(lo, hi), j - 1})
        if (k != last) {
          out.x.push_back(s.x[k]);
          out.y.push_back(s.y[k]);
          last = k;
        }
    });
    return out;
  }
  const auto [y0, y1] = finiteRange(s.y, n);
  auto cell = [&](double v, double lo, double hi) {
    return std::isfinite(v) ? static_cast<long>((v - lo) / (hi - lo) * buckets) : -1;
  };
  long cx = -2, cy = -2;
  for (std::size_t i = 0; i < n; ++i) {
    const long bx = cell(s.x[i], x0, x1), by = cell(s.y[i], y0, y1);
    if (bx != cx || by != cy || i + 1 == n) {
      out.x.push_back(s.x[i]);
      out.y.push_back(s.y[i]);
      cx = bx, cy = by;
    }
  }
  return out;
}

// A band: per slice of x, the lowest lo and the highest hi.
Band decimated(const Band& b, int buckets) {
  const std::size_t n = std::min({b.x.size(), b.lo.size(), b.hi.size()});
  if (n <= static_cast<std::size_t>(4 * buckets) || !std::is_sorted(b.x.begin(), b.x.begin() + static_cast<std::ptrdiff_t>(n)))
    return b;
  Band out{{}, {}, {}, b.color, b.alpha};
  const auto [x0, x1] = finiteRange(b.x, n);
  forEachSlice(b.x, n, x0, x1, buckets, [&](std::size_t i, std::size_t j) {
    out.x.push_back(b.x[i]);
    out.lo.push_back(*std::min_element(b.lo.begin() + static_cast<std::ptrdiff_t>(i), b.lo.begin() + static_cast<std::ptrdiff_t>(j)));
    out.hi.push_back(*std::max_element(b.hi.begin() + static_cast<std::ptrdiff_t>(i), b.hi.begin() + static_cast<std::ptrdiff_t>(j)));
  });
  return out;
}

void centeredText(mrpt::img::CImage& img, int cx, int y, const std::string& s, TColor c,
                  int char_w = kCharW) {
  img.textOut(cx - static_cast<int>(s.size()) * char_w / 2, y, s, c);
}
}  // namespace

Color paletteColor(std::size_t i) {
  static const Color p[] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                            {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127},
                            {188, 189, 34},  {23, 190, 207}};
  return p[i % 10];
}

namespace {
// The axes of a figure: data ranges (robust quantiles unless bars or limits
// say otherwise), nice ticks, the plot area in pixels, equal aspect.
struct Layout {
  Axes ax;
  Ticks xt, yt;
};

Layout layoutAxes(const Figure& fig, const std::vector<Series>& series, int width, int height) {
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin;
  std::vector<double> ys;
  for (const auto& s : series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        xmin = std::min(xmin, s.x[i]);
        xmax = std::max(xmax, s.x[i]);
        ys.push_back(s.y[i]);
      }
  for (const auto& b : fig.bars) {
    xmin = std::min(xmin, b.x0);
    xmax = std::max(xmax, b.x1);
    ys.push_back(0);
    ys.push_back(b.height);
  }
  if (ys.empty()) xmin = 0, xmax = 1, ys = {0, 1};
  double ylo = fig.bars.empty() ? quantile(ys, fig.robust_quantile) : 0.0;
  double yhi = quantile(ys, fig.bars.empty() ? 1 - fig.robust_quantile : 1.0);
  const double pad = 0.06 * std::max(yhi - ylo, 1e-9 * std::max(1.0, std::abs(yhi)));
  const bool non_negative = *std::min_element(ys.begin(), ys.end()) >= 0;
  if (fig.bars.empty()) ylo -= pad;
  if (non_negative) ylo = std::max(ylo, 0.0);  // e.g. an RMSE axis starts at 0
  yhi += pad;
  if (fig.xlim) xmin = fig.xlim->first, xmax = fig.xlim->second;
  if (fig.ylim) ylo = fig.ylim->first, yhi = fig.ylim->second;
  Layout l{{}, niceTicks(xmin, xmax, 9), niceTicks(ylo, yhi, 8)};
  const bool x_tight = !fig.bars.empty() || fig.xlim.has_value();
  l.ax = Axes{0, 0, 0, 0, x_tight ? xmin : l.xt.lo, x_tight ? xmax : l.xt.hi, fig.ylim ? ylo : l.yt.lo,
              fig.ylim ? yhi : l.yt.hi};
  int label_w = 0;
  for (double v : l.yt.values) label_w = std::max(label_w, static_cast<int>(formatTick(v, l.yt.step).size()));
  Axes& ax = l.ax;
  ax.left = 24 + (label_w + 1) * kCharW;
  ax.top = 56;
  ax.right = width - 24;
  ax.bottom = height - 56;
  if (fig.equal_aspect) {
    const double ux = (ax.x1 - ax.x0) / (ax.right - ax.left), uy = (ax.y1 - ax.y0) / (ax.bottom - ax.top);
    const double u = std::max(ux, uy);
    const double cx = 0.5 * (ax.x0 + ax.x1), cy = 0.5 * (ax.y0 + ax.y1);
    ax.x0 = cx - 0.5 * u * (ax.right - ax.left);
    ax.x1 = cx + 0.5 * u * (ax.right - ax.left);
    ax.y0 = cy - 0.5 * u * (ax.bottom - ax.top);
    ax.y1 = cy + 0.5 * u * (ax.bottom - ax.top);
    l.xt = niceTicks(ax.x0, ax.x1, 9);
    l.yt = niceTicks(ax.y0, ax.y1, 8);
  }
  return l;
}

const TColor kGrid(225, 225, 225), kAxis(60, 60, 60), kText(30, 30, 30);

void drawGrid(mrpt::img::CImage& img, const Layout& l) {
  const Axes& ax = l.ax;
  for (double v : l.xt.values) {
    if (v < ax.x0 - 1e-12 || v > ax.x1 + 1e-12) continue;
    const int x = static_cast<int>(std::lround(ax.px(v)));
    img.line(x, ax.top, x, ax.bottom, kGrid);
    img.line(x, ax.bottom, x, ax.bottom + 5, kAxis);
    centeredText(img, x, ax.bottom + 9, formatTick(v, l.xt.step), kText);
  }
  for (double v : l.yt.values) {
    if (v < ax.y0 - 1e-12 || v > ax.y1 + 1e-12) continue;
    const int y = static_cast<int>(std::lround(ax.py(v)));
    img.line(ax.left, y, ax.right, y, kGrid);
    img.line(ax.left - 5, y, ax.left, y, kAxis);
    const std::string s = formatTick(v, l.yt.step);
    img.textOut(ax.left - 8 - static_cast<int>(s.size()) * kCharW, y - kCharH / 2, s, kText);
  }
}

void drawData(mrpt::img::CImage& img, const Axes& ax, const Figure& fig, const std::vector<Series>& series,
              const std::vector<Band>& bands) {
  for (const auto& b : bands) drawBand(img, ax, b);
  for (const auto& b : fig.bars) {
    const PixelBlender pixels(img, b.color, 0.55);
    const int x0 = static_cast<int>(std::lround(ax.px(b.x0))), x1 = static_cast<int>(std::lround(ax.px(b.x1)));
    const int y = std::max(ax.top, static_cast<int>(std::lround(ax.py(b.height))));
    for (int col = std::max(x0, ax.left); col < std::min(x1, ax.right); ++col)
      for (int row = y; row < ax.bottom; ++row) pixels.blend(col, row);
  }
  for (const auto& s : series) drawSeries(img, ax, s);
  img.rectangle(ax.left, ax.top, ax.right, ax.bottom, kAxis);
}

// The legend, top right, a line sample and the label of each labelled series.
void drawLegend(mrpt::img::CImage& img, const Axes& ax, const std::vector<Series>& series) {
  std::vector<const Series*> labelled;
  for (const auto& s : series)
    if (!s.label.empty()) labelled.push_back(&s);
  if (labelled.empty()) return;
  int w = 0;
  for (const auto* s : labelled) w = std::max(w, static_cast<int>(s->label.size()));
  const int lw = 44 + w * kCharW, lh = 8 + 18 * static_cast<int>(labelled.size());
  const int x0 = ax.right - lw - 10, y0 = ax.top + 10;
  img.filledRectangle(x0, y0, x0 + lw, y0 + lh, TColor(255, 255, 255));
  img.rectangle(x0, y0, x0 + lw, y0 + lh, TColor(170, 170, 170));
  for (std::size_t i = 0; i < labelled.size(); ++i) {
    const int y = y0 + 12 + 18 * static_cast<int>(i);
    Series sample = *labelled[i];
    Axes lax{x0, y0, x0 + lw, y0 + lh, 0, 1, 0, 1};
    sample.x = {static_cast<double>(x0 + 8 - x0) / lw, static_cast<double>(x0 + 34 - x0) / lw};
    const double yy = 1.0 - static_cast<double>(y - y0) / lh;
    sample.y = {yy, yy};
    drawSeries(img, lax, sample);
    img.textOut(x0 + 40, y - kCharH / 2, labelled[i]->label, kText);
  }
}
}  // namespace

void savePng(const Figure& fig, const std::string& path, int width, int height) {
  // Long runs (10⁵ points and more) are decimated first to what `width`
  // pixels can show: drawing cost and the axis quantiles then do not grow
  // with the run.
  std::vector<Series> series;
  std::vector<Band> bands;
  for (const auto& s : fig.series) series.push_back(decimated(s, 2 * width));
  for (const auto& b : fig.bands) bands.push_back(decimated(b, 2 * width));
  mrpt::img::CImage img(width, height, mrpt::img::CH_RGB);
  img.filledRectangle(0, 0, width - 1, height - 1, TColor(255, 255, 255));
  img.selectTextFont("6x13");
  const Layout layout = layoutAxes(fig, series, width, height);
  const Axes& ax = layout.ax;
  drawGrid(img, layout);
  drawData(img, ax, fig, series, bands);
  img.selectTextFont("10x20");
  centeredText(img, (ax.left + ax.right) / 2, 8, fig.title, kText, 10);
  img.selectTextFont("6x13");
  centeredText(img, (ax.left + ax.right) / 2, height - 26, fig.xlabel, kText);
  img.textOut(ax.left, ax.top - 20, fig.ylabel, kText);
  if (fig.legend) drawLegend(img, ax, series);
  if (!img.saveToFile(path)) throw std::runtime_error(path + ": cannot write the PNG");
}

void drawPngs(const std::vector<FigureJob>& jobs, int threads) {
  // MRPT unpacks its bitmap fonts into a global table on the first font
  // selection, unguarded: done here, before any worker draws.
  mrpt::img::CImage fonts(1, 1, mrpt::img::CH_RGB);
  fonts.selectTextFont("6x13");
  for (const auto& e : runJobs(jobs.size(), static_cast<std::size_t>(std::max(1, threads)),
                               [&](std::size_t k) { savePng(jobs[k].make(), jobs[k].path); }))
    if (e) std::rethrow_exception(e);
}

void savePngs(const std::vector<std::pair<Figure, std::string>>& figures, int threads) {
  std::vector<FigureJob> jobs;
  for (const auto& f : figures) jobs.push_back({[&f] { return f.first; }, f.second});
  drawPngs(jobs, threads);
}

Figure histogram(const std::vector<std::pair<std::string, std::vector<double>>>& groups, int bins,
                 const std::string& title, const std::string& xlabel) {
  Figure f;
  f.title = title;
  f.xlabel = xlabel;
  f.ylabel = "fraction of updates";
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& g : groups)
    if (!g.second.empty()) {
      lo = std::min(lo, quantile(g.second, 0.0));
      hi = std::max(hi, quantile(g.second, 0.99));  // the slowest 1% would squash the rest
    }
  if (!(hi > lo)) hi = lo + 1;
  const double w = (hi - lo) / bins;
  const double gw = w / static_cast<double>(std::max<std::size_t>(groups.size(), 1));
  for (std::size_t gi = 0; gi < groups.size(); ++gi) {
    const auto& vals = groups[gi].second;
    std::vector<double> count(static_cast<std::size_t>(bins), 0.0);
    for (double v : vals) {
      const int b = std::clamp(static_cast<int>((v - lo) / w), 0, bins - 1);
      count[static_cast<std::size_t>(b)] += 1.0 / static_cast<double>(vals.size());
    }
    const Color c = paletteColor(gi);
    for (int b = 0; b < bins; ++b) {
      const double x0 = lo + b * w + static_cast<double>(gi) * gw;
      f.bars.push_back({x0, x0 + gw, count[static_cast<std::size_t>(b)], c});
    }
    f.series.push_back({groups[gi].first, {}, {}, c, 6, false});  // legend entry
  }
  f.xlim = std::make_pair(lo, hi);
  return f;
}

}  // namespace gssm::plot
