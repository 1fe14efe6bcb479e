#pragma once
// Angles: residuals, innovations, errors and reported estimates of
// components marked as angles are wrapped to (−π, π] (docs/DESIGN.md §9).
#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace gssm {

/// a wrapped to (−π, π].
inline double wrapAngle(double a) {
  if (a > -M_PI && a <= M_PI) return a;
  double w = std::remainder(a, 2 * M_PI);  // [−π, π]
  if (w <= -M_PI) w += 2 * M_PI;
  return w;
}

/// Wraps the listed components of v in place (indices outside v are ignored).
inline void wrapAngles(Eigen::Ref<Eigen::VectorXd> v, const std::vector<int>& components, int offset = 0) {
  for (int i : components) {
    const int j = i - offset;
    if (j >= 0 && j < v.size()) v[j] = wrapAngle(v[j]);
  }
}

}  // namespace gssm
