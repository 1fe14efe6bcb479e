// What a navigation user reads of a StrapdownIns estimate (issue #37,
// point 6): the antenna's latitude, longitude and height, the velocity, the
// vehicle's roll, pitch and yaw, and the constants in the vehicle's terms,
// each with its standard deviation to first order (J·Σ·Jᵀ on the stacked
// tangent: the attitude's block is a right perturbation).
#include <cmath>
#include <vector>

#include "gssm/core/so3.h"
#include "gssm/models/strapdown_ins.h"

namespace gssm::models {

namespace {
constexpr double kDegPerRad = 180.0 / M_PI;  // rad → deg
constexpr int kTheta = 0, kVel = 3;
constexpr int kFixedOutputs = 29;  // every INS's report; the constraints' points follow

// √diag(J·Σ·Jᵀ), each row over its own nonzero columns: J is mostly unit
// rows (a dense product was most of a report's time, ~57k products where
// ~2k are not zeros).
void sdOfRows(const Eigen::MatrixXd& J, const Eigen::MatrixXd& covariance, Eigen::VectorXd& sd) {
  sd.resize(J.rows());
  std::vector<Eigen::Index> nz;
  nz.reserve(static_cast<std::size_t>(J.cols()));
  for (Eigen::Index r = 0; r < J.rows(); ++r) {
    nz.clear();
    for (Eigen::Index c = 0; c < J.cols(); ++c)
      if (J(r, c) != 0.0) nz.push_back(c);
    double v = 0;
    for (Eigen::Index a : nz) {
      double w = 0;
      for (Eigen::Index b : nz) w += covariance(a, b) * J(r, b);
      v += J(r, a) * w;
    }
    sd[r] = std::sqrt(v);
  }
}
}  // namespace

std::vector<std::string> StrapdownIns::reportNames() const {
  std::vector<std::string> names{"lat",       "lon",        "height",      "vn",        "ve",     "vd",
                                 "roll",      "pitch",      "yaw",         "bg_x",      "bg_y",   "bg_z",
                                 "ba_x",      "ba_y",       "ba_z",        "lever_f",   "lever_r", "lever_d",
                                 "imu_delay", "mount_roll", "mount_pitch", "mount_yaw", "sg_x",   "sg_y",
                                 "sg_z",      "sa_x",       "sa_y",        "sa_z",      "clock_rate"};
  for (int b = kConstants; b < dims().nb; ++b) names.push_back(this->names().constants[static_cast<std::size_t>(b)]);
  return names;  // the constraints' points (m) as they are
}

// Rows of J (outputs × stacked tangent) and values, in reportNames' order.
void StrapdownIns::report(const Eigen::VectorXd& mean, const Eigen::MatrixXd& covariance, Eigen::VectorXd& value,
                          Eigen::VectorXd& sd) const {
  const int nc = dims().nc;
  const int nb = dims().nb;
  const Eigen::VectorXd xc = mean.head(nc), xb = mean.tail(nb);
  const int n = nc + nb, b = nc;  // b: where x_b starts in the stacked state
  const int outputs = kFixedOutputs + nb - kConstants;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(outputs, n);
  value.resize(outputs);
  // The antenna in the frame, then geodetic (deg, deg, m).
  Eigen::MatrixXd J_xc, J_xb;
  const Eigen::Vector3d ned = antenna(xc, xb, &J_xc, &J_xb);
  const geodesy::Geodetic g = frame_.local().toGeodetic(ned);
  const Eigen::Vector3d to_geo(kDegPerRad / (geodesy::meridianRadius(g.lat) + g.height),
                               kDegPerRad / ((geodesy::transverseRadius(g.lat) + g.height) * std::cos(g.lat)), -1.0);
  value.head<3>() << g.lat * kDegPerRad, g.lon * kDegPerRad, g.height;
  J.block(0, 0, 3, nc) = to_geo.asDiagonal() * J_xc;
  J.block(0, b, 3, nb) = to_geo.asDiagonal() * J_xb;
  value.segment<3>(3) = xc.segment<3>(kVel);
  J.block<3, 3>(3, kVel).setIdentity();
  // The vehicle: R_nv = R·R_vbᵀ, perturbed R_nv·Exp(R_vb·(δθ − E·δμ)).
  Eigen::Matrix3d E, J_rpy = Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d R = so3::Exp(xc.head<3>()), R_vb = mounting(xb, &E);
  value.segment<3>(6) = so3::rollPitchYaw(R * R_vb.transpose(), &J_rpy) * kDegPerRad;
  J.block<3, 3>(6, kTheta) = kDegPerRad * J_rpy * R_vb;
  J.block<3, 3>(6, b + kMount) = -kDegPerRad * J_rpy * R_vb * E;
  value.segment<3>(9) = gyroBias(xc, xb);  // the gyro bias now: b_g (+ β_g)
  value.segment<3>(12) = xb.segment<3>(kAccelBias);
  J.block<6, 6>(9, b + kGyroBias).setIdentity();
  if (gyroBiasWalks()) J.block<3, 3>(9, kGyroWalk).setIdentity();
  // The lever arm in vehicle axes, R_vb·ℓ.
  const Eigen::Vector3d lever = xb.segment<3>(kLever);
  value.segment<3>(15) = R_vb * lever;
  J.block<3, 3>(15, b + kLever) = R_vb;
  J.block<3, 3>(15, b + kMount) = -R_vb * so3::hat(lever) * E;
  value[18] = xb[kDelay];
  J(18, b + kDelay) = 1;
  // The mounting as the ZYX angles of R_vb (IMU → vehicle), as the source's.
  J_rpy.setZero();
  value.segment<3>(19) = so3::rollPitchYaw(R_vb, &J_rpy) * kDegPerRad;
  J.block<3, 3>(19, b + kMount) = kDegPerRad * J_rpy * E;
  value.segment<6>(22) = xb.segment<6>(kGyroScale);
  J.block<6, 6>(22, b + kGyroScale).setIdentity();
  value[28] = xb[kClockRate];
  J(28, b + kClockRate) = 1;
  for (int i = kConstants; i < nb; ++i) {
    value[kFixedOutputs + i - kConstants] = xb[i];
    J(kFixedOutputs + i - kConstants, b + i) = 1;
  }
  sdOfRows(J, covariance, sd);
}

}  // namespace gssm::models
