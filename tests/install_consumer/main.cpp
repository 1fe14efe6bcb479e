// Built against an installed gssm through find_package(gssm).
#include <gssm/solvers/ekf.h>
#include <gssm/io/config.h>
#include <gssm/models/radar2d.h>

#include <iostream>

int main() {
  gssm::models::Radar2D radar;
  gssm::ExtendedKalmanFilter ekf(radar);
  ekf.predict(0.05, Eigen::VectorXd(0));
  ekf.update(Eigen::VectorXd::Constant(1, 2236.0));
  std::cout << "consumer: h = " << ekf.mean()[2] << "\n";
  // The upper libraries are exported too (gssm::io links gssm::analysis and gssm::gssm).
  const gssm::Method m = gssm::io::parseMethod("fixed-lag", "consumer");
  std::cout << "consumer: method " << m << "\n";
  // Models register themselves when the library loads: one from its INI form.
  const auto model = gssm::io::makeModel(gssm::io::IniDocument::parse("[model]\ntype = nav_2d\n", "consumer.ini"));
  std::cout << "consumer: model " << model->name() << "\n";
  return ekf.mean().allFinite() && m == gssm::Method::FixedLag && model->name() == "nav_2d" ? 0 : 1;
}
