#include "gssm/model/model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>
#include <set>
#include <sstream>

#include "gssm/core/angles.h"
#include "gssm/core/error.h"
#include "gssm/core/rotation_blocks.h"
#include "model/central_differences.h"

namespace gssm {

namespace {
void requireNames(const std::vector<std::string>& names, int n, const std::string& what,
                  std::set<std::string>& seen) {
  if (static_cast<int>(names.size()) != n)
    throw InvalidArgument("model: " + std::to_string(names.size()) + " " + what +
                          " names given, the dimension is " + std::to_string(n));
  for (const auto& s : names) {
    if (s.empty() || s.find_first_of(", \t\n\"") != std::string::npos)
      throw InvalidArgument("model: " + what + " name '" + s +
                            "' must be non-empty with no comma, space or quote");
    if (!seen.insert(s).second)
      throw InvalidArgument("model: name '" + s + "' is used twice");
  }
}
}  // namespace

Model::Model(ModelDims dims, ModelNames names, ModelNoise noise)
    : dims_(dims), names_(std::move(names)), noise_(std::move(noise)) {
  if (dims_.nc < 1 || dims_.nb < 0 || dims_.nu < 0 || dims_.ny < 1)
    throw InvalidArgument("model: need n_c >= 1, n_b >= 0, n_u >= 0, n_y >= 1");
  std::set<std::string> states, meas;
  requireNames(names_.state, dims_.nc, "state", states);
  requireNames(names_.constants, dims_.nb, "constant", states);
  requireNames(names_.input, dims_.nu, "input", meas);
  requireNames(names_.measurement, dims_.ny, "measurement", meas);
  if (!(noise_.T > 0) || !std::isfinite(noise_.T))
    throw InvalidArgument("model: step T must be a positive number, got " +
                          std::to_string(noise_.T));
  requireCovariance(noise_.Q, dims_.nc, "model: process noise Q");
  requireCovariance(noise_.R, dims_.ny, "model: measurement noise R");
  MeasurementChannel y;
  y.name = "y";
  y.components = names_.measurement;
  y.R = noise_.R;
  channels_ = {y};
  channel_noise_ = {GaussianNoise(noise_.R, "model: measurement noise R")};
  q_cache_ = std::make_shared<NoiseCache>();
  requireVector(noise_.prior_state.mean, dims_.nc, "model: prior mean of x_c(0)");
  requireCovariance(noise_.prior_state.covariance, dims_.nc, "model: prior covariance of x_c(0)");
  requireVector(noise_.prior_constants.mean, dims_.nb, "model: prior mean of x_b");
  if (dims_.nb > 0)
    requireCovariance(noise_.prior_constants.covariance, dims_.nb,
                      "model: prior covariance of x_b");
}

Eigen::MatrixXd Model::processNoise(double dt) const { return noise_.Q * (dt / noise_.T); }
Eigen::MatrixXd Model::processNoiseOf(double dt, const Eigen::VectorXd&) const { return processNoise(dt); }

void Model::hInto(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::VectorXd& out,
                  Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  out = h(channel, xc, xb, J_h_xc, J_h_xb);
}

Eigen::VectorXd Model::h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                         Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const {
  if (channel != 0)
    throw InvalidArgument("model '" + name() + "': channel " + std::to_string(channel) +
                          " has no measurement function (the model does not override h(channel, ...))");
  return h(xc, xb, J_h_xc, J_h_xb);
}

void Model::hRegressedInto(int c, const Eigen::VectorXd&, const Eigen::VectorXd&, const Eigen::VectorXd&,
                           Eigen::VectorXd&, Eigen::MatrixXd*, Eigen::MatrixXd*) const {
  throw InvalidArgument("model '" + name() + "': channel '" + channel(c).name + "' reads " +
                        std::to_string(channel(c).regressors) +
                        " known values but the model does not override hRegressedInto");
}

void Model::throwRegressors(int c, Eigen::Index given) const {
  const MeasurementChannel& ch = channel(c);
  throw InvalidArgument("model '" + name() + "': a measurement on channel '" + ch.name + "' carries " +
                        std::to_string(given) + " known values (regressors); the channel reads " +
                        std::to_string(ch.regressors));
}

void Model::throwNoChannel(int c) const {
  throw InvalidArgument("model '" + name() + "': no channel " + std::to_string(c) + " (it has " +
                        std::to_string(numChannels()) + ")");
}

int Model::channelIndex(const std::string& channel_name) const {
  std::string known;
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    if (channels_[i].name == channel_name) return static_cast<int>(i);
    known += (i ? ", " : "") + channels_[i].name;
  }
  throw InvalidArgument("model '" + name() + "': unknown channel '" + channel_name + "' (channels: " + known + ")");
}

const GaussianNoise& Model::channelNoiseModel(int c) const {
  channel(c);  // range check
  return channel_noise_[static_cast<std::size_t>(c)];
}

void Model::setChannelLoss(int c, const RobustLoss& loss, double ekf_gate) {
  std::string why;
  if (!loss.validate(&why)) throw InvalidArgument("model '" + name() + "', channel '" + channel(c).name + "': " + why);
  if (!(ekf_gate >= 0) || !std::isfinite(ekf_gate))
    throw InvalidArgument("model '" + name() + "', channel '" + channel(c).name + "': EKF gate must be >= 0");
  channels_[static_cast<std::size_t>(c)].loss = loss;
  channels_[static_cast<std::size_t>(c)].ekf_gate = ekf_gate;
}

void Model::setChannels(std::vector<MeasurementChannel> channels) {
  if (channels.empty() || channels.front().dim() != dims_.ny)
    throw InvalidArgument("model: channel 0 must have n_y = " + std::to_string(dims_.ny) + " components");
  std::set<std::string> names, components;
  std::vector<GaussianNoise> noise;
  for (const auto& ch : channels) {
    if (ch.name.empty() || !names.insert(ch.name).second)
      throw InvalidArgument("model: channel name '" + ch.name + "' is empty or used twice");
    requireNames(ch.components, ch.dim(), "channel '" + ch.name + "' component", components);
    requireCovariance(ch.R, ch.dim(), "model: noise R of channel '" + ch.name + "'");
    if (!(ch.own_R_scale > 0) || !std::isfinite(ch.own_R_scale))
      throw InvalidArgument("model: channel '" + ch.name + "': own_R_scale " + std::to_string(ch.own_R_scale) +
                            " must be finite and > 0");
    if (ch.regressors < 0)
      throw InvalidArgument("model: channel '" + ch.name + "': regressors " + std::to_string(ch.regressors) + " < 0");
    for (int a : ch.angles)
      if (a < 0 || a >= ch.dim()) throw InvalidArgument("model: channel '" + ch.name + "': angle component out of range");
    for (std::size_t i = 0; i < ch.constants.size(); ++i)
      if (ch.constants[i] < 0 || ch.constants[i] >= dims_.nb || (i > 0 && ch.constants[i] <= ch.constants[i - 1]))
        throw InvalidArgument("model: channel '" + ch.name + "': its constants must be ascending indices into x_b (0 to " +
                              std::to_string(dims_.nb - 1) + ")");
    std::string why;
    if (!ch.loss.validate(&why)) throw InvalidArgument("model: channel '" + ch.name + "': " + why);
    noise.emplace_back(ch.R, "model: noise R of channel '" + ch.name + "'");
  }
  channels_ = std::move(channels);
  channel_noise_ = std::move(noise);
}

void Model::setAngleStates(std::vector<int> stacked_components) {
  for (int a : stacked_components)
    if (a < 0 || a >= dims_.nc + dims_.nb)
      throw InvalidArgument("model: angle component " + std::to_string(a) + " outside the stacked state");
  std::sort(stacked_components.begin(), stacked_components.end());
  angle_states_ = std::move(stacked_components);
}

void Model::setRotationBlocks(std::vector<int> first_components) {
  std::sort(first_components.begin(), first_components.end());
  const int nc = dims_.nc, n = nc + dims_.nb;
  for (std::size_t i = 0; i < first_components.size(); ++i) {
    const int b = first_components[i];
    const std::string what = "model: rotation block at stacked component " + std::to_string(b);
    if (b < 0 || b + 3 > n || (b < nc && b + 3 > nc))
      throw InvalidArgument(what + " does not fit in x_c (" + std::to_string(nc) + ") or x_b (" +
                            std::to_string(dims_.nb) + ")");
    if (i > 0 && first_components[i - 1] + 3 > b) throw InvalidArgument(what + " overlaps the block before it");
    for (int a : angle_states_)
      if (a >= b && a < b + 3) throw InvalidArgument(what + " holds angle component " + std::to_string(a));
  }
  rotation_blocks_ = std::move(first_components);
}

std::vector<int> Model::rotationBlocksIn(bool constants) const {
  std::vector<int> out;
  for (int b : rotation_blocks_)
    if (constants ? b >= dims_.nc : b < dims_.nc) out.push_back(constants ? b - dims_.nc : b);
  return out;
}

Eigen::VectorXd Model::wrapStacked(Eigen::VectorXd z) const {
  wrapAngles(z, angle_states_);
  normalizeBlocks(z, rotation_blocks_);
  return z;
}

struct Model::NoiseCache {
  std::mutex mutex;
  std::array<std::pair<double, GaussianNoise>, 8> entries;
  std::size_t used = 0, next = 0;
};

GaussianNoise Model::processNoiseModel(double dt, std::int64_t step) const {
  NoiseCache& c = *q_cache_;
  {
    std::lock_guard<std::mutex> lock(c.mutex);
    for (std::size_t i = 0; i < c.used; ++i)
      if (c.entries[i].first == dt) return c.entries[i].second;
  }
  GaussianNoise q(processNoise(dt), "process noise of step " + std::to_string(step));  // may throw: nothing cached
  std::lock_guard<std::mutex> lock(c.mutex);
  c.entries[c.next] = {dt, q};
  c.next = (c.next + 1) % c.entries.size();
  c.used = std::max(c.used, c.next == 0 ? c.entries.size() : c.next);
  return q;
}

void Model::report(const Eigen::VectorXd& mean, const Eigen::MatrixXd& covariance, Eigen::VectorXd& value,
                   Eigen::VectorXd& sd) const {
  value = mean;
  sd = covariance.diagonal().cwiseSqrt();
}

std::vector<std::string> Model::stackedStateNames() const {
  std::vector<std::string> out = names_.state;
  out.insert(out.end(), names_.constants.begin(), names_.constants.end());
  return out;
}

namespace {
// Accumulates the worst entry of analytic vs numeric.
void compare(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric,
             const std::string& name, JacobianCheck& out) {
  if (analytic.rows() != numeric.rows() || analytic.cols() != numeric.cols()) {
    std::ostringstream os;
    os << name << " has size " << analytic.rows() << "x" << analytic.cols() << ", expected "
       << numeric.rows() << "x" << numeric.cols();
    throw InvalidArgument("checkJacobians: " + os.str());
  }
  for (Eigen::Index i = 0; i < numeric.rows(); ++i)
    for (Eigen::Index j = 0; j < numeric.cols(); ++j) {
      const double abs_err = std::abs(analytic(i, j) - numeric(i, j));
      const double rel_err = abs_err / std::max(1.0, std::abs(numeric(i, j)));
      out.max_abs_error = std::max(out.max_abs_error, abs_err);
      if (rel_err >= out.max_rel_error) {
        out.max_rel_error = rel_err;
        std::ostringstream os;
        os << name << "(" << i << "," << j << "): analytic " << analytic(i, j) << ", numeric "
           << numeric(i, j);
        out.worst = os.str();
      }
    }
}

}  // namespace

JacobianCheck checkJacobians(const Model& model, const Eigen::VectorXd& xc,
                             const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                             double eps) {
  const ModelDims& d = model.dims();
  JacobianCheck out;
  Eigen::MatrixXd J_f_xc, J_f_xb, J_h_xc, J_h_xb;
  // On the tangents: x moved by ⊕, f's values compared by ⊖ (rotation blocks).
  const std::vector<int>& rot = model.rotationBlocks();
  const int nc = d.nc;
  auto differences = [&](auto g, const Eigen::VectorXd& x, Eigen::Index rows, int in_offset, bool out_state) {
    return internal::tangentDifferences(g, x, rows, eps, rot, in_offset, out_state ? rot : std::vector<int>{}, 0);
  };
  model.f(xc, xb, u, dt, &J_f_xc, &J_f_xb);
  compare(J_f_xc, differences([&](const Eigen::VectorXd& v) { return model.f(v, xb, u, dt); }, xc, nc, 0, true), "J_f_xc", out);
  compare(J_f_xb, differences([&](const Eigen::VectorXd& v) { return model.f(xc, v, u, dt); }, xb, nc, nc, true), "J_f_xb", out);
  // Every channel's h (channel 0 is the default h); a channel that reads
  // known values gets a fixed made-up set of them.
  for (int c = 0; c < model.numChannels(); ++c) {
    const int ny = model.channel(c).dim();
    const std::string at = c == 0 ? "" : "[" + model.channel(c).name + "]";
    Eigen::VectorXd known(model.channel(c).regressors);
    for (Eigen::Index j = 0; j < known.size(); ++j) known[j] = 0.5 * std::sin(1.3 * static_cast<double>(j) + 0.7);
    model.hWith(c, known, xc, xb, &J_h_xc, &J_h_xb);
    compare(J_h_xc, differences([&](const Eigen::VectorXd& v) { return model.hWith(c, known, v, xb); }, xc, ny, 0, false),
            "J_h_xc" + at, out);
    compare(J_h_xb, differences([&](const Eigen::VectorXd& v) { return model.hWith(c, known, xc, v); }, xb, ny, nc, false),
            "J_h_xb" + at, out);
  }
  return out;
}

}  // namespace gssm
