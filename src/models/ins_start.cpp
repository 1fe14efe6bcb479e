#include "gssm/models/ins_start.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "gssm/core/error.h"
#include "gssm/core/so3.h"

namespace gssm::models {

Eigen::Matrix3d wahbaRotation(const std::vector<Eigen::Vector3d>& body, const std::vector<Eigen::Vector3d>& nav,
                              const std::vector<double>& weights) {
  if (body.size() != nav.size() || body.size() != weights.size() || body.size() < 2)
    throw InvalidArgument("wahbaRotation: need at least two (body, nav, weight) triples of equal counts");
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < body.size(); ++i) B += weights[i] * nav[i] * body[i].transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(B, Eigen::ComputeFullU | Eigen::ComputeFullV);
  if (!(svd.singularValues()[1] > 1e-12 * svd.singularValues()[0]))
    throw InvalidArgument("wahbaRotation: the directions are parallel: they do not fix a rotation");
  Eigen::Vector3d d(1, 1, (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1);
  return svd.matrixU() * d.asDiagonal() * svd.matrixV().transpose();
}

namespace {
// The antenna's track near a time: a quadratic in time fitted by least
// squares to the fixes in [from, to] (a 4 Hz chord in a turn at 0.25 rad/s
// is 0.03 rad off the tangent, and differenced fixes amplify their noise;
// the fit is neither, and works one-sided at a log's start).
struct Track {
  double t0 = 0;
  Eigen::Matrix3d c;  // rows: the coefficients of 1, s, s² (s = t − t0)
  Eigen::Vector3d velocity(double t) const { return (c.row(1) + 2 * (t - t0) * c.row(2)).transpose(); }
};

Track fitTrack(double t0, double from, double to, const std::vector<double>& ft, const std::vector<Eigen::Vector3d>& fp) {
  Eigen::Matrix3d N = Eigen::Matrix3d::Zero(), B = Eigen::Matrix3d::Zero();
  int used = 0;
  for (std::size_t i = 0; i < ft.size(); ++i) {
    if (ft[i] < from || ft[i] > to) continue;
    const double s = ft[i] - t0;
    const Eigen::Vector3d row(1, s, s * s);
    N += row * row.transpose();
    B += row * fp[i].transpose();
    ++used;
  }
  if (used < 6)
    throw InputError("INS start: " + std::to_string(used) + " GNSS fixes between t = " + std::to_string(from) +
                     " and " + std::to_string(to) + " (need 6 to fit the track)");
  Track tr;
  tr.t0 = t0;
  tr.c = N.ldlt().solve(B);
  return tr;
}
// At rest: the direction to the first fix track_distance from the first
// one, or to the last before a gap in the fixes if that is
// min_track_distance away (ins_start.h).
Eigen::Vector3d pullingAwayTrack(const std::vector<double>& fix_t, const std::vector<Eigen::Vector3d>& fix_ned,
                                 const InsStartOptions& o) {
  auto distance = [&](std::size_t i) { return (fix_ned[i] - fix_ned.front()).head<2>().norm(); };
  for (std::size_t i = 1; i < fix_ned.size(); ++i) {
    if (fix_t[i] - fix_t[i - 1] > o.track_gap && distance(i - 1) >= o.min_track_distance)
      return fix_ned[i - 1] - fix_ned.front();
    if (distance(i) >= o.track_distance) return fix_ned[i] - fix_ned.front();
  }
  throw InputError("INS start: the GNSS track never gets " + std::to_string(o.track_distance) +
                   " m from its start: no heading for the vehicle");
}
}  // namespace

InsStart insStart(double t0, const std::vector<Input>& imu, const std::vector<double>& fix_t,
                  const std::vector<Eigen::Vector3d>& fix_ned, const Eigen::Matrix3d& R_vb,
                  const strapdown::NavFrame& frame, const InsStartOptions& o) {
  if (fix_t.size() != fix_ned.size() || fix_t.size() < 2)
    throw InputError("INS start: need at least two GNSS fixes (got " + std::to_string(fix_t.size()) + ")");
  // The specific force in the IMU's axes at t0: each sample turned back by
  // the gyro's rotation since t0 (a turning car turns 0.25 rad in a second).
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_0b = Eigen::Matrix3d::Identity();
  int n = 0;
  for (std::size_t i = 0; i < imu.size(); ++i) {
    if (imu[i].t < t0 || imu[i].t >= t0 + o.window) continue;
    f += R_0b * imu[i].u.tail<3>(), ++n;
    if (i + 1 < imu.size()) R_0b = R_0b * so3::Exp(imu[i].u.head<3>() * (imu[i + 1].t - imu[i].t));
  }
  if (n == 0) throw InputError("INS start: no IMU row in the first " + std::to_string(o.window) + " s");
  f /= n;
  InsStart s;
  // The velocity at each end of the window from a local fit: a second
  // either side (at a log's start, as much further on as six fixes need).
  auto fixesIn = [&](double from, double until) {
    return std::count_if(fix_t.begin(), fix_t.end(), [&](double t) { return t >= from && t <= until; });
  };
  auto trackAt = [&](double t) {
    double to = t + 1.0;
    while (fixesIn(t - 1.0, to) < 6 && to < t + 3.0) to += 0.25;
    return fitTrack(t, t - 1.0, to, fix_t, fix_ned);
  };
  auto velocity = [&](double t) { return trackAt(t).velocity(t); };
  const Track start = trackAt(t0);
  s.velocity = start.velocity(t0);
  s.position = start.c.row(0).transpose();
  Eigen::Vector3d track = s.velocity;
  s.moving = std::hypot(track.x(), track.y()) > o.moving_speed;
  // The window's mean acceleration; none for a car at rest (a fit's
  // extrapolation to a log's first instant only adds its noise).
  const Eigen::Vector3d accel =
      s.moving ? Eigen::Vector3d((velocity(t0 + o.window) - s.velocity) / o.window) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d gravity = frame.gravity(fix_ned.front());
  if (!s.moving) track = pullingAwayTrack(fix_t, fix_ned, o);
  // In 3-D: the vehicle's forward axis is along its velocity (slope
  // included: a flattened track would tilt the answer on a hill).
  s.track_yaw = std::atan2(track.y(), track.x());
  // Gravity is known far better than the heading: weight it so.
  s.R_nb = wahbaRotation({f.normalized(), R_vb.transpose() * Eigen::Vector3d::UnitX()},
                         {(accel - gravity).normalized(), track.normalized()}, {100.0, 1.0});
  return s;
}

}  // namespace gssm::models
