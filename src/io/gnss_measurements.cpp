#include "io/gnss_measurements.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>

#include "gssm/core/error.h"
#include "gssm/io/csv.h"
#include "gssm/io/number_text.h"
#include "gssm/io/rtklib_pos.h"
#include "io/input_window.h"

namespace gssm::io {

namespace {
struct Outage {
  double start, end;
};

std::vector<Outage> readOutages(const std::string& path) {
  const CsvTable t = readCsv(path);
  const int a = t.column("start"), b = t.column("end");
  if (a < 0 || b < 0) throw InputError(t.source + ":1: expected columns start,end (s)");
  std::vector<Outage> out;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    const double s = t.rows[r][static_cast<std::size_t>(a)], e = t.rows[r][static_cast<std::size_t>(b)];
    if (!(e > s))
      throw InputError(t.source + ":" + std::to_string(t.line_of_row[r]) + ": an outage must end after it starts");
    out.push_back({s, e});
  }
  return out;
}

// into ← into and more, in time order (into's first where times are equal).
void mergeInTime(std::vector<Measurement>& into, std::vector<Measurement> more) {
  std::vector<Measurement> merged;
  merged.reserve(into.size() + more.size());
  std::merge(std::make_move_iterator(into.begin()), std::make_move_iterator(into.end()),
             std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()), std::back_inserter(merged),
             [](const Measurement& a, const Measurement& b) { return a.t < b.t; });
  into = std::move(merged);
}

bool inside(const std::vector<Outage>& outages, double t) {
  return std::any_of(outages.begin(), outages.end(), [t](const Outage& o) { return t >= o.start && t < o.end; });
}

// [dataset] gnss_still_channel: the channel of a zero-velocity measurement
// at every used fix whose own velocity is under gnss_still_speed (m/s).
struct StillFixes {
  int channel = -1;  // none
  double speed = 0;
  int rates_channel = -1;  // gnss_still_rates: none
};

Eigen::Matrix3d neuToNed() { return Eigen::Vector3d(1, 1, -1).asDiagonal(); }

// The mean of the inputs' first dim(channel) components over (from, to]
// (the gyro's reading while the car stands still), as a measurement at `to`.
void addMeanInput(const std::vector<Input>& inputs, const Model& model, int channel, double from, double to,
                  std::vector<Measurement>& out) {
  Eigen::VectorXd sum;
  auto it = std::upper_bound(inputs.begin(), inputs.end(), from, [](double t, const Input& u) { return t < u.t; });
  const int n = sumInputs(it, inputs, to, model.channel(channel).dim(), sum);
  if (n > 0) out.emplace_back(to, sum / n, channel);
}

// [dataset] gnss_velocity_channel: each used fix's own velocity (NED) on
// this channel, with the known values its h reads (the channel's
// regressors, 3 or more): the mean of the inputs' first regressors − 3
// components within ±window/2 of the fix (the IMU's rates, with which the
// lever arm turns), then the velocity's rate of change (NED) from the
// neighbouring used fixes (what the receiver's delay and lag multiply).
struct VelocityFixes {
  int channel = -1;  // none
  double window = 0.1;
};

VelocityFixes velocityFixes(const IniDocument& ini, const Model& model, const GnssSolution& sol) {
  VelocityFixes v;
  if (!ini.has("dataset", "gnss_velocity_channel")) return v;
  v.channel = model.channelIndex(ini.getString("dataset", "gnss_velocity_channel"));
  const MeasurementChannel& ch = model.channel(v.channel);
  if (ch.dim() != 3 || ch.regressors < 3)
    throw InputError(ini.source() + ": [dataset] gnss_velocity_channel: channel '" + ch.name + "' has " +
                     std::to_string(ch.dim()) + " components and reads " + std::to_string(ch.regressors) +
                     " known values; a GNSS velocity has 3 and needs at least 3 (its rate of change)");
  v.window = ini.getDouble("dataset", "gnss_velocity_window", v.window);
  if (!(v.window > 0)) throw InputError(ini.source() + ": [dataset] gnss_velocity_window must be positive (s)");
  if (!sol.has_velocity)
    throw InputError(sol.source + ": no velocity columns (vn ve vu), which [dataset] gnss_velocity_channel needs "
                     "(RTKLIB: output the velocity, or remove the key)");
  return v;
}

Eigen::Vector3d velocityNed(const GnssFix& f) { return neuToNed() * *f.vel_neu; }

// The used fixes' velocities as measurements, in time order. A fix without
// an input in its window, or without a used neighbour within 1 s, has none
// (the known values h reads would be missing).
std::vector<Measurement> velocityMeasurements(const std::vector<const GnssFix*>& fixes, const VelocityFixes& v,
                                              const Model& model, const std::vector<Input>& inputs) {
  const Eigen::Matrix3d neu_to_ned = neuToNed();
  const int k = model.channel(v.channel).regressors - 3;
  std::vector<Measurement> out;
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    const GnssFix& f = *fixes[i];
    const GnssFix& a = *fixes[i > 0 && f.t - fixes[i - 1]->t <= 1.0 ? i - 1 : i];
    const GnssFix& b = *fixes[i + 1 < fixes.size() && fixes[i + 1]->t - f.t <= 1.0 ? i + 1 : i];
    if (&a == &b) continue;
    Eigen::VectorXd known(k + 3);
    known.tail<3>() = (velocityNed(b) - velocityNed(a)) / (b.t - a.t);
    Eigen::VectorXd sum;
    auto it = std::lower_bound(inputs.begin(), inputs.end(), f.t - v.window / 2,
                               [](const Input& u, double t) { return u.t < t; });
    const int n = sumInputs(it, inputs, f.t + v.window / 2, k, sum);
    if (k > 0 && n == 0) continue;
    known.head(k) = sum / std::max(n, 1);
    Eigen::MatrixXd R;
    if (f.vel_cov_neu.diagonal().maxCoeff() > 0) R = neu_to_ned * f.vel_cov_neu * neu_to_ned;
    out.emplace_back(f.t, velocityNed(f), v.channel, R, known);
  }
  return out;
}

StillFixes stillFixes(const IniDocument& ini, const Model& model, const GnssSolution& sol) {
  StillFixes s;
  if (!ini.has("dataset", "gnss_still_channel")) return s;
  s.channel = model.channelIndex(ini.getString("dataset", "gnss_still_channel"));
  s.speed = ini.getDouble("dataset", "gnss_still_speed", 0.05);
  if (!(s.speed > 0))
    throw InputError(ini.source() + ": [dataset] gnss_still_speed must be positive (m/s)");
  if (ini.has("dataset", "gnss_still_rates")) s.rates_channel = model.channelIndex(ini.getString("dataset", "gnss_still_rates"));
  if (!sol.has_velocity)
    throw InputError(sol.source + ": no velocity columns (vn ve vu), which [dataset] gnss_still_channel needs "
                     "(RTKLIB: output the velocity, or remove the key)");
  return s;
}
}  // namespace

void readGnssMeasurements(const std::string& path, const std::string& outages_path, const IniDocument& ini,
                          const Model& model, Dataset& out) {
  const int channel = model.channelIndex(ini.getString("dataset", "gnss_channel", "gnss"));
  if (model.channel(channel).dim() != 3 || !model.localPosition(0, 0, 0))
    throw InputError(ini.source() + ": [dataset] gnss: model '" + model.name() + "' channel '" +
                     model.channel(channel).name + "' does not take positions in a frame anchored on the Earth");
  const int max_quality = static_cast<int>(ini.getDouble("dataset", "gnss_max_quality", 1));
  const double float_scale = ini.getDouble("dataset", "gnss_float_scale", 3.0);
  // A log without its outages file (a log whose outage rows were taken out
  // of the .pos before gssm sees it) withholds nothing, and says so.
  const bool listed = !outages_path.empty() && std::filesystem::exists(outages_path);
  if (!outages_path.empty() && !listed)
    out.dropped.push_back(outages_path + ": no such file ([dataset] gnss_outages): no fixes withheld");
  const std::vector<Outage> outages = listed ? readOutages(outages_path) : std::vector<Outage>{};
  for (const Outage& o : outages) out.outages.emplace_back(o.start, o.end);
  const GnssSolution sol = readRtklibPos(path);
  const StillFixes still = stillFixes(ini, model, sol);
  const VelocityFixes velocity = velocityFixes(ini, model, sol);
  const Eigen::Matrix3d neu_to_ned = neuToNed();
  const double deg = M_PI / 180;
  std::vector<Measurement> used;
  std::vector<const GnssFix*> moving;  // the used fixes with a velocity, for gnss_velocity_channel
  double previous = out.t0;
  for (const GnssFix& f : sol.fixes) {
    if (!(f.t > out.t0)) {  // before the first IMU row, or the start the INI sets
      out.dropped.push_back(sol.source + ":" + std::to_string(f.line) + ":1: time " + formatDouble(f.t) +
                            " is not after the start " + formatDouble(out.t0) + " (dropped: before the run)");
      continue;
    }
    Measurement m(f.t, *model.localPosition(f.lat_deg * deg, f.lon_deg * deg, f.height), channel,
                  neu_to_ned * f.cov_neu * neu_to_ned);
    if (inside(outages, f.t)) {
      if (f.quality == 1) out.withheld.push_back(std::move(m));  // RTK-fixed: the truth inside
      continue;
    }
    if (f.quality > max_quality) {
      ++out.gnss_dropped;
      continue;
    }
    if (f.quality != 1) m.R *= float_scale * float_scale;
    used.push_back(std::move(m));
    if (velocity.channel >= 0 && f.vel_neu) moving.push_back(&f);
    if (still.channel >= 0 && f.vel_neu->norm() < still.speed) {  // standing: its zero-velocity measurement too
      used.emplace_back(f.t, Eigen::VectorXd::Zero(model.channel(still.channel).dim()), still.channel);
      if (still.rates_channel >= 0) addMeanInput(out.inputs, model, still.rates_channel, previous, f.t, used);
    }
    previous = f.t;
  }
  if (velocity.channel >= 0) mergeInTime(used, velocityMeasurements(moving, velocity, model, out.inputs));
  mergeInTime(out.measurements, std::move(used));
}

}  // namespace gssm::io
