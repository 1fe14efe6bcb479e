#include "gssm/io/track_pos.h"

#include <algorithm>
#include <cmath>

#include "gssm/io/rtklib_pos.h"
#include "gssm/models/geodesy.h"

namespace gssm::io {

namespace {
int indexOf(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}
}  // namespace

bool reportsGeodeticTrack(const Model& model) {
  const auto names = model.reportNames();
  return indexOf(names, "lat") >= 0 && indexOf(names, "lon") >= 0 && indexOf(names, "height") >= 0;
}

void writeTrackPos(const std::string& path, const Model& model, const OfflineRun& run) {
  const auto names = model.reportNames();
  const int lat = indexOf(names, "lat"), lon = indexOf(names, "lon"), height = indexOf(names, "height");
  const int vn = indexOf(names, "vn"), ve = indexOf(names, "ve"), vd = indexOf(names, "vd");
  GnssSolution s;
  s.source = std::string(methodName(run.method)) + ", " + model.name();
  s.has_velocity = vn >= 0 && ve >= 0 && vd >= 0;
  Eigen::VectorXd value, sd;
  for (const EstimateRow& row : run.rows) {
    model.report(row.mean, row.covariance, value, sd);
    GnssFix f;
    f.t = row.t;
    f.lat_deg = value[lat], f.lon_deg = value[lon], f.height = value[height];
    // lat/lon sds back to metres north and east (the point's radii of curvature)
    const double phi = value[lat] * M_PI / 180, to_rad = M_PI / 180;
    const double sn = sd[lat] * to_rad * (geodesy::meridianRadius(phi) + value[height]);
    const double se = sd[lon] * to_rad * (geodesy::transverseRadius(phi) + value[height]) * std::cos(phi);
    f.cov_neu.diagonal() << sn * sn, se * se, sd[height] * sd[height];
    f.quality = std::hypot(sn, se) < 0.05 ? 1 : 2;
    if (s.has_velocity) {
      f.vel_neu = Eigen::Vector3d(value[vn], value[ve], -value[vd]);
      f.vel_cov_neu.diagonal() << sd[vn] * sd[vn], sd[ve] * sd[ve], sd[vd] * sd[vd];
    }
    s.fixes.push_back(std::move(f));
  }
  writeRtklibPos(path, s, "gssm-process");
}

}  // namespace gssm::io
