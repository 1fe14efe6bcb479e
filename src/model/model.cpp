#include "gssm/model/model.h"

#include <algorithm>
#include <array>
#include <mutex>
#include <set>
#include <sstream>

#include "gssm/core/error.h"
#include "model/central_differences.h"

namespace gssm {

namespace {
void requireNames(const std::vector<std::string>& names, int n, const std::string& what,
                  std::set<std::string>& seen) {
  if (static_cast<int>(names.size()) != n)
    throw InvalidArgument("model: " + std::to_string(names.size()) + " " + what +
                          " names given, the dimension is " + std::to_string(n));
  for (const auto& s : names) {
    if (s.empty() || s.find_first_of(", \t\n\"") != std::string::npos)
      throw InvalidArgument("model: " + what + " name '" + s +
                            "' must be non-empty with no comma, space or quote");
    if (!seen.insert(s).second)
      throw InvalidArgument("model: name '" + s + "' is used twice");
  }
}
}  // namespace

Model::Model(ModelDims dims, ModelNames names, ModelNoise noise)
    : dims_(dims), names_(std::move(names)), noise_(std::move(noise)) {
  if (dims_.nc < 1 || dims_.nb < 0 || dims_.nu < 0 || dims_.ny < 1)
    throw InvalidArgument("model: need n_c >= 1, n_b >= 0, n_u >= 0, n_y >= 1");
  std::set<std::string> states, meas;
  requireNames(names_.state, dims_.nc, "state", states);
  requireNames(names_.constants, dims_.nb, "constant", states);
  requireNames(names_.input, dims_.nu, "input", meas);
  requireNames(names_.measurement, dims_.ny, "measurement", meas);
  if (!(noise_.T > 0) || !std::isfinite(noise_.T))
    throw InvalidArgument("model: step T must be a positive number, got " +
                          std::to_string(noise_.T));
  requireCovariance(noise_.Q, dims_.nc, "model: process noise Q");
  requireCovariance(noise_.R, dims_.ny, "model: measurement noise R");
  r_model_ = GaussianNoise(noise_.R, "model: measurement noise R");
  q_cache_ = std::make_shared<NoiseCache>();
  requireVector(noise_.prior_state.mean, dims_.nc, "model: prior mean of x_c(0)");
  requireCovariance(noise_.prior_state.covariance, dims_.nc, "model: prior covariance of x_c(0)");
  requireVector(noise_.prior_constants.mean, dims_.nb, "model: prior mean of x_b");
  if (dims_.nb > 0)
    requireCovariance(noise_.prior_constants.covariance, dims_.nb,
                      "model: prior covariance of x_b");
}

Eigen::MatrixXd Model::processNoise(double dt) const { return noise_.Q * (dt / noise_.T); }

struct Model::NoiseCache {
  std::mutex mutex;
  std::array<std::pair<double, GaussianNoise>, 8> entries;
  std::size_t used = 0, next = 0;
};

GaussianNoise Model::processNoiseModel(double dt, const std::string& what) const {
  NoiseCache& c = *q_cache_;
  {
    std::lock_guard<std::mutex> lock(c.mutex);
    for (std::size_t i = 0; i < c.used; ++i)
      if (c.entries[i].first == dt) return c.entries[i].second;
  }
  GaussianNoise q(processNoise(dt), what);  // may throw: nothing cached
  std::lock_guard<std::mutex> lock(c.mutex);
  c.entries[c.next] = {dt, q};
  c.next = (c.next + 1) % c.entries.size();
  c.used = std::max(c.used, c.next == 0 ? c.entries.size() : c.next);
  return q;
}

std::vector<std::string> Model::stackedStateNames() const {
  std::vector<std::string> out = names_.state;
  out.insert(out.end(), names_.constants.begin(), names_.constants.end());
  return out;
}

namespace {
// Accumulates the worst entry of analytic vs numeric.
void compare(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric,
             const char* name, JacobianCheck& out) {
  if (analytic.rows() != numeric.rows() || analytic.cols() != numeric.cols()) {
    std::ostringstream os;
    os << name << " has size " << analytic.rows() << "x" << analytic.cols() << ", expected "
       << numeric.rows() << "x" << numeric.cols();
    throw InvalidArgument("checkJacobians: " + os.str());
  }
  for (Eigen::Index i = 0; i < numeric.rows(); ++i)
    for (Eigen::Index j = 0; j < numeric.cols(); ++j) {
      const double abs_err = std::abs(analytic(i, j) - numeric(i, j));
      const double rel_err = abs_err / std::max(1.0, std::abs(numeric(i, j)));
      out.max_abs_error = std::max(out.max_abs_error, abs_err);
      if (rel_err >= out.max_rel_error) {
        out.max_rel_error = rel_err;
        std::ostringstream os;
        os << name << "(" << i << "," << j << "): analytic " << analytic(i, j) << ", numeric "
           << numeric(i, j);
        out.worst = os.str();
      }
    }
}

}  // namespace

JacobianCheck checkJacobians(const Model& model, const Eigen::VectorXd& xc,
                             const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                             double eps) {
  const ModelDims& d = model.dims();
  JacobianCheck out;
  Eigen::MatrixXd J_f_xc, J_f_xb, J_h_xc, J_h_xb;
  model.f(xc, xb, u, dt, &J_f_xc, &J_f_xb);
  model.h(xc, xb, &J_h_xc, &J_h_xb);
  compare(J_f_xc, internal::centralDifferences([&](const Eigen::VectorXd& v) { return model.f(v, xb, u, dt); }, xc, d.nc, eps), "J_f_xc", out);
  compare(J_f_xb, internal::centralDifferences([&](const Eigen::VectorXd& v) { return model.f(xc, v, u, dt); }, xb, d.nc, eps), "J_f_xb", out);
  compare(J_h_xc, internal::centralDifferences([&](const Eigen::VectorXd& v) { return model.h(v, xb); }, xc, d.ny, eps), "J_h_xc", out);
  compare(J_h_xb, internal::centralDifferences([&](const Eigen::VectorXd& v) { return model.h(xc, v); }, xb, d.ny, eps), "J_h_xb", out);
  return out;
}

}  // namespace gssm
