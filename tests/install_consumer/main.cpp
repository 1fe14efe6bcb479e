// Built against an installed gssm through find_package(gssm).
#include <gssm/ekf.h>
#include <gssm/models/radar2d.h>

#include <iostream>

int main() {
  gssm::models::Radar2D radar;
  gssm::ExtendedKalmanFilter ekf(radar);
  ekf.predict(0.05, Eigen::VectorXd(0));
  ekf.update(Eigen::VectorXd::Constant(1, 2236.0));
  std::cout << "consumer: h = " << ekf.mean()[2] << "\n";
  return ekf.mean().allFinite() ? 0 : 1;
}
