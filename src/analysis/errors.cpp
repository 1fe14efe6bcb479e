#include "gssm/analysis/errors.h"

#include <Eigen/Cholesky>
#include <iomanip>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/core/time.h"

namespace gssm {

Eigen::VectorXd RunErrors::rmse() const {
  if (error.empty()) return {};
  Eigen::VectorXd sq = Eigen::VectorXd::Zero(error.front().size());
  for (const auto& e : error) sq += e.cwiseAbs2();
  return (sq / static_cast<double>(error.size())).cwiseSqrt();
}

RunErrors runErrors(const OfflineRun& run, const Truth& truth) {
  RunErrors out;
  TimeMatcher match(truth.times);
  for (const auto& row : run.rows) {
    const auto j = match.find(row.t);
    if (!j) {
      std::ostringstream os;
      os << std::setprecision(17) << "run errors: the truth has no row at t = " << row.t << " (" << methodName(run.method)
         << " estimate)";
      throw InvalidArgument(os.str());
    }
    const Eigen::VectorXd e = row.mean - truth.states[*j];
    out.times.push_back(row.t);
    out.nees.push_back(e.dot(row.covariance.ldlt().solve(e)));
    out.error.push_back(e);
  }
  return out;
}

}  // namespace gssm
