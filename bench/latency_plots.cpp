// Draws the README's latency figures (gui-offscreen): median per-update
// latency vs fixed-lag window length, and vs history length for the EKF,
// fixed-lag and full-history smoothers, on the radar paper scenario.
// Usage: gssm_latency_plots OUTDIR [HISTORY_STEPS]
#include <chrono>
#include <deque>
#include <filesystem>
#include <iostream>
#include <random>

#include "gssm/estimator/estimator.h"
#include "gssm/analysis/metrics.h"
#include "gssm/models/radar2d.h"
#include "gssm/plot/figure.h"

namespace {
// Streams `steps` radar measurements; calls sample(k, median of the last 1000).
template <class Fn>
void stream(gssm::Method method, int window, long steps, long every, Fn sample) {
  const gssm::models::Radar2D radar;
  gssm::EstimatorOptions o;
  o.method = method;
  o.fixed_lag.window = o.paper_window.window = window;
  auto est = gssm::makeEstimator(radar, o);
  std::mt19937 rng(1);
  std::normal_distribution<double> n01(0, 1);
  std::deque<double> last;
  double x = 0;
  for (long k = 1; k <= steps; ++k) {
    x += 5.0;
    const Eigen::VectorXd y = Eigen::VectorXd::Constant(1, std::hypot(x, 1000.0) + 3 * n01(rng));
    const auto t0 = std::chrono::steady_clock::now();
    est->addMeasurement(k * 0.05, y);
    last.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (last.size() > 1000) last.pop_front();
    if (k % every == 0) sample(k, gssm::percentile(std::vector<double>(last.begin(), last.end()), 50));
  }
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') {  // an option is no folder name ("--help")
    std::cerr << "usage: gssm_latency_plots OUTDIR [HISTORY_STEPS]\n";
    return 2;
  }
  namespace fs = std::filesystem;
  const fs::path out = argv[1];
  const long history = argc > 2 ? std::atol(argv[2]) : 100000;
  fs::create_directories(out);

  gssm::plot::Figure w;
  w.title = "median per-update latency vs window length (radar, 3000 steps)";
  w.xlabel = "window length w (states kept)";
  w.ylabel = "median latency (us)";
  gssm::plot::Series fl{"fixed-lag smoother", {}, {}, gssm::plot::paletteColor(1), 2, false};
  gssm::plot::Series pw{"paper window (a window re-solve)", {}, {}, gssm::plot::paletteColor(3), 2, false};
  gssm::plot::Series ekf{"EKF", {}, {}, gssm::plot::paletteColor(0), 2, true};
  double ekf_median = 0;
  stream(gssm::Method::Ekf, 10, 3000, 3000, [&](long, double m) { ekf_median = m; });
  for (int win : {1, 2, 5, 10, 20, 50, 100, 200}) {
    stream(gssm::Method::FixedLag, win, 3000, 3000, [&](long, double m) {
      fl.x.push_back(win);
      fl.y.push_back(m * 1e6);
    });
    if (win >= 2 && win <= 100)  // the paper window's priors go on its second-oldest state
      stream(gssm::Method::PaperWindow, win, 1000, 1000, [&](long, double m) {
        pw.x.push_back(win);
        pw.y.push_back(m * 1e6);
      });
    ekf.x.push_back(win);
    ekf.y.push_back(ekf_median * 1e6);
    std::cout << "w = " << win << ": fixed-lag " << fl.y.back() << " us\n";
  }
  w.series = {fl, pw, ekf};
  w.robust_quantile = 0.0;
  gssm::plot::savePng(w, (out / "latency-vs-window.png").string());

  gssm::plot::Figure h;
  h.title = "median per-update latency vs history length (radar, last 1000 updates)";
  h.xlabel = "step k (thousands)";
  h.ylabel = "median latency (us)";
  const long every = std::max(1000L, history / 50);
  std::size_t color = 0;
  for (const gssm::Method m : {gssm::Method::Ekf, gssm::Method::FixedLag, gssm::Method::Incremental}) {
    gssm::plot::Series s{gssm::methodName(m), {}, {}, gssm::plot::paletteColor(color++), 2, false};
    stream(m, 10, history, every, [&](long k, double med) {
      s.x.push_back(k / 1000.0);
      s.y.push_back(med * 1e6);
    });
    std::cout << m << " at " << history << " steps: " << s.y.back() << " us\n";
    h.series.push_back(std::move(s));
  }
  h.robust_quantile = 0.0;
  gssm::plot::savePng(h, (out / "latency-vs-history.png").string());
  std::cout << "figures: " << (out / "latency-vs-window.png").string() << ", "
            << (out / "latency-vs-history.png").string() << "\n";
  return 0;
}
