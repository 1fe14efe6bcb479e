#include "gssm/models/linear.h"

#include <unsupported/Eigen/MatrixFunctions>

#include "gssm/core/error.h"
#include "gssm/model/noise_params.h"
#include "gssm/model/registry.h"

namespace gssm::models {

namespace {
ModelDims linearDims(const LinearSystem& s) {
  const int nc = static_cast<int>(s.A_c.rows());
  const int nb = static_cast<int>(s.A_b.cols());
  const int nu = static_cast<int>(s.B.cols());
  const int ny = static_cast<int>(s.C_c.rows());
  auto need = [](bool ok, const char* what) {
    if (!ok) throw InvalidArgument(std::string("LinearModel: ") + what);
  };
  need(s.A_c.cols() == nc, "A_c must be square (n_c x n_c)");
  need(s.A_b.rows() == nc, "A_b must have n_c rows");
  need(s.B.rows() == nc || (nu == 0 && s.B.size() == 0), "B must have n_c rows");
  need(s.C_c.cols() == nc, "C_c must have n_c columns");
  need(s.C_b.rows() == ny && s.C_b.cols() == nb, "C_b must be n_y x n_b");
  return {nc, nb, nu, ny};
}

std::vector<std::string> numbered(const std::string& prefix, int n) {
  std::vector<std::string> out;
  for (int i = 1; i <= n; ++i) out.push_back(prefix + std::to_string(i));
  return out;
}

ModelNames linearNames(const LinearSystem& s) {
  const ModelDims d = linearDims(s);
  ModelNames n = s.names;
  if (n.state.empty()) n.state = numbered("x", d.nc);
  if (n.constants.empty()) n.constants = numbered("b", d.nb);
  if (n.input.empty()) n.input = numbered("u", d.nu);
  if (n.measurement.empty()) n.measurement = numbered("y", d.ny);
  return n;
}
}  // namespace

LinearModel::LinearModel(LinearSystem sys, Discretization d)
    : Model(linearDims(sys), linearNames(sys), sys.noise), sys_(std::move(sys)), disc_(d) {
  if (sys_.B.size() == 0) sys_.B.setZero(dims().nc, 0);
  if (!sys_.A_c.allFinite() || !sys_.A_b.allFinite() || !sys_.B.allFinite() ||
      !sys_.C_c.allFinite() || !sys_.C_b.allFinite())
    throw InvalidArgument("LinearModel: a system matrix has a NaN or infinite entry");
  if (!sys_.channels.empty()) {
    std::vector<MeasurementChannel> channels{channel(0)};
    for (const auto& c : sys_.channels) {
      if (c.C_c.rows() != c.R.rows() || c.C_c.cols() != dims().nc || c.C_b.rows() != c.R.rows() ||
          c.C_b.cols() != dims().nb || !c.C_c.allFinite() || !c.C_b.allFinite())
        throw InvalidArgument("LinearModel: channel '" + c.name + "': C_c must be n × n_c and C_b n × n_b, finite, "
                              "with n the size of its R");
      MeasurementChannel ch;
      ch.name = c.name;
      ch.components = c.components.empty() ? numbered(c.name + "_", static_cast<int>(c.R.rows())) : c.components;
      ch.R = c.R;
      channels.push_back(std::move(ch));
    }
    setChannels(std::move(channels));
  }
  // The nominal step's matrices are cached: f() at the nominal step is hot.
  Eigen::MatrixXd Fc, Fb, Bk;
  discreteMatrices(nominalStep(), Fc, Fb, Bk);
  Fc_T_ = Fc;
  Fb_T_ = Fb;
  Bk_T_ = Bk;
}

void LinearModel::discreteMatrices(double dt, Eigen::MatrixXd& F_c, Eigen::MatrixXd& F_b,
                                   Eigen::MatrixXd& B_k) const {
  if (Fc_T_.size() > 0 && dt == nominalStep()) {
    F_c = Fc_T_;
    F_b = Fb_T_;
    B_k = Bk_T_;
    return;
  }
  const ModelDims& d = dims();
  if (disc_ == Discretization::Euler) {
    F_c = Eigen::MatrixXd::Identity(d.nc, d.nc) + sys_.A_c * dt;
    F_b = sys_.A_b * dt;
    B_k = sys_.B * dt;
    return;
  }
  const int n = d.nc + d.nb + d.nu;
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  M.block(0, 0, d.nc, d.nc) = sys_.A_c;
  M.block(0, d.nc, d.nc, d.nb) = sys_.A_b;
  M.block(0, d.nc + d.nb, d.nc, d.nu) = sys_.B;
  const Eigen::MatrixXd E = (M * dt).exp();
  F_c = E.block(0, 0, d.nc, d.nc);
  F_b = E.block(0, d.nc, d.nc, d.nb);
  B_k = E.block(0, d.nc + d.nb, d.nc, d.nu);
}

Eigen::VectorXd LinearModel::f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                               const Eigen::VectorXd& u, double dt, Eigen::MatrixXd* J_f_xc,
                               Eigen::MatrixXd* J_f_xb) const {
  Eigen::MatrixXd Fc, Fb, Bk;
  discreteMatrices(dt, Fc, Fb, Bk);
  Eigen::VectorXd out = Fc * xc + Fb * xb;
  if (dims().nu > 0) out += Bk * u;
  if (J_f_xc) *J_f_xc = Fc;
  if (J_f_xb) *J_f_xb = Fb;
  return out;
}

Eigen::VectorXd LinearModel::h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                               Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  if (J_h_xc) *J_h_xc = sys_.C_c;
  if (J_h_xb) *J_h_xb = sys_.C_b;
  return sys_.C_c * xc + sys_.C_b * xb;
}

void LinearModel::outputMatrices(int c, Eigen::MatrixXd& C_c, Eigen::MatrixXd& C_b) const {
  channel(c);  // range check
  const bool base = c == 0;
  C_c = base ? sys_.C_c : sys_.channels[static_cast<std::size_t>(c - 1)].C_c;
  C_b = base ? sys_.C_b : sys_.channels[static_cast<std::size_t>(c - 1)].C_b;
}

Eigen::VectorXd LinearModel::h(int c, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                               Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  if (c == 0) return h(xc, xb, J_h_xc, J_h_xb);
  channel(c);  // range check
  const LinearChannel& ch = sys_.channels[static_cast<std::size_t>(c - 1)];
  if (J_h_xc) *J_h_xc = ch.C_c;
  if (J_h_xb) *J_h_xb = ch.C_b;
  return ch.C_c * xc + ch.C_b * xb;
}

namespace {
std::vector<ParamSpec> linearParams() {
  using namespace param;
  std::vector<ParamSpec> p{required(matrix("model", "A_c", "d/dt x_c = A_c x_c + A_b x_b + B u (n_c×n_c)")),
                           matrix("model", "A_b", "n_c×n_b; absent: no constants"),
                           matrix("model", "B", "n_c×n_u; absent: no input"),
                           required(matrix("model", "C_c", "y = C_c x_c + C_b x_b (n_y×n_c)")),
                           matrix("model", "C_b", "n_y×n_b"),
                           text("model", "discretization", "euler (F = I + A T, the paper's) or exact (expm)"),
                           sections("model", "channels", "channel", "further sensors, each a [channel.<name>]"),
                           matrix("channel", "C_c", "the channel's C_c"),
                           matrix("channel", "C_b", "the channel's C_b"),
                           learnable(matrix("channel", "R", "the channel's noise covariance")),
                           names("channel", "components", "the channel's component names"),
                           names("model", "state_names", "names of x_c (default x1..)"),
                           names("model", "constant_names", "names of x_b (default b1..)"),
                           names("model", "input_names", "names of u (default u1..)"),
                           names("model", "measurement_names", "names of y (default y1..)")};
  for (ParamSpec& n : noiseParams()) {
    if (n.key == "Q" || n.key == "R") n.required = true;
    p.push_back(n);
  }
  return p;
}

Eigen::MatrixXd matrixOr(const ParamSource& in, const std::string& section, const char* key, Eigen::Index rows,
                         Eigen::Index cols) {
  return in.has(section, key) ? in.matrix(section, key, rows, cols) : Eigen::MatrixXd::Zero(rows, cols);
}

std::vector<LinearChannel> readChannels(const ParamSource& in, Eigen::Index nc, Eigen::Index nb) {
  std::vector<LinearChannel> out;
  if (!in.has("model", "channels")) return out;
  for (const std::string& name : in.names("model", "channels")) {
    const std::string section = "channel." + name;
    LinearChannel c;
    c.name = name;
    c.C_c = in.matrix(section, "C_c", -1, nc);
    c.C_b = matrixOr(in, section, "C_b", c.C_c.rows(), nb);
    c.R = in.matrix(section, "R", c.C_c.rows(), c.C_c.rows());
    if (in.has(section, "components")) c.components = in.names(section, "components");
    out.push_back(std::move(c));
  }
  return out;
}

std::unique_ptr<Model> readLinear(const ParamSource& in) {
  LinearSystem s;
  s.A_c = in.matrix("model", "A_c");
  const Eigen::Index nc = s.A_c.rows();
  s.C_c = in.matrix("model", "C_c", -1, nc);
  // No A_b and C_b: a model without constants (n_b = 0).
  const Eigen::Index nb = in.has("model", "A_b")   ? in.matrix("model", "A_b").cols()
                          : in.has("model", "C_b") ? in.matrix("model", "C_b").cols()
                                                   : 0;
  s.A_b = matrixOr(in, "model", "A_b", nc, nb);
  s.C_b = matrixOr(in, "model", "C_b", s.C_c.rows(), nb);
  s.B = in.has("model", "B") ? in.matrix("model", "B", nc, -1) : Eigen::MatrixXd::Zero(nc, 0);
  s.channels = readChannels(in, nc, nb);
  for (auto [key, names] : {std::pair{"state_names", &s.names.state}, {"constant_names", &s.names.constants},
                            {"input_names", &s.names.input}, {"measurement_names", &s.names.measurement}})
    if (in.has("model", key)) *names = in.names("model", key);
  const ModelDims d{static_cast<int>(nc), static_cast<int>(nb), static_cast<int>(s.B.cols()),
                    static_cast<int>(s.C_c.rows())};
  ModelNoise fallback;  // priors: zero mean, unit covariance
  fallback.prior_state = {Eigen::VectorXd::Zero(nc), Eigen::MatrixXd::Identity(nc, nc)};
  fallback.prior_constants = {Eigen::VectorXd::Zero(nb), Eigen::MatrixXd::Identity(nb, nb)};
  s.noise = readNoise(in, d, fallback);
  const std::string disc = in.text("model", "discretization", "euler");
  if (disc != "euler" && disc != "exact")
    throw InputError(in.where("model", "discretization") + " = '" + disc + "': expected euler or exact");
  return std::make_unique<LinearModel>(std::move(s), disc == "exact" ? Discretization::Exact : Discretization::Euler);
}

void writeLinear(const LinearModel& lin, ParamSink& out) {
  const LinearSystem& s = lin.system();
  out.matrix("model", "A_c", s.A_c);
  if (s.A_b.cols() > 0) out.matrix("model", "A_b", s.A_b);
  if (s.B.size()) out.matrix("model", "B", s.B);
  out.matrix("model", "C_c", s.C_c);
  if (s.C_b.cols() > 0) out.matrix("model", "C_b", s.C_b);
  std::vector<std::string> channels;
  for (const auto& c : s.channels) {
    channels.push_back(c.name);
    out.matrix("channel." + c.name, "C_c", c.C_c);
    if (c.C_b.cols() > 0) out.matrix("channel." + c.name, "C_b", c.C_b);
    out.matrix("channel." + c.name, "R", c.R);
    if (!c.components.empty()) out.names("channel." + c.name, "components", c.components);
  }
  if (!channels.empty()) out.names("model", "channels", channels);
  out.text("model", "discretization", lin.discretization() == Discretization::Exact ? "exact" : "euler");
  for (auto [key, names] : {std::pair{"state_names", &s.names.state}, {"constant_names", &s.names.constants},
                            {"input_names", &s.names.input}, {"measurement_names", &s.names.measurement}})
    if (!names->empty()) out.names("model", key, *names);
  writeNoise(lin, out);
}

const ModelRegistration linear_registration{{
    "linear", {}, "Linear",
    "A linear GSSM from matrices: x_c' = A_c x_c + A_b x_b + B u (continuous time, discretized by "
    "`discretization`), y = C_c x_c + C_b x_b; channels: further sensors.",
    linearParams(), readLinear,
    [](const Model& m, ParamSink& out) { writeLinear(dynamic_cast<const LinearModel&>(m), out); },
    [](const Model& m) { return dynamic_cast<const LinearModel*>(&m) != nullptr; },
    {}}};
}  // namespace

}  // namespace gssm::models
