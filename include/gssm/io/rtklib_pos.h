#pragma once
// RTKLIB's solution format (.pos), as RTKLIB writes it: '%' comment lines,
// the last of which names the columns, then one epoch a line. gssm reads
// latitude/longitude/height solutions with GPST times (calendar, or GPS
// week and seconds), and the velocity columns when present; any other
// layout (ECEF x/y/z, east/north/up baselines, degrees-minutes-seconds,
// UTC or local times) is refused with what to change in RTKLIB's output
// options. Errors name file, line and column.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace gssm::io {

/// One epoch of a solution.
struct GnssFix {
  double t = 0;            ///< GPS seconds since 1980-01-06 00:00:00 (GPST: no leap seconds)
  double lat_deg = 0;      ///< WGS-84 latitude (deg)
  double lon_deg = 0;      ///< WGS-84 longitude (deg)
  double height = 0;       ///< ellipsoidal height (m)
  int quality = 0;         ///< RTKLIB's Q: 1 fix, 2 float, 3 SBAS, 4 DGPS, 5 single, 6 PPP
  int satellites = 0;
  /// Covariance of (north, east, up) in m² from sdn, sde, sdu and RTKLIB's
  /// signed square roots of the cross terms (sdne = sign(c)·√|c|).
  Eigen::Matrix3d cov_neu = Eigen::Matrix3d::Zero();
  double age = 0;          ///< differential age (s)
  double ratio = 0;        ///< ambiguity ratio
  /// Velocity (north, east, up) in m/s and its covariance, when the file has them.
  std::optional<Eigen::Vector3d> vel_neu;
  Eigen::Matrix3d vel_cov_neu = Eigen::Matrix3d::Zero();
  int line = 0;            ///< its line in the file (for messages downstream)
};

struct GnssSolution {
  std::string source;
  std::vector<GnssFix> fixes;  ///< in time order, strictly increasing
  bool has_velocity = false;
};

/// GPS seconds of a GPST calendar time (proleptic Gregorian, no leap seconds).
double gpsSeconds(int year, int month, int day, int hour, int minute, double second);
/// The calendar time of GPS seconds t, as RTKLIB prints it ("2025/07/08 19:34:18.499").
std::string gpstCalendar(double t);

/// Reads a .pos text (`source` names it in messages). Throws InputError
/// naming source:line:column for a malformed line, a value out of range,
/// time going backwards, or a layout gssm does not read.
GnssSolution parseRtklibPos(const std::string& text, const std::string& source);
GnssSolution readRtklibPos(const std::string& path);
/// The named columns of a solution, one row per fix, for readers that take
/// a data file by its columns (ParamSource::dataFile): t (GPS s), lat, lon
/// (deg), height (m), q, ns, sdn, sde, sdu (m), vn, ve, vu (m/s, when the
/// file has velocities). InputError naming the source and the known columns
/// for any other.
Eigen::MatrixXd solutionColumns(const GnssSolution& solution, const std::vector<std::string>& columns);

/// Writes a solution in the layout parseRtklibPos reads (and RTKPLOT
/// plots): latitude/longitude/height, GPST calendar times, the velocity
/// columns when the solution has them. `program` goes in the header.
void writeRtklibPos(const std::string& path, const GnssSolution& solution, const std::string& program = "gssm");

}  // namespace gssm::io
