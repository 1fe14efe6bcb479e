#include "gssm/models/linear.h"

#include <unsupported/Eigen/MatrixFunctions>

#include "gssm/core/error.h"

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

}  // namespace gssm::models
