#include "gssm/models/planar_rigid_body.h"

#include <algorithm>
#include <cmath>

#include "gssm/core/error.h"
#include "gssm/model/noise_params.h"
#include "gssm/model/registry.h"

namespace gssm::models {

namespace {
std::string linkName(const PlanarRigidBody::Params& p, std::size_t i, std::size_t j) {
  return std::to_string(p.tag_ids[i]) + "_" + std::to_string(p.anchor_ids[j]);
}

int countLinkBiases(const PlanarRigidBody::Params& p) {
  return p.link_biases ? static_cast<int>(p.tags.size() * p.anchors.size()) : 0;
}
// Harmonics 2..K: the first is a lever-arm error (a tag's position), which
// the ranges cannot tell from the body origin's.
int antennaTermsPerTag(const PlanarRigidBody::Params& p) { return 2 * std::max(0, p.antenna_harmonics - 1); }
int countAntennaTerms(const PlanarRigidBody::Params& p) {
  return antennaTermsPerTag(p) * static_cast<int>(p.tags.size());
}
int countConstants(const PlanarRigidBody::Params& p) {
  return countLinkBiases(p) + (p.range_scale ? 1 : 0) + countAntennaTerms(p);
}

ModelNames bodyNames(const PlanarRigidBody::Params& p) {
  ModelNames n{{"px", "py", "yaw", "vx", "vy", "omega"}, {}, {}, {}};
  if (p.link_biases)
    for (std::size_t i = 0; i < p.tags.size(); ++i)
      for (std::size_t j = 0; j < p.anchors.size(); ++j) n.constants.push_back("bias_" + linkName(p, i, j));
  if (p.range_scale) n.constants.push_back("range_scale");
  for (std::size_t i = 0; i < p.tags.size(); ++i)
    for (int k = 2; k <= p.antenna_harmonics; ++k)
      for (const char* part : {"_c", "_s"})
        n.constants.push_back("antenna_" + std::to_string(p.tag_ids[i]) + part + std::to_string(k));
  if (!p.tags.empty() && !p.anchors.empty()) n.measurement = {"range_" + linkName(p, 0, 0)};
  return n;
}

// q²·[[dt³/3, dt²/2], [dt²/2, dt]] on each (position, rate) pair.
Eigen::MatrixXd bodyProcessNoise(const PlanarRigidBody::Params& p, double dt) {
  const double q_xy = p.accel_sd, q_yaw = p.yaw_accel_sd;
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(6, 6);
  for (int i = 0; i < 3; ++i) {
    const double a = (i < 2 ? q_xy : q_yaw) * (i < 2 ? q_xy : q_yaw);
    Q(i, i) = a * dt * dt * dt / 3;
    Q(i, i + 3) = Q(i + 3, i) = a * dt * dt / 2;
    Q(i + 3, i + 3) = a * dt;
  }
  return Q;
}

ModelNoise bodyNoise(const PlanarRigidBody::Params& p) {
  if (p.tags.empty() || p.anchors.empty() || p.tags.size() != p.tag_ids.size() || p.anchors.size() != p.anchor_ids.size())
    throw InvalidArgument("PlanarRigidBody: need at least one tag and one anchor, each with an id");
  for (double v : {p.accel_sd, p.yaw_accel_sd, p.range_sd, p.position_sd, p.yaw_sd, p.velocity_sd, p.omega_sd,
                   p.bias_sd, p.range_scale_sd, p.antenna_sd, p.T})
    if (!(v > 0) || !std::isfinite(v)) throw InvalidArgument("PlanarRigidBody: every σ and T must be > 0");
  if (!(p.bias_common_sd >= 0) || !std::isfinite(p.bias_common_sd))
    throw InvalidArgument("PlanarRigidBody: bias_common_sd must be >= 0 (0: the links' biases independent)");
  if (p.antenna_harmonics < 0 || p.antenna_harmonics > 8)
    throw InvalidArgument("PlanarRigidBody: antenna_harmonics must be in [0, 8], got " +
                          std::to_string(p.antenna_harmonics));
  ModelNoise n;
  n.T = p.T;
  n.Q = bodyProcessNoise(p, p.T);
  n.R = Eigen::MatrixXd::Constant(1, 1, p.range_sd * p.range_sd);
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(6), sd(6);
  mean.head<3>() = p.start;
  sd << p.position_sd, p.position_sd, p.yaw_sd, p.velocity_sd, p.velocity_sd, p.omega_sd;
  n.prior_state = {mean, Eigen::MatrixXd(sd.cwiseAbs2().asDiagonal())};
  const int nb = countConstants(p);
  Eigen::VectorXd bmean = Eigen::VectorXd::Zero(nb), bsd = Eigen::VectorXd::Constant(nb, p.bias_sd);
  const int nl = countLinkBiases(p);
  if (p.range_scale) bmean[nl] = 1, bsd[nl] = p.range_scale_sd;
  bsd.tail(countAntennaTerms(p)).setConstant(p.antenna_sd);
  Eigen::MatrixXd P = bsd.cwiseAbs2().asDiagonal();
  // b_ij = c + d_ij: the part all links share (c ~ N(0, σ_c²)) marginalized
  // out of the prior, so every link keeps its own node and its own factors.
  P.topLeftCorner(nl, nl).array() += p.bias_common_sd * p.bias_common_sd;
  n.prior_constants = {bmean, P};
  return n;
}
}  // namespace

PlanarRigidBody::PlanarRigidBody(const Params& p)
    : Model({6, countConstants(p), 0, 1}, bodyNames(p), bodyNoise(p)), p_(p) {
  int i = 0;
  if (p.link_biases) {
    i_bias_ = i;
    i += static_cast<int>(p.tags.size() * p.anchors.size());
  }
  if (p.range_scale) i_scale_ = i++;
  const int per_tag = antennaTermsPerTag(p);
  if (per_tag > 0) i_antenna_ = i;
  std::vector<MeasurementChannel> channels;
  for (std::size_t t = 0; t < p.tags.size(); ++t)
    for (std::size_t a = 0; a < p.anchors.size(); ++a) {
      MeasurementChannel ch;
      ch.name = "range_" + linkName(p, t, a);
      ch.components = {ch.name};
      ch.R = Eigen::MatrixXd::Constant(1, 1, p.range_sd * p.range_sd);
      ch.loss = p.range_loss;
      ch.ekf_gate = p.ekf_gate;
      if (i_bias_ >= 0) ch.constants.push_back(i_bias_ + static_cast<int>(t * p.anchors.size() + a));
      if (i_scale_ >= 0) ch.constants.push_back(i_scale_);
      for (int k = 0; k < per_tag; ++k) ch.constants.push_back(i_antenna_ + static_cast<int>(t) * per_tag + k);
      channels.push_back(std::move(ch));
    }
  setChannels(std::move(channels));
  setAngleStates({2});
}

std::vector<Eigen::Vector2d> PlanarRigidBody::landmarks() const {
  std::vector<Eigen::Vector2d> out;
  for (const auto& a : p_.anchors) out.emplace_back(a.head<2>());
  return out;
}

std::vector<Eigen::Vector2d> PlanarRigidBody::bodyPoints(const Eigen::VectorXd& xc) const {
  const double c = std::cos(xc[2]), s = std::sin(xc[2]);
  std::vector<Eigen::Vector2d> out;
  for (const auto& l : p_.tags) out.emplace_back(xc[0] + c * l.x() - s * l.y(), xc[1] + s * l.x() + c * l.y());
  return out;
}

Eigen::VectorXd PlanarRigidBody::meanTrueDistances(const Truth& truth) const {
  const Eigen::VectorXd xb0 = priorConstants().mean;  // biases 0, scale 1: h is the geometric range
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(numChannels());
  for (const auto& row : truth.states) {  // the truth's components into x_c (velocities do not enter h)
    Eigen::VectorXd xc = Eigen::VectorXd::Zero(6);
    for (Eigen::Index i = 0; i < row.size(); ++i) {
      const int k = truth.components.empty() ? static_cast<int>(i) : truth.components[static_cast<std::size_t>(i)];
      if (k < 6) xc[k] = row[i];
    }
    for (int c = 0; c < numChannels(); ++c) sum[c] += h(c, xc, xb0)[0];
  }
  return truth.states.empty() ? sum : Eigen::VectorXd(sum / static_cast<double>(truth.states.size()));
}

Eigen::VectorXd PlanarRigidBody::referenceConstants(const Eigen::MatrixXd& rows, const Truth& truth) const {
  Eigen::VectorXd out = Eigen::VectorXd::Constant(dims().nb, std::numeric_limits<double>::quiet_NaN());
  if (i_bias_ < 0 || truth.states.empty()) return out;
  const Eigen::VectorXd distance = meanTrueDistances(truth);
  for (Eigen::Index r = 0; r < rows.rows(); ++r) {
    const auto tag = std::find(p_.tag_ids.begin(), p_.tag_ids.end(), static_cast<int>(rows(r, 0)));
    const auto anchor = std::find(p_.anchor_ids.begin(), p_.anchor_ids.end(), static_cast<int>(rows(r, 1)));
    if (tag == p_.tag_ids.end() || anchor == p_.anchor_ids.end())
      throw InputError("calibration reference row " + std::to_string(r + 1) + ": link (" +
                       std::to_string(static_cast<int>(rows(r, 0))) + ", " + std::to_string(static_cast<int>(rows(r, 1))) +
                       ") is not in the tags and anchors");
    const int c = channelOf(static_cast<std::size_t>(tag - p_.tag_ids.begin()),
                            static_cast<std::size_t>(anchor - p_.anchor_ids.begin()));
    out[biasIndex(c)] = rows(r, 2) + rows(r, 3) * distance[c];
  }
  return out;
}

Gaussian PlanarRigidBody::comparableConstants(const Gaussian& xb, const Truth& truth) const {
  if (i_scale_ < 0 || i_bias_ < 0 || truth.states.empty()) return xb;
  const Eigen::VectorXd distance = meanTrueDistances(truth);
  Eigen::MatrixXd J = Eigen::MatrixXd::Identity(dims().nb, dims().nb);  // linear in x_b
  Eigen::VectorXd mean = xb.mean;
  for (int c = 0; c < numChannels(); ++c) {
    J(biasIndex(c), i_scale_) = distance[c];
    mean[biasIndex(c)] += (xb.mean[i_scale_] - 1.0) * distance[c];
  }
  return {mean, J * xb.covariance * J.transpose()};
}

std::vector<std::string> PlanarRigidBody::bodyPointNames() const {
  std::vector<std::string> out;
  for (int id : p_.tag_ids) out.push_back("tag " + std::to_string(id));
  return out;
}

Eigen::VectorXd PlanarRigidBody::f(const Eigen::VectorXd& xc, const Eigen::VectorXd& /*xb*/,
                                   const Eigen::VectorXd& /*u*/, double dt, Eigen::MatrixXd* J_f_xc,
                                   Eigen::MatrixXd* J_f_xb) const {
  Eigen::VectorXd out = xc;
  out.head<3>() += dt * xc.segment<3>(3);
  if (J_f_xc) {
    *J_f_xc = Eigen::MatrixXd::Identity(6, 6);
    J_f_xc->block<3, 3>(0, 3).diagonal().setConstant(dt);
  }
  if (J_f_xb) *J_f_xb = Eigen::MatrixXd::Zero(6, dims().nb);
  return out;
}

Eigen::VectorXd PlanarRigidBody::h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                                   Eigen::MatrixXd* J_h_xb) const {
  return h(0, xc, xb, J_h_xc, J_h_xb);
}

// The tag at p + R(yaw)·l (horizontally), the anchor at a: ρ = ‖d‖ with
// d = (tag − a) and the vertical part dz fixed; ∂ρ/∂p = d_xy/ρ,
// ∂ρ/∂yaw = d_xy·(R'(yaw) l)/ρ with R' l = (−sin·lx − cos·ly, cos·lx − sin·ly).
Eigen::VectorXd PlanarRigidBody::h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                                   Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  Eigen::VectorXd out;
  hInto(channel, xc, xb, out, J_h_xc, J_h_xb);
  return out;
}

void PlanarRigidBody::hInto(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::VectorXd& out,
                            Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  this->channel(channel);  // range check: throws, naming the channels
  const std::size_t t = static_cast<std::size_t>(channel) / p_.anchors.size();
  const std::size_t a = static_cast<std::size_t>(channel) % p_.anchors.size();
  const Eigen::Vector3d& l = p_.tags[t];
  const double c = std::cos(xc[2]), s = std::sin(xc[2]);
  const Eigen::Vector2d rl(c * l.x() - s * l.y(), s * l.x() + c * l.y());
  const Eigen::Vector2d d = xc.head<2>() + rl - p_.anchors[a].head<2>();
  const double dz = p_.height + l.z() - p_.anchors[a].z();
  const double rho = std::sqrt(d.squaredNorm() + dz * dz);
  const double scale = i_scale_ >= 0 ? xb[i_scale_] : 1.0;
  const int ib = biasIndex(channel);
  if (J_h_xb) {
    *J_h_xb = Eigen::MatrixXd::Zero(1, dims().nb);
    if (ib >= 0) (*J_h_xb)(0, ib) = 1.0;
    if (i_scale_ >= 0) (*J_h_xb)(0, i_scale_) = rho;
  }
  if (J_h_xc) {
    *J_h_xc = Eigen::MatrixXd::Zero(1, 6);
    if (rho > 0) {
      (*J_h_xc)(0, 0) = scale * d.x() / rho;
      (*J_h_xc)(0, 1) = scale * d.y() / rho;
      (*J_h_xc)(0, 2) = scale * (d.x() * -rl.y() + d.y() * rl.x()) / rho;  // R'(yaw) l = (−rl_y, rl_x)
    }
  }
  const double g = i_antenna_ >= 0 ? antennaDelay(t, c, s, d, xb, J_h_xc, J_h_xb) : 0.0;
  out.resize(1);
  out[0] = scale * rho + (ib >= 0 ? xb[ib] : 0.0) + g;
}

// The anchor in the body frame, seen from the tag: v = R(yaw)ᵀ(−d), β =
// atan2(v_y, v_x); g_t(β) = Σ_{k=2..K} a_k cos kβ + b_k sin kβ, cos kβ and
// sin kβ by the angle-sum recurrence. ∂β/∂v = (−v_y, v_x)/|v|²; ∂v/∂p =
// −Rᵀ; ∂v/∂yaw = ((v + l)_y, −(v + l)_x).
double PlanarRigidBody::antennaDelay(std::size_t t, double c, double s, const Eigen::Vector2d& d,
                                     const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                                     Eigen::MatrixXd* J_h_xb) const {
  const Eigen::Vector2d v(-(c * d.x() + s * d.y()), -(-s * d.x() + c * d.y()));
  const double vn2 = v.squaredNorm();
  if (!(vn2 > 0)) return 0.0;  // the anchor straight above the tag: no bearing
  const double vn = std::sqrt(vn2), cos_b = v.x() / vn, sin_b = v.y() / vn;
  const int i0 = i_antenna_ + static_cast<int>(t) * antennaTermsPerTag(p_);
  double ck = cos_b * cos_b - sin_b * sin_b, sk = 2 * sin_b * cos_b, g = 0, dg = 0;  // k = 2
  for (int k = 2; k <= p_.antenna_harmonics; ++k) {
    const int i = i0 + 2 * (k - 2);
    g += xb[i] * ck + xb[i + 1] * sk;
    dg += k * (-xb[i] * sk + xb[i + 1] * ck);
    if (J_h_xb) (*J_h_xb)(0, i) = ck, (*J_h_xb)(0, i + 1) = sk;
    const double next_c = ck * cos_b - sk * sin_b;
    sk = sk * cos_b + ck * sin_b;
    ck = next_c;
  }
  if (J_h_xc && dg != 0) {
    const Eigen::Vector2d db_dv = Eigen::Vector2d(-v.y(), v.x()) / vn2;
    const Eigen::Vector2d vl = v + p_.tags[t].head<2>();
    (*J_h_xc)(0, 0) += dg * -(db_dv.x() * c - db_dv.y() * s);
    (*J_h_xc)(0, 1) += dg * -(db_dv.x() * s + db_dv.y() * c);
    (*J_h_xc)(0, 2) += dg * (db_dv.x() * vl.y() - db_dv.y() * vl.x());
  }
  return g;
}

Eigen::MatrixXd PlanarRigidBody::processNoise(double dt) const {
  return bodyProcessNoise(p_, dt);
}

namespace {
std::vector<ParamSpec> bodyParams() {
  using namespace param;
  std::vector<ParamSpec> p{
      real("model", "T", "nominal step (s)"),
      required(table("model", "anchors", {"anchor", "x", "y", "z"}, "anchors: rows 'id x y z' (m), or a CSV file")),
      required(table("model", "tags", {"tag", "x", "y", "z"}, "tags' lever arms: rows 'id x y z' (m), or a CSV file")),
      real("model", "height", "the known height of the body origin (m)"),
      learnable(real("model", "accel_sd", "white acceleration, m/s² per √Hz")),
      learnable(real("model", "yaw_accel_sd", "white angular acceleration, rad/s² per √Hz")),
      learnable(real("model", "range_sd", "σ of one range (m)")),
      flag("model", "link_biases", "estimate a bias per link (bias_<tag>_<anchor>)"),
      flag("model", "range_scale", "estimate a common range scale"),
      real("model", "antenna_harmonics",
              "harmonics K of each tag's antenna delay in the anchor's body-frame bearing (0: none)")};
  for (auto& l : lossParams("model")) p.push_back(l);
  for (auto& q : {real("model", "ekf_gate", "EKF NIS gate of every range (0: none)"),
                  vector("prior", "start", "prior mean of [px, py, yaw] (default: the anchors' centroid, 0)"),
                  real("prior", "position_sd", "prior σ of px and py (m)"), real("prior", "yaw_sd", "prior σ of yaw"),
                  real("prior", "velocity_sd", "prior σ of vx, vy (m/s)"),
                  real("prior", "omega_sd", "prior σ of the yaw rate (rad/s)"),
                  learnablePrior(real("prior", "bias_sd", "prior σ of each link's own bias (about the common part), m")),
                  real("prior", "bias_common_sd", "prior σ of a bias every link shares (0: none), m"),
                  real("prior", "range_scale_sd", "prior σ of the range scale (mean 1)"),
                  learnablePrior(real("prior", "antenna_sd", "prior σ of each antenna-delay harmonic's coefficient, m"))})
    p.push_back(q);
  return p;
}

template <class Points>
void readPoints(const ParamSource& in, const char* key, const char* column, std::vector<int>& ids, Points& points) {
  const Eigen::MatrixXd rows = in.table("model", key, {column, "x", "y", "z"});
  for (Eigen::Index i = 0; i < rows.rows(); ++i) {
    if (rows(i, 0) != std::floor(rows(i, 0)))
      throw InputError(in.where("model", key) + ": row " + std::to_string(i + 1) + ": id must be an integer");
    ids.push_back(static_cast<int>(rows(i, 0)));
    points.emplace_back(rows(i, 1), rows(i, 2), rows(i, 3));
  }
}

PlanarRigidBody::Params readBody(const ParamSource& in) {
  PlanarRigidBody::Params p;
  readPoints(in, "anchors", "anchor", p.anchor_ids, p.anchors);
  readPoints(in, "tags", "tag", p.tag_ids, p.tags);
  for (auto [key, value] : {std::pair{"T", &p.T}, {"height", &p.height}, {"accel_sd", &p.accel_sd},
                            {"yaw_accel_sd", &p.yaw_accel_sd}, {"range_sd", &p.range_sd}, {"ekf_gate", &p.ekf_gate}})
    *value = in.real("model", key, *value);
  p.link_biases = in.flag("model", "link_biases", p.link_biases);
  p.range_scale = in.flag("model", "range_scale", p.range_scale);
  const double harmonics = in.real("model", "antenna_harmonics", p.antenna_harmonics);
  if (harmonics != std::floor(harmonics) || harmonics < 0 || harmonics > 8)
    throw InputError(in.where("model", "antenna_harmonics") + ": must be a whole number in [0, 8], got " +
                     std::to_string(harmonics));
  p.antenna_harmonics = static_cast<int>(harmonics);
  p.range_loss = readLoss(in, "model");
  if (in.has("prior", "start")) {
    p.start = in.vector("prior", "start", 3);
  } else if (!p.anchors.empty()) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const auto& a : p.anchors) centroid += a;
    p.start << centroid.x() / static_cast<double>(p.anchors.size()), centroid.y() / static_cast<double>(p.anchors.size()), 0;
  }
  for (auto [key, value] : {std::pair{"position_sd", &p.position_sd}, {"yaw_sd", &p.yaw_sd},
                            {"velocity_sd", &p.velocity_sd}, {"omega_sd", &p.omega_sd}, {"bias_sd", &p.bias_sd},
                            {"bias_common_sd", &p.bias_common_sd}, {"range_scale_sd", &p.range_scale_sd},
                            {"antenna_sd", &p.antenna_sd}})
    *value = in.real("prior", key, *value);
  return p;
}

Eigen::MatrixXd pointRows(const std::vector<int>& ids, const std::vector<Eigen::Vector3d>& points) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(points.size()), 4);
  for (std::size_t i = 0; i < points.size(); ++i) out.row(static_cast<Eigen::Index>(i)) << ids[i], points[i].transpose();
  return out;
}

void writeBody(const PlanarRigidBody::Params& p, ParamSink& out) {
  out.real("model", "T", p.T);
  out.matrix("model", "anchors", pointRows(p.anchor_ids, p.anchors));
  out.matrix("model", "tags", pointRows(p.tag_ids, p.tags));
  for (auto [key, value] : {std::pair{"height", p.height}, {"accel_sd", p.accel_sd}, {"yaw_accel_sd", p.yaw_accel_sd},
                            {"range_sd", p.range_sd}})
    out.real("model", key, value);
  out.flag("model", "link_biases", p.link_biases);
  out.flag("model", "range_scale", p.range_scale);
  out.real("model", "antenna_harmonics", p.antenna_harmonics);
  writeLoss(p.range_loss, "model", out);
  out.real("model", "ekf_gate", p.ekf_gate);
  out.vector("prior", "start", p.start);
  for (auto [key, value] : {std::pair{"position_sd", p.position_sd}, {"yaw_sd", p.yaw_sd},
                            {"velocity_sd", p.velocity_sd}, {"omega_sd", p.omega_sd}, {"bias_sd", p.bias_sd},
                            {"bias_common_sd", p.bias_common_sd}, {"range_scale_sd", p.range_scale_sd},
                            {"antenna_sd", p.antenna_sd}})
    out.real("prior", key, value);
}

const ModelRegistration planar_rigid_body_registration{{
    "planar_rigid_body", {}, "PlanarRigidBody",
    "A rigid body in a plane (constant velocity) with range tags at lever arms, ranging to anchors; a bias per "
    "link and a common range scale as optional constants; one channel per link.",
    bodyParams(),
    [](const ParamSource& in) -> std::unique_ptr<Model> { return std::make_unique<PlanarRigidBody>(readBody(in)); },
    [](const Model& m, ParamSink& out) { writeBody(dynamic_cast<const PlanarRigidBody&>(m).params(), out); },
    [](const Model& m) { return dynamic_cast<const PlanarRigidBody*>(&m) != nullptr; },
    [](ParamSink& out) { writeBody(PlanarRigidBody::Params{}, out); }}};
}  // namespace

}  // namespace gssm::models
