// WGS-84 geodesy for the navigation frame: coordinates against the
// ellipsoid's defining values and round trips (poles, deep and high
// points), normal gravity against WGS-84's equator and pole values and the
// drive's measured site, the local NED frame against small moves.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>

#include "gssm/models/geodesy.h"

using namespace gssm::geodesy;

namespace {
constexpr double kDeg = M_PI / 180;
const double kB = kSemiMajorAxis * (1 - kFlattening);  // semi-minor axis
}  // namespace

TEST(Geodesy, EcefOfTheEllipsoidsDefiningPoints) {
  EXPECT_LT((toEcef({0, 0, 0}) - Eigen::Vector3d(kSemiMajorAxis, 0, 0)).norm(), 1e-9);
  EXPECT_LT((toEcef({0, 90 * kDeg, 100}) - Eigen::Vector3d(0, kSemiMajorAxis + 100, 0)).norm(), 1e-8);
  EXPECT_LT((toEcef({90 * kDeg, 0.3, 0}) - Eigen::Vector3d(0, 0, kB)).norm(), 1e-8);
  EXPECT_LT((toEcef({-90 * kDeg, 0, -50}) - Eigen::Vector3d(0, 0, -kB + 50)).norm(), 1e-8);
  EXPECT_NEAR(meridianRadius(0), kSemiMajorAxis * (1 - kEccentricity2), 1e-6);
  EXPECT_NEAR(transverseRadius(0), kSemiMajorAxis, 1e-6);
  EXPECT_NEAR(meridianRadius(M_PI / 2), transverseRadius(M_PI / 2), 1e-6);
}

TEST(Geodesy, GeodeticRoundTripsEverywhere) {
  for (double lat : {-90.0, -89.999999, -45.0, 0.0, 1e-9, 40.0966268, 89.9999999, 90.0})
    for (double lon : {-180.0, -105.1474483, 0.0, 179.9999})
      for (double h : {-1000.0, 0.0, 1601.474, 1e6}) {
        const Geodetic p{lat * kDeg, lon * kDeg, h};
        const Geodetic q = toGeodetic(toEcef(p));
        EXPECT_NEAR(q.lat, p.lat, 1e-12) << lat << " " << lon << " " << h;
        if (std::abs(lat) < 90) {  // the longitude of a pole is any
          EXPECT_NEAR(std::remainder(q.lon - p.lon, 2 * M_PI), 0, 1e-12) << lat << " " << lon;
        }
        EXPECT_NEAR(q.height, p.height, 1e-6) << lat << " " << lon << " " << h;
      }
}

TEST(Geodesy, NormalGravityMatchesWgs84AndTheDrivesSite) {
  EXPECT_NEAR(normalGravity(0, 0), 9.7803253359, 1e-10);      // WGS-84 γ_e
  EXPECT_NEAR(normalGravity(M_PI / 2, 0), 9.8321849378, 1e-9);  // WGS-84 γ_p
  // The drive's site (40.1°, 1601 m): 9.797 m/s² (its README); ~3.1e-6 s⁻² per metre up.
  EXPECT_NEAR(normalGravity(40.0966 * kDeg, 1601.5), 9.797, 5e-4);
  EXPECT_NEAR(normalGravity(0.7, 0) - normalGravity(0.7, 100), 100 * 3.086e-6, 1e-6);
}

TEST(Geodesy, LocalFrameMovesAsTheEllipsoidSays) {
  const Geodetic anchor{40.0966268 * kDeg, -105.1474483 * kDeg, 1601.474};
  const LocalFrame frame(anchor);
  EXPECT_LT(frame.toNed(anchor).norm(), 1e-9);
  const double RN = meridianRadius(anchor.lat) + anchor.height, RE = transverseRadius(anchor.lat) + anchor.height;
  const Eigen::Vector3d north = frame.toNed({anchor.lat + 1 / RN, anchor.lon, anchor.height});
  EXPECT_LT((north - Eigen::Vector3d(1, 0, 0)).norm(), 1e-6);
  const Eigen::Vector3d east = frame.toNed({anchor.lat, anchor.lon + 1 / (RE * std::cos(anchor.lat)), anchor.height});
  EXPECT_LT((east - Eigen::Vector3d(0, 1, 0)).norm(), 1e-6);
  const Eigen::Vector3d up = frame.toNed({anchor.lat, anchor.lon, anchor.height + 10});
  EXPECT_LT((up - Eigen::Vector3d(0, 0, -10)).norm(), 1e-9);
  for (const Eigen::Vector3d& ned : {Eigen::Vector3d(350, -1200, 24), Eigen::Vector3d(-5000, 3000, -100)}) {
    const Geodetic p = frame.toGeodetic(ned);
    EXPECT_LT((frame.toNed(p) - ned).norm(), 1e-6) << ned.transpose();
  }
  // NED → ECEF is a rotation.
  const Eigen::Matrix3d R = nedToEcef(anchor);
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-15);
  EXPECT_NEAR(R.determinant(), 1, 1e-15);
}

TEST(Geodesy, EarthAndTransportRates) {
  EXPECT_NEAR(earthRateNed(0.7).norm(), kEarthRate, 1e-18);
  EXPECT_NEAR(earthRateNed(0.7).z(), -kEarthRate * std::sin(0.7), 1e-18);  // up component is negative down
  const Eigen::Vector3d w = transportRateNed({0, 0, 100}, Eigen::Vector3d(0, 10, 0));
  EXPECT_LT((w - Eigen::Vector3d(10 / (kSemiMajorAxis + 100), 0, 0)).norm(), 1e-15);
}
