#pragma once
// An independent, textbook linear Kalman filter and RTS smoother on the
// stacked state z = [x_c; x_b] (constants as zero-noise states). Tests
// compare the GSSM solvers against it.
#include <Eigen/Dense>
#include <memory>
#include <random>
#include <vector>

#include "gssm/core/data.h"
#include "gssm/models/linear.h"
#include "gssm/model/simulation.h"

namespace gssm::testing {

/// A seeded N(0, 1) source for simulations in tests.
inline NormalSampler normalSampler(unsigned seed) {
  auto rng = std::make_shared<std::mt19937>(seed);
  auto dist = std::make_shared<std::normal_distribution<double>>(0.0, 1.0);
  return [rng, dist] { return (*dist)(*rng); };
}

/// The radar paper scenario's truth (x(0) = 0, ẋ = 100, h = 1000, no
/// process noise), simulated for `steps` steps with seeded noise.
inline SimulatedRun radarPaperRun(const Model& radar, int steps, unsigned seed) {
  SimulationSpec spec;
  spec.steps = steps;
  spec.x0 = Eigen::VectorXd::Constant(1, 0.0);
  spec.xb = Eigen::Vector2d(100, 1000);
  spec.process_noise = false;
  return simulate(radar, spec, normalSampler(seed));
}

struct StackedLinear {
  Eigen::MatrixXd F, Qz, H, R;
  Eigen::VectorXd z0;
  Eigen::MatrixXd P0;
};

inline StackedLinear stack(const models::LinearModel& m, double dt) {
  const auto d = m.dims();
  const int n = d.nc + d.nb;
  Eigen::MatrixXd Fc, Fb, Bk;
  m.discreteMatrices(dt, Fc, Fb, Bk);
  StackedLinear s;
  s.F = Eigen::MatrixXd::Identity(n, n);
  s.F.topLeftCorner(d.nc, d.nc) = Fc;
  s.F.topRightCorner(d.nc, d.nb) = Fb;
  s.Qz = Eigen::MatrixXd::Zero(n, n);
  s.Qz.topLeftCorner(d.nc, d.nc) = m.processNoise(dt);
  s.H.resize(d.ny, n);
  s.H << m.system().C_c, m.system().C_b;
  s.R = m.measurementNoise();
  s.z0.resize(n);
  s.z0 << m.priorState().mean, m.priorConstants().mean;
  s.P0 = Eigen::MatrixXd::Zero(n, n);
  s.P0.topLeftCorner(d.nc, d.nc) = m.priorState().covariance;
  s.P0.bottomRightCorner(d.nb, d.nb) = m.priorConstants().covariance;
  return s;
}

struct KalmanRun {
  std::vector<Eigen::VectorXd> zf, zp, zs;  // filtered, predicted, smoothed; index k = 0..N
  std::vector<Eigen::MatrixXd> Pf, Pp, Ps;
};

/// Filter (k = 0 is the prior) and RTS smoother over measurements y(1..N).
inline KalmanRun kalmanAndRts(const StackedLinear& s, const std::vector<Measurement>& ys) {
  KalmanRun out;
  out.zf.push_back(s.z0);
  out.Pf.push_back(s.P0);
  out.zp.push_back(s.z0);
  out.Pp.push_back(s.P0);
  for (const auto& m : ys) {
    const Eigen::VectorXd zp = s.F * out.zf.back();
    const Eigen::MatrixXd Pp = s.F * out.Pf.back() * s.F.transpose() + s.Qz;
    const Eigen::MatrixXd S = s.H * Pp * s.H.transpose() + s.R;
    const Eigen::MatrixXd K = Pp * s.H.transpose() * S.inverse();
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(zp.size(), zp.size());
    out.zp.push_back(zp);
    out.Pp.push_back(Pp);
    out.zf.push_back(zp + K * (m.y - s.H * zp));
    out.Pf.push_back((I - K * s.H) * Pp * (I - K * s.H).transpose() + K * s.R * K.transpose());
  }
  const std::size_t N = out.zf.size();
  out.zs = out.zf;
  out.Ps = out.Pf;
  for (std::size_t k = N - 1; k-- > 0;) {
    const Eigen::MatrixXd G = out.Pf[k] * s.F.transpose() * out.Pp[k + 1].inverse();
    out.zs[k] = out.zf[k] + G * (out.zs[k + 1] - out.zp[k + 1]);
    out.Ps[k] = out.Pf[k] + G * (out.Ps[k + 1] - out.Pp[k + 1]) * G.transpose();
  }
  return out;
}

/// A random, well-conditioned linear GSSM (n_c states, n_b constants, n_y outputs).
inline models::LinearSystem randomLinearSystem(std::mt19937& rng, int nc, int nb, int ny, double T) {
  std::normal_distribution<double> g(0.0, 1.0);
  auto rnd = [&](int r, int c, double scale) {
    Eigen::MatrixXd m(r, c);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < c; ++j) m(i, j) = scale * g(rng);
    return m;
  };
  auto spd = [&](int n, double scale) {
    const Eigen::MatrixXd a = rnd(n, n, 1.0);
    return Eigen::MatrixXd(scale * (a * a.transpose() / n + Eigen::MatrixXd::Identity(n, n)));
  };
  models::LinearSystem s;
  s.A_c = rnd(nc, nc, 0.5);
  s.A_b = rnd(nc, nb, 1.0);
  s.B = Eigen::MatrixXd::Zero(nc, 0);
  s.C_c = rnd(ny, nc, 1.0);
  s.C_b = rnd(ny, nb, 1.0);
  s.noise.T = T;
  s.noise.Q = spd(nc, 0.01);
  s.noise.R = spd(ny, 0.25);
  s.noise.prior_state.mean = rnd(nc, 1, 1.0);
  s.noise.prior_state.covariance = spd(nc, 1.0);
  s.noise.prior_constants.mean = rnd(nb, 1, 1.0);
  s.noise.prior_constants.covariance = spd(nb, 1.0);
  return s;
}

inline double relativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(1.0, b.norm());
}

}  // namespace gssm::testing
