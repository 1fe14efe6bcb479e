#include "gssm/models/nav2d.h"

#include "gssm/core/error.h"
#include "gssm/model/noise_params.h"
#include "gssm/model/registry.h"

namespace gssm::models {

namespace {
Eigen::MatrixXd whiteAcceleration(double q, double dt) {
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(4, 4);
  const double a = q * q;
  Q.topLeftCorner(2, 2).diagonal().setConstant(a * dt * dt * dt / 3);
  Q.topRightCorner(2, 2).diagonal().setConstant(a * dt * dt / 2);
  Q.bottomLeftCorner(2, 2).diagonal().setConstant(a * dt * dt / 2);
  Q.bottomRightCorner(2, 2).diagonal().setConstant(a * dt);
  return Q;
}

ModelNoise navNoise(const Nav2D::Params& p) {
  ModelNoise n;
  n.T = p.T;
  n.Q = whiteAcceleration(p.accel_noise, p.T);
  n.R = Eigen::MatrixXd::Identity(static_cast<Eigen::Index>(p.beacons.size()),
                                  static_cast<Eigen::Index>(p.beacons.size())) *
        (p.range_sigma * p.range_sigma);
  n.prior_state = {p.prior_state, Eigen::MatrixXd(p.prior_state_sd.cwiseAbs2().asDiagonal())};
  n.prior_constants = {p.prior_constants, Eigen::MatrixXd(p.prior_constants_sd.cwiseAbs2().asDiagonal())};
  return n;
}

ModelNames navNames(std::size_t beacons) {
  ModelNames n{{"px", "py", "vx", "vy"}, {"bax", "bay", "brho"}, {"ax", "ay"}, {}};
  for (std::size_t i = 1; i <= beacons; ++i) n.measurement.push_back("range" + std::to_string(i));
  return n;
}
}  // namespace

Nav2D::Nav2D(const Params& p) : Nav2D(navNoise(p), p.beacons, p.accel_noise) {}

Nav2D::Nav2D(const ModelNoise& noise, std::vector<Eigen::Vector2d> beacons, double accel_noise)
    : Model({4, 3, 2, static_cast<int>(beacons.size())}, navNames(beacons.size()), noise),
      beacons_(std::move(beacons)),
      accel_noise_(accel_noise) {
  if (!(accel_noise_ > 0)) throw InvalidArgument("Nav2D: accel_noise must be > 0");
}

Eigen::MatrixXd Nav2D::processNoise(double dt) const { return whiteAcceleration(accel_noise_, dt); }

Eigen::VectorXd Nav2D::f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                         Eigen::MatrixXd* J_f_xc, Eigen::MatrixXd* J_f_xb) const {
  const Eigen::Vector2d a = u.head<2>() - xb.head<2>();
  Eigen::VectorXd out(4);
  out.head<2>() = xc.head<2>() + xc.tail<2>() * dt + 0.5 * a * dt * dt;
  out.tail<2>() = xc.tail<2>() + a * dt;
  if (J_f_xc) {
    *J_f_xc = Eigen::MatrixXd::Identity(4, 4);
    J_f_xc->topRightCorner(2, 2).diagonal().setConstant(dt);
  }
  if (J_f_xb) {
    *J_f_xb = Eigen::MatrixXd::Zero(4, 3);
    J_f_xb->topLeftCorner(2, 2).diagonal().setConstant(-0.5 * dt * dt);
    J_f_xb->block(2, 0, 2, 2).diagonal().setConstant(-dt);
  }
  return out;
}

Eigen::VectorXd Nav2D::h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                         Eigen::MatrixXd* J_h_xb) const {
  const auto m = static_cast<Eigen::Index>(beacons_.size());
  Eigen::VectorXd y(m);
  if (J_h_xc) *J_h_xc = Eigen::MatrixXd::Zero(m, 4);
  if (J_h_xb) *J_h_xb = Eigen::MatrixXd::Zero(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    const Eigen::Vector2d d = xc.head<2>() - beacons_[static_cast<std::size_t>(i)];
    const double rho = d.norm();
    y[i] = rho + xb[2];
    // At a beacon the range is not differentiable; the zero row it gives is
    // reported by the solvers if nothing else determines the position.
    if (J_h_xc && rho > 0) J_h_xc->block(i, 0, 1, 2) = d.transpose() / rho;
    if (J_h_xb) (*J_h_xb)(i, 2) = 1.0;
  }
  return y;
}

std::vector<Eigen::Vector2d> Nav2D::landmarks() const { return beacons_; }

namespace {
std::vector<Eigen::Vector2d> points(const Eigen::MatrixXd& rows) {
  std::vector<Eigen::Vector2d> out;
  for (Eigen::Index i = 0; i < rows.rows(); ++i) out.emplace_back(rows(i, 0), rows(i, 1));
  return out;
}

std::vector<ParamSpec> navParams() {
  std::vector<ParamSpec> p = noiseParams({false, true});
  p.push_back(param::learnable(param::real("model", "accel_noise", "white acceleration noise density (m/s²/√Hz)")));
  p.push_back(param::table("model", "beacons", {"x", "y"}, "beacon positions (m), one row 'x y' each"));
  return p;
}

void writeNav(const Nav2D& nav, ParamSink& out) {
  Eigen::MatrixXd B(static_cast<Eigen::Index>(nav.beacons().size()), 2);
  for (std::size_t i = 0; i < nav.beacons().size(); ++i) B.row(static_cast<Eigen::Index>(i)) = nav.beacons()[i].transpose();
  out.matrix("model", "beacons", B);
  out.real("model", "accel_noise", nav.accelNoise());
  writeNoise(nav, out, {false, true});
}

// [model] type = nav_2d: beacons, accel_noise, T, R and the priors; absent
// keys keep Nav2D::Params' defaults (R: range_sigma² per beacon).
const ModelRegistration nav2d_registration{{
    "nav_2d", {"nav2d"}, "Nav2D",
    "Constant-velocity vehicle ranging to beacons, with an accelerometer bias and a range bias as constants.",
    navParams(),
    [](const ParamSource& in) -> std::unique_ptr<Model> {
      Nav2D::Params p;
      if (in.has("model", "beacons")) p.beacons = points(in.table("model", "beacons", {"x", "y"}));
      if (p.beacons.empty()) throw InputError(in.where("model", "beacons") + ": expected at least one beacon");
      p.accel_noise = in.real("model", "accel_noise", p.accel_noise);
      const Nav2D defaults(p);
      return std::make_unique<Nav2D>(readNoise(in, defaults.dims(), defaults.noise(), {false, true}), p.beacons,
                                     p.accel_noise);
    },
    [](const Model& m, ParamSink& out) { writeNav(dynamic_cast<const Nav2D&>(m), out); },
    [](const Model& m) { return dynamic_cast<const Nav2D*>(&m) != nullptr; },
    [](ParamSink& out) { writeNav(Nav2D(), out); }}};
}  // namespace

}  // namespace gssm::models
