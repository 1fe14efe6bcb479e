#include "gssm/models/geodesy.h"

#include <cmath>

namespace gssm::geodesy {

namespace {
// WGS-84 normal gravity (TR8350.2 §4): at the equator, Somigliana's
// constant k, and m = ω²a²b/GM.
constexpr double kGravityEquator = 9.7803253359;
constexpr double kSomigliana = 0.00193185265241;
constexpr double kGravityRatio = 0.00344978650684;
}  // namespace

double transverseRadius(double lat) {
  const double s = std::sin(lat);
  return kSemiMajorAxis / std::sqrt(1 - kEccentricity2 * s * s);
}

double meridianRadius(double lat) {
  const double s = std::sin(lat), w = 1 - kEccentricity2 * s * s;
  return kSemiMajorAxis * (1 - kEccentricity2) / (w * std::sqrt(w));
}

Eigen::Vector3d toEcef(const Geodetic& p) {
  const double N = transverseRadius(p.lat), cl = std::cos(p.lat);
  return {(N + p.height) * cl * std::cos(p.lon), (N + p.height) * cl * std::sin(p.lon),
          (N * (1 - kEccentricity2) + p.height) * std::sin(p.lat)};
}

Geodetic toGeodetic(const Eigen::Vector3d& x) {
  // Fixed-point iteration on the latitude (Groves eq. 2.113 ff.), which
  // gains a factor e² ≈ 1/150 a step, to 1e-14 rad for any height above
  // −a/2. It starts from Bowring's latitude (Bowring 1976, Survey Review
  // 23(181)): within ~1e-10 rad near the surface, so two steps finish where
  // the spherical guess took six (gravity at every IMU reading made this
  // conversion a sixth of the INS's filter pass).
  Geodetic g;
  const double r = std::hypot(x.x(), x.y());
  g.lon = std::atan2(x.y(), x.x());
  const double b = kSemiMajorAxis * std::sqrt(1 - kEccentricity2), ep2 = kEccentricity2 / (1 - kEccentricity2);
  const double beta = std::atan2(x.z() * kSemiMajorAxis, r * b);  // the parametric latitude's guess
  const double sb = std::sin(beta), cb = std::cos(beta);
  g.lat = std::atan2(x.z() + ep2 * b * sb * sb * sb, r - kEccentricity2 * kSemiMajorAxis * cb * cb * cb);
  for (int i = 0; i < 20; ++i) {
    const double N = transverseRadius(g.lat);
    const double h = r > 1e-9 ? r / std::cos(g.lat) - N : std::abs(x.z()) - N * (1 - kEccentricity2);
    const double lat = std::atan2(x.z(), r * (1 - kEccentricity2 * N / (N + h)));
    if (std::abs(lat - g.lat) < 1e-14) {
      g.lat = lat;
      break;
    }
    g.lat = lat;
  }
  // The height from the final latitude, without the 1/cos near the poles.
  const double s = std::sin(g.lat), c = std::cos(g.lat), N = transverseRadius(g.lat);
  g.height = r * c + x.z() * s - N * (1 - kEccentricity2 * s * s);
  return g;
}

Eigen::Matrix3d nedToEcef(const Geodetic& p) {
  const double sl = std::sin(p.lat), cl = std::cos(p.lat), so = std::sin(p.lon), co = std::cos(p.lon);
  Eigen::Matrix3d R;
  R << -sl * co, -so, -cl * co,  //
      -sl * so, co, -cl * so,    //
      cl, 0, -sl;
  return R;
}

double normalGravity(double lat, double h) {
  const double s2 = std::sin(lat) * std::sin(lat);
  const double g0 = kGravityEquator * (1 + kSomigliana * s2) / std::sqrt(1 - kEccentricity2 * s2);
  const double a = kSemiMajorAxis;
  return g0 * (1 - 2 / a * (1 + kFlattening + kGravityRatio - 2 * kFlattening * s2) * h + 3 * h * h / (a * a));
}

Eigen::Vector3d earthRateNed(double lat) { return {kEarthRate * std::cos(lat), 0, -kEarthRate * std::sin(lat)}; }

Eigen::Vector3d transportRateNed(const Geodetic& p, const Eigen::Vector3d& v) {
  const double RE = transverseRadius(p.lat) + p.height, RN = meridianRadius(p.lat) + p.height;
  return {v.y() / RE, -v.x() / RN, -v.y() * std::tan(p.lat) / RE};
}

LocalFrame::LocalFrame(const Geodetic& anchor)
    : anchor_(anchor), origin_(toEcef(anchor)), ned_to_ecef_(nedToEcef(anchor)) {}

Eigen::Vector3d LocalFrame::toNed(const Geodetic& p) const { return ned_to_ecef_.transpose() * (toEcef(p) - origin_); }

Geodetic LocalFrame::toGeodetic(const Eigen::Vector3d& ned) const {
  return geodesy::toGeodetic(origin_ + ned_to_ecef_ * ned);
}

}  // namespace gssm::geodesy
