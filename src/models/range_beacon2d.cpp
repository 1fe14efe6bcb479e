#include "gssm/models/range_beacon2d.h"

#include <cmath>

#include "gssm/core/error.h"
#include "gssm/model/noise_params.h"
#include "gssm/model/registry.h"

namespace gssm::models {

namespace {
int countConstants(const RangeBeacon2D::Params& p) {
  return (p.range_scale ? 1 : 0) + (p.range_offsets ? static_cast<int>(p.beacons.size()) : 0) +
         (p.odometry_scale ? 1 : 0) + (p.heading_rate_bias ? 1 : 0);
}

ModelNames beaconNames(const RangeBeacon2D::Params& p) {
  ModelNames n{{"px", "py", "heading"}, {}, {"v", "omega"}, {}};
  if (p.range_scale) n.constants.push_back("range_scale");
  if (p.range_offsets)
    for (int id : p.beacon_ids) n.constants.push_back("range_offset_" + std::to_string(id));
  if (p.odometry_scale) n.constants.push_back("odometry_scale");
  if (p.heading_rate_bias) n.constants.push_back("heading_rate_bias");
  if (!p.beacon_ids.empty()) n.measurement = {"range_" + std::to_string(p.beacon_ids.front())};
  return n;
}

ModelNoise beaconNoise(const RangeBeacon2D::Params& p) {
  if (p.beacons.empty() || p.beacons.size() != p.beacon_ids.size())
    throw InvalidArgument("RangeBeacon2D: need at least one beacon, with one id per position");
  ModelNoise n;
  n.T = p.T;
  n.Q = Eigen::Vector3d(p.position_sd_per_s * p.position_sd_per_s * p.T, p.position_sd_per_s * p.position_sd_per_s * p.T,
                        p.heading_sd_per_s * p.heading_sd_per_s * p.T)
            .asDiagonal();
  n.R = Eigen::MatrixXd::Constant(1, 1, p.range_sd * p.range_sd);
  n.prior_state = {p.start, Eigen::MatrixXd(p.start_sd.cwiseAbs2().asDiagonal())};
  const int nb = countConstants(p);
  Eigen::VectorXd mean(nb), sd(nb);
  int i = 0;
  if (p.range_scale) mean[i] = 1, sd[i++] = p.range_scale_sd;
  if (p.range_offsets)
    for (std::size_t b = 0; b < p.beacons.size(); ++b) mean[i] = 0, sd[i++] = p.range_offset_sd;
  if (p.odometry_scale) mean[i] = 1, sd[i++] = p.odometry_scale_sd;
  if (p.heading_rate_bias) mean[i] = 0, sd[i++] = p.heading_rate_bias_sd;
  n.prior_constants = {mean, Eigen::MatrixXd(sd.cwiseAbs2().asDiagonal())};
  return n;
}
}  // namespace

RangeBeacon2D::RangeBeacon2D(const Params& p)
    : Model({3, countConstants(p), 2, 1}, beaconNames(p), beaconNoise(p)), p_(p) {
  for (double v : {p.range_sd, p.distance_sd, p.turn_sd, p.heading_drift_sd, p.position_sd_per_s, p.heading_sd_per_s})
    if (!(v > 0) || !std::isfinite(v)) throw InvalidArgument("RangeBeacon2D: every noise σ must be > 0");
  int i = 0;
  if (p.range_scale) i_scale_ = i++;
  if (p.range_offsets) {
    i_offset_ = i;
    i += static_cast<int>(p.beacons.size());
  }
  if (p.odometry_scale) i_odo_ = i++;
  if (p.heading_rate_bias) i_hrb_ = i++;
  std::vector<MeasurementChannel> channels;
  for (int id : p.beacon_ids) {
    MeasurementChannel ch;
    ch.name = "range_" + std::to_string(id);
    ch.components = {ch.name};
    ch.R = Eigen::MatrixXd::Constant(1, 1, p.range_sd * p.range_sd);
    ch.loss = p.range_loss;
    ch.ekf_gate = p.ekf_gate;
    channels.push_back(std::move(ch));
  }
  setChannels(std::move(channels));
  setAngleStates({2});
}

Eigen::VectorXd RangeBeacon2D::f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u,
                                 double dt, Eigen::MatrixXd* J_f_xc, Eigen::MatrixXd* J_f_xb) const {
  const double s = i_odo_ >= 0 ? xb[i_odo_] : 1.0;
  const double d = u[0] * dt, c = std::cos(xc[2]), sn = std::sin(xc[2]);
  Eigen::VectorXd out(3);
  const double b = i_hrb_ >= 0 ? xb[i_hrb_] : 0.0;
  out << xc[0] + s * d * c, xc[1] + s * d * sn, xc[2] + (u[1] - b) * dt;
  if (J_f_xc) {
    *J_f_xc = Eigen::MatrixXd::Identity(3, 3);
    (*J_f_xc)(0, 2) = -s * d * sn;
    (*J_f_xc)(1, 2) = s * d * c;
  }
  if (J_f_xb) {
    *J_f_xb = Eigen::MatrixXd::Zero(3, dims().nb);
    if (i_odo_ >= 0) {
      (*J_f_xb)(0, i_odo_) = d * c;
      (*J_f_xb)(1, i_odo_) = d * sn;
    }
    if (i_hrb_ >= 0) (*J_f_xb)(2, i_hrb_) = -dt;
  }
  return out;
}

Eigen::VectorXd RangeBeacon2D::h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                                 Eigen::MatrixXd* J_h_xb) const {
  return h(0, xc, xb, J_h_xc, J_h_xb);
}

Eigen::VectorXd RangeBeacon2D::h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                                 Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  this->channel(channel);  // range check
  const Eigen::Vector2d delta = xc.head<2>() - p_.beacons[static_cast<std::size_t>(channel)];
  const double rho = delta.norm();
  const double s = i_scale_ >= 0 ? xb[i_scale_] : 1.0;
  const int io = rangeOffsetIndex(static_cast<std::size_t>(channel));
  const double o = io >= 0 ? xb[io] : 0.0;
  if (J_h_xc) {
    *J_h_xc = Eigen::MatrixXd::Zero(1, 3);
    if (rho > 0) J_h_xc->leftCols(2) = s * delta.transpose() / rho;
  }
  if (J_h_xb) {
    *J_h_xb = Eigen::MatrixXd::Zero(1, dims().nb);
    if (i_scale_ >= 0) (*J_h_xb)(0, i_scale_) = rho;
    if (io >= 0) (*J_h_xb)(0, io) = 1.0;
  }
  return Eigen::VectorXd::Constant(1, s * rho + o);
}

Eigen::MatrixXd RangeBeacon2D::processNoise(double dt) const { return processNoiseOf(dt, Eigen::Vector2d::Zero()); }

Eigen::MatrixXd RangeBeacon2D::processNoiseOf(double dt, const Eigen::VectorXd& u) const {
  // Variances additive in distance, turn and time, so a split step has the
  // noise of the whole; isotropic in position (no dependence on the heading).
  const double d = std::abs(u[0]) * dt, a = std::abs(u[1]) * dt;
  const double pos = p_.distance_sd * p_.distance_sd * d + p_.position_sd_per_s * p_.position_sd_per_s * dt;
  const double head = p_.turn_sd * p_.turn_sd * a + p_.heading_drift_sd * p_.heading_drift_sd * d +
                      p_.heading_sd_per_s * p_.heading_sd_per_s * dt;
  return Eigen::Vector3d(pos, pos, head).asDiagonal();
}

std::vector<Eigen::Vector2d> RangeBeacon2D::landmarks() const { return p_.beacons; }

namespace {
std::vector<ParamSpec> rangeBeaconParams() {
  using namespace param;
  std::vector<ParamSpec> p{
      real("model", "T", "nominal odometry period (s)"),
      required(table("model", "beacons", {"beacon", "x", "y"}, "beacons: rows 'id x y' (m), or a CSV file beacon,x,y")),
      flag("model", "range_scale", "estimate a common range scale s_r"),
      flag("model", "range_offsets", "estimate a range offset per beacon"),
      flag("model", "odometry_scale", "estimate an odometry distance scale s_d"),
      flag("model", "heading_rate_bias", "estimate a bias of the odometry's turn rate (rad/s)"),
      learnable(real("model", "range_sd", "σ of one range (m)")),
      learnable(real("model", "distance_sd", "odometry position noise, m per √m travelled")),
      learnable(real("model", "turn_sd", "heading noise, rad per √rad turned")),
      learnable(real("model", "heading_drift_sd", "heading noise, rad per √m travelled")),
      learnable(real("model", "position_sd_per_s", "position noise floor, m per √s")),
      learnable(real("model", "heading_sd_per_s", "heading noise floor, rad per √s"))};
  for (auto& l : lossParams("model")) p.push_back(l);
  for (auto& q : {real("model", "ekf_gate", "EKF NIS gate of every range (0: none)"),
                  any("prior", "start", "prior mean of [px, py] (m), or 'truth': the truth file's first row"),
                  real("prior", "position_sd", "prior σ of px and py (m)"),
                  real("prior", "heading", "prior mean of the heading (rad)"),
                  real("prior", "heading_sd", "prior σ of the heading (rad)"),
                  real("prior", "range_scale_sd", "prior σ of s_r (mean 1)"),
                  real("prior", "range_offset_sd", "prior σ of each range offset (mean 0), m"),
                  real("prior", "odometry_scale_sd", "prior σ of s_d (mean 1)"),
                  real("prior", "heading_rate_bias_sd", "prior σ of the turn-rate bias (mean 0), rad/s")})
    p.push_back(q);
  return p;
}

// [prior] start: "x y", or "truth" (the first row of [dataset] truth).
Eigen::Vector2d readStart(const ParamSource& in) {
  if (in.has("prior", "start") && in.text("prior", "start") == "truth") {
    const Eigen::MatrixXd t = in.dataFile(in.text("dataset", "truth", "truth.csv"), {"px", "py"});
    if (t.rows() == 0) throw InputError(in.where("prior", "start") + " = truth: the truth file has no rows");
    return t.row(0).transpose();
  }
  return in.has("prior", "start") ? Eigen::Vector2d(in.vector("prior", "start", 2)) : Eigen::Vector2d::Zero();
}

RangeBeacon2D::Params readRangeBeacon(const ParamSource& in) {
  RangeBeacon2D::Params p;
  const Eigen::MatrixXd B = in.table("model", "beacons", {"beacon", "x", "y"});
  for (Eigen::Index i = 0; i < B.rows(); ++i) {
    if (B(i, 0) != std::floor(B(i, 0)))
      throw InputError(in.where("model", "beacons") + ": row " + std::to_string(i + 1) + ": id must be an integer");
    p.beacon_ids.push_back(static_cast<int>(B(i, 0)));
    p.beacons.emplace_back(B(i, 1), B(i, 2));
  }
  p.T = in.real("model", "T", p.T);
  p.range_scale = in.flag("model", "range_scale", p.range_scale);
  p.range_offsets = in.flag("model", "range_offsets", p.range_offsets);
  p.odometry_scale = in.flag("model", "odometry_scale", p.odometry_scale);
  p.heading_rate_bias = in.flag("model", "heading_rate_bias", p.heading_rate_bias);
  for (auto [key, value] : {std::pair{"range_sd", &p.range_sd}, {"distance_sd", &p.distance_sd},
                            {"turn_sd", &p.turn_sd}, {"heading_drift_sd", &p.heading_drift_sd},
                            {"position_sd_per_s", &p.position_sd_per_s}, {"heading_sd_per_s", &p.heading_sd_per_s}})
    *value = in.real("model", key, *value);
  p.range_loss = readLoss(in, "model");
  p.ekf_gate = in.real("model", "ekf_gate", p.ekf_gate);
  p.start.head<2>() = readStart(in);
  p.start[2] = in.real("prior", "heading", 0.0);
  const double psd = in.real("prior", "position_sd", 1.0);
  p.start_sd << psd, psd, in.real("prior", "heading_sd", M_PI);
  p.range_scale_sd = in.real("prior", "range_scale_sd", p.range_scale_sd);
  p.range_offset_sd = in.real("prior", "range_offset_sd", p.range_offset_sd);
  p.odometry_scale_sd = in.real("prior", "odometry_scale_sd", p.odometry_scale_sd);
  p.heading_rate_bias_sd = in.real("prior", "heading_rate_bias_sd", p.heading_rate_bias_sd);
  return p;
}

void writeRangeBeacon(const RangeBeacon2D::Params& p, ParamSink& out) {
  Eigen::MatrixXd B(static_cast<Eigen::Index>(p.beacons.size()), 3);
  for (std::size_t i = 0; i < p.beacons.size(); ++i)
    B.row(static_cast<Eigen::Index>(i)) << p.beacon_ids[i], p.beacons[i].x(), p.beacons[i].y();
  out.real("model", "T", p.T);
  out.matrix("model", "beacons", B);
  out.flag("model", "range_scale", p.range_scale);
  out.flag("model", "range_offsets", p.range_offsets);
  out.flag("model", "odometry_scale", p.odometry_scale);
  out.flag("model", "heading_rate_bias", p.heading_rate_bias);
  for (auto [key, value] : {std::pair{"range_sd", p.range_sd}, {"distance_sd", p.distance_sd}, {"turn_sd", p.turn_sd},
                            {"heading_drift_sd", p.heading_drift_sd}, {"position_sd_per_s", p.position_sd_per_s},
                            {"heading_sd_per_s", p.heading_sd_per_s}})
    out.real("model", key, value);
  writeLoss(p.range_loss, "model", out);
  out.real("model", "ekf_gate", p.ekf_gate);
  out.vector("prior", "start", p.start.head<2>());
  out.real("prior", "position_sd", p.start_sd[0]);
  out.real("prior", "heading", p.start[2]);
  out.real("prior", "heading_sd", p.start_sd[2]);
  out.real("prior", "range_scale_sd", p.range_scale_sd);
  out.real("prior", "range_offset_sd", p.range_offset_sd);
  out.real("prior", "odometry_scale_sd", p.odometry_scale_sd);
  out.real("prior", "heading_rate_bias_sd", p.heading_rate_bias_sd);
}

const ModelRegistration range_beacon2d_registration{{
    "range_beacon_2d", {}, "RangeBeacon2D",
    "A vehicle with odometry ranging to known beacons (the CMU Plaza logs); range scale, per-beacon offsets and "
    "odometry scale as optional constants; one channel per beacon.",
    rangeBeaconParams(),
    [](const ParamSource& in) -> std::unique_ptr<Model> { return std::make_unique<RangeBeacon2D>(readRangeBeacon(in)); },
    [](const Model& m, ParamSink& out) { writeRangeBeacon(dynamic_cast<const RangeBeacon2D&>(m).params(), out); },
    [](const Model& m) { return dynamic_cast<const RangeBeacon2D*>(&m) != nullptr; },
    [](ParamSink& out) { writeRangeBeacon(RangeBeacon2D::Params{}, out); }}};
}  // namespace

}  // namespace gssm::models
