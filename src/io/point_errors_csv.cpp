#include "gssm/io/point_errors_csv.h"

#include <fstream>
#include <iomanip>

#include "gssm/core/error.h"

namespace gssm::io {

void writePointErrorsCsv(const std::string& path, const std::vector<PointError>& errors) {
  std::ofstream csv(path);
  if (!csv) throw InputError(path + ": cannot be written");
  csv << "t,horizontal_error";
  const Eigen::Index width = errors.empty() ? 0 : errors.front().error.size();
  for (Eigen::Index i = 0; i < width; ++i) csv << ",error_" << i;
  csv << "\n" << std::setprecision(17);
  for (const PointError& e : errors) {
    csv << e.t << "," << horizontalNorm(e.error);
    for (Eigen::Index i = 0; i < width; ++i) csv << "," << e.error[i];
    csv << "\n";
  }
  if (!csv) throw InputError(path + ": write failed");
}

}  // namespace gssm::io
