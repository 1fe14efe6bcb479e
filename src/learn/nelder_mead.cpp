#include "learn/nelder_mead.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace gssm::internal {

namespace {
struct Simplex {
  std::vector<Eigen::VectorXd> x;
  std::vector<double> f;
  void sort() {
    std::vector<std::size_t> order(x.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return f[a] < f[b]; });
    std::vector<Eigen::VectorXd> xs;
    std::vector<double> fs;
    for (std::size_t i : order) xs.push_back(x[i]), fs.push_back(f[i]);
    x.swap(xs), f.swap(fs);
  }
  // Values within ftol, and points within xtol or the values identical to
  // the last bit of ftol/1000: along a direction the function does not
  // depend on (parameters that trade off exactly) the points never close up.
  bool collapsed(double ftol, double xtol) const {
    const double spread = f.back() - f.front(), scale = 1.0 + std::abs(f.front());
    if (!(spread <= ftol * scale)) return false;
    if (spread <= 1e-3 * ftol * scale) return true;
    for (const auto& xi : x)
      if ((xi - x.front()).lpNorm<Eigen::Infinity>() > xtol) return false;
    return true;
  }
};

// One iteration on a sorted simplex: the worst point replaced by a better
// one along the line through the centroid of the others, or every point
// shrunk towards the best.
void iterate(Simplex& s, const std::function<double(const Eigen::VectorXd&)>& f, int& evaluations) {
  const std::size_t n = s.x.size() - 1;
  Eigen::VectorXd centroid = Eigen::VectorXd::Zero(s.x[0].size());
  for (std::size_t i = 0; i < n; ++i) centroid += s.x[i];
  centroid /= static_cast<double>(n);
  auto point = [&](double t) -> Eigen::VectorXd { return centroid + t * (centroid - s.x[n]); };
  auto eval = [&](const Eigen::VectorXd& x) {
    ++evaluations;
    const double v = f(x);
    return std::isnan(v) ? std::numeric_limits<double>::infinity() : v;
  };
  auto replace = [&](const Eigen::VectorXd& x, double v) { s.x[n] = x, s.f[n] = v; };
  const Eigen::VectorXd xr = point(1.0);
  const double fr = eval(xr);
  if (fr < s.f[0]) {
    const Eigen::VectorXd xe = point(2.0);
    const double fe = eval(xe);
    fe < fr ? replace(xe, fe) : replace(xr, fr);
  } else if (fr < s.f[n - 1]) {
    replace(xr, fr);
  } else {
    const bool outside = fr < s.f[n];
    const Eigen::VectorXd xc = point(outside ? 0.5 : -0.5);
    const double fc = eval(xc);
    if (fc < (outside ? fr : s.f[n])) {
      replace(xc, fc);
    } else {
      for (std::size_t i = 1; i <= n; ++i) {
        s.x[i] = s.x[0] + 0.5 * (s.x[i] - s.x[0]);
        s.f[i] = eval(s.x[i]);
      }
    }
  }
  s.sort();
}
}  // namespace

NelderMeadResult nelderMead(const std::function<double(const Eigen::VectorXd&)>& f, const Eigen::VectorXd& x0,
                            double step, int max_evaluations, double ftol, double xtol,
                            const std::function<void(double)>& iteration) {
  NelderMeadResult r;
  Simplex s;
  const auto n = x0.size();
  for (Eigen::Index i = 0; i <= n; ++i) {
    Eigen::VectorXd x = x0;
    if (i > 0) x[i - 1] += step;
    const double v = f(x);
    ++r.evaluations;
    s.x.push_back(x);
    s.f.push_back(std::isnan(v) ? std::numeric_limits<double>::infinity() : v);
  }
  s.sort();
  while (r.evaluations < max_evaluations && !(r.converged = s.collapsed(ftol, xtol))) {
    iterate(s, f, r.evaluations);
    ++r.iterations;
    if (iteration) iteration(s.f[0]);
  }
  r.x = s.x[0];
  r.value = s.f[0];
  return r;
}

}  // namespace gssm::internal
