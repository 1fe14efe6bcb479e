#include "gssm/analysis/errors.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <iomanip>
#include <sstream>

#include "gssm/core/angles.h"
#include "gssm/core/error.h"
#include "gssm/core/time.h"

namespace gssm {

Eigen::VectorXd RunErrors::rmse() const {
  if (error.empty()) return {};
  Eigen::VectorXd sq = Eigen::VectorXd::Zero(error.front().size());
  for (const auto& e : error) sq += e.cwiseAbs2();
  return (sq / static_cast<double>(error.size())).cwiseSqrt();
}

RunErrors runErrors(const OfflineRun& run, const Truth& truth, const std::vector<int>& angles) {
  RunErrors out;
  TimeMatcher match(truth.times);
  out.components = truth.components;
  if (out.components.empty() && !run.rows.empty())
    for (int i = 0; i < run.rows.front().mean.size(); ++i) out.components.push_back(i);
  const auto n = static_cast<Eigen::Index>(out.components.size());
  std::vector<int> wrapped;  // positions within the compared components
  for (Eigen::Index i = 0; i < n; ++i)
    if (std::find(angles.begin(), angles.end(), out.components[static_cast<std::size_t>(i)]) != angles.end())
      wrapped.push_back(static_cast<int>(i));
  Eigen::MatrixXd P(n, n);  // one buffer for every row's covariance and its factor
  Eigen::LDLT<Eigen::MatrixXd> factor(n);
  for (const auto& row : run.rows) {
    const auto j = match.find(row.t);
    if (!j && !truth.covers_every_row) {
      ++out.without_truth;
      continue;
    }
    if (!j) {
      std::ostringstream os;
      os << std::setprecision(17) << "run errors: the truth has no row at t = " << row.t << " (" << methodName(run.method)
         << " estimate)";
      throw InvalidArgument(os.str());
    }
    Eigen::VectorXd e(n);
    for (Eigen::Index a = 0; a < n; ++a) {
      const int ia = out.components[static_cast<std::size_t>(a)];
      e[a] = row.mean[ia] - truth.states[*j][a];
      for (Eigen::Index b = 0; b < n; ++b) P(a, b) = row.covariance(ia, out.components[static_cast<std::size_t>(b)]);
    }
    wrapAngles(e, wrapped);
    out.times.push_back(row.t);
    out.nees.push_back(e.dot(factor.compute(P).solve(e)));
    out.error.push_back(e);
  }
  return out;
}

}  // namespace gssm
