#pragma once
// The Earth for strapdown navigation: WGS-84 geodetic ↔ ECEF coordinates, a
// local-level north-east-down frame anchored at a point, normal gravity,
// the Earth's rotation and the radii of curvature (WGS-84, NIMA TR8350.2;
// P. D. Groves, "Principles of GNSS, Inertial, and Multisensor Integrated
// Navigation Systems", 2nd ed., ch. 2).
#include <Eigen/Core>

namespace gssm::geodesy {

constexpr double kSemiMajorAxis = 6378137.0;             ///< a (m)
constexpr double kFlattening = 1 / 298.257223563;        ///< f
constexpr double kEccentricity2 = kFlattening * (2 - kFlattening);  ///< e²
constexpr double kEarthRate = 7.292115e-5;               ///< ω_ie (rad/s)

/// Latitude, longitude (rad) and ellipsoidal height (m).
struct Geodetic {
  double lat = 0, lon = 0, height = 0;
};

/// ECEF position of a geodetic point.
Eigen::Vector3d toEcef(const Geodetic& p);
/// The geodetic point of an ECEF position (iterated to 1e-12 rad; any
/// height above −a/2, the poles included).
Geodetic toGeodetic(const Eigen::Vector3d& ecef);

/// Rotation from the local north-east-down frame at `p` to ECEF (its
/// columns: north, east, down).
Eigen::Matrix3d nedToEcef(const Geodetic& p);

/// Meridian (north–south) and transverse (east–west) radii of curvature at latitude lat (rad).
double meridianRadius(double lat);
double transverseRadius(double lat);

/// Magnitude of normal gravity (m/s²) at latitude lat (rad) and height h
/// (m): Somigliana's formula on the ellipsoid, its second-order height
/// correction above it. Gravity points down in NED: (0, 0, g).
double normalGravity(double lat, double h);

/// The Earth's rotation in the NED frame at latitude lat: ω_ie (cos lat, 0, −sin lat).
Eigen::Vector3d earthRateNed(double lat);
/// The NED frame's rotation over the Earth while moving at v_ned at `p` (transport rate ω_en).
Eigen::Vector3d transportRateNed(const Geodetic& p, const Eigen::Vector3d& v_ned);

/// A local-level NED frame anchored at a point (the first GNSS fix): the
/// navigation frame of the strapdown model, held fixed for the run.
class LocalFrame {
 public:
  explicit LocalFrame(const Geodetic& anchor);
  const Geodetic& anchor() const { return anchor_; }
  /// The point's position in the frame (north, east, down from the anchor, m).
  Eigen::Vector3d toNed(const Geodetic& p) const;
  /// The geodetic point at a position in the frame.
  Geodetic toGeodetic(const Eigen::Vector3d& ned) const;

 private:
  Geodetic anchor_;
  Eigen::Vector3d origin_;    // the anchor in ECEF
  Eigen::Matrix3d ned_to_ecef_;
};

}  // namespace gssm::geodesy
