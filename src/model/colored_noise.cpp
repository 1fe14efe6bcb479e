#include "gssm/model/colored_noise.h"

#include <algorithm>
#include <cmath>

#include "gssm/core/error.h"

namespace gssm {

namespace {

// Where the error states sit: the inner x_c, then each chosen channel's
// components in channel order.
struct Augmentation {
  int inner_nc = 0;
  std::vector<int> offset;  // per channel: its first error state in x_c, −1 if white
  int count = 0;            // error states in all
};

Augmentation layOut(const Model& inner, const ColoredNoise& noise) {
  if (!(noise.tau > 0) || !std::isfinite(noise.tau) || !(noise.sd > 0) || !std::isfinite(noise.sd))
    throw InvalidArgument("[colored_noise]: tau and sd must be > 0 (got tau " + std::to_string(noise.tau) + ", sd " +
                          std::to_string(noise.sd) + ")");
  Augmentation a;
  a.inner_nc = inner.dims().nc;
  a.offset.assign(static_cast<std::size_t>(inner.numChannels()), -1);
  const bool all = noise.channels.size() == 1 && noise.channels.front() == "all";
  std::vector<bool> chosen(a.offset.size(), all);
  if (!all)
    for (const auto& name : noise.channels) chosen[static_cast<std::size_t>(inner.channelIndex(name))] = true;
  for (int c = 0; c < inner.numChannels(); ++c)
    if (chosen[static_cast<std::size_t>(c)]) {
      a.offset[static_cast<std::size_t>(c)] = a.inner_nc + a.count;
      a.count += inner.channel(c).dim();
    }
  return a;
}

ModelNames augmentedNames(const Model& inner, const Augmentation& a) {
  ModelNames n = inner.names();
  for (int c = 0; c < inner.numChannels(); ++c) {
    if (a.offset[static_cast<std::size_t>(c)] < 0) continue;
    const MeasurementChannel& ch = inner.channel(c);
    for (const auto& component : ch.components)
      n.state.push_back("err_" + (ch.dim() == 1 ? component : ch.name + "_" + component));
  }
  return n;
}

Eigen::MatrixXd blockDiagonal(const Eigen::MatrixXd& top, int n, double diagonal) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(top.rows() + n, top.cols() + n);
  out.topLeftCorner(top.rows(), top.cols()) = top;
  out.bottomRightCorner(n, n).diagonal().setConstant(diagonal);
  return out;
}

// Var q = σ²(1 − φ²): e stays stationary at σ² over any step.
double driveVariance(const ColoredNoise& noise, double dt) {
  const double phi = std::exp(-dt / noise.tau);
  return noise.sd * noise.sd * (1 - phi * phi);
}

ModelNoise augmentedNoise(const Model& inner, const ColoredNoise& noise, const Augmentation& a) {
  ModelNoise n = inner.noise();
  n.Q = blockDiagonal(inner.processNoise(n.T), a.count, driveVariance(noise, n.T));
  n.prior_state.mean.conservativeResize(a.inner_nc + a.count);
  n.prior_state.mean.tail(a.count).setZero();
  n.prior_state.covariance = blockDiagonal(inner.priorState().covariance, a.count, noise.sd * noise.sd);
  return n;
}

// The augmented model. Everything but the error states is the inner model's.
class ColoredNoiseModel final : public Model {
 public:
  ColoredNoiseModel(std::unique_ptr<Model> inner, ColoredNoise noise, const Augmentation& a)
      : Model({a.inner_nc + a.count, inner->dims().nb, inner->dims().nu, inner->dims().ny}, augmentedNames(*inner, a),
              augmentedNoise(*inner, noise, a)),
        inner_(std::move(inner)),
        noise_(std::move(noise)),
        a_(a) {
    std::vector<MeasurementChannel> channels;
    for (int c = 0; c < inner_->numChannels(); ++c) channels.push_back(inner_->channel(c));
    setChannels(std::move(channels));
    std::vector<int> angles = inner_->angleStates();
    for (int& i : angles)
      if (i >= a_.inner_nc) i += a_.count;  // a constant: after the error states
    setAngleStates(std::move(angles));
    std::vector<int> rotations = inner_->rotationBlocks();
    for (int& i : rotations)
      if (i >= a_.inner_nc) i += a_.count;
    setRotationBlocks(std::move(rotations));
  }

  const Model& inner() const { return *inner_; }
  const ColoredNoise& coloredNoise() const { return noise_; }
  std::string name() const override { return inner_->name(); }

  // The error states' own step φe is linear, h adds e: affine where the inner model is.
  bool processIsAffine() const override { return inner_->processIsAffine(); }
  bool measurementIsAffine(int channel) const override { return inner_->measurementIsAffine(channel); }

  Eigen::VectorXd f(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, const Eigen::VectorXd& u, double dt,
                    Eigen::MatrixXd* J_f_xc, Eigen::MatrixXd* J_f_xb) const override {
    const double phi = std::exp(-dt / noise_.tau);
    Eigen::MatrixXd J_inner;
    Eigen::VectorXd out(dims().nc);
    out.head(a_.inner_nc) = inner_->f(xc.head(a_.inner_nc), xb, u, dt, J_f_xc ? &J_inner : nullptr, J_f_xb);
    out.tail(a_.count) = phi * xc.tail(a_.count);
    if (J_f_xc) *J_f_xc = blockDiagonal(J_inner, a_.count, phi);
    if (J_f_xb) J_f_xb->conservativeResizeLike(Eigen::MatrixXd::Zero(dims().nc, dims().nb));
    return out;
  }

  Eigen::VectorXd h(const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                    Eigen::MatrixXd* J_h_xb) const override {
    return h(0, xc, xb, J_h_xc, J_h_xb);
  }
  Eigen::VectorXd h(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::MatrixXd* J_h_xc,
                    Eigen::MatrixXd* J_h_xb) const override {
    Eigen::VectorXd out;
    hInto(channel, xc, xb, out, J_h_xc, J_h_xb);
    return out;
  }
  void hInto(int channel, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb, Eigen::VectorXd& out,
             Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const override {
    withErrors(channel, xc, out, J_h_xc, [&](const Eigen::VectorXd& inner_xc, Eigen::MatrixXd* J_inner) {
      inner_->hInto(channel, inner_xc, xb, out, J_inner, J_h_xb);
    });
  }
  void hRegressedInto(int channel, const Eigen::VectorXd& known, const Eigen::VectorXd& xc, const Eigen::VectorXd& xb,
                      Eigen::VectorXd& out, Eigen::MatrixXd* J_h_xc, Eigen::MatrixXd* J_h_xb) const override {
    withErrors(channel, xc, out, J_h_xc, [&](const Eigen::VectorXd& inner_xc, Eigen::MatrixXd* J_inner) {
      inner_->hRegressedInto(channel, known, inner_xc, xb, out, J_inner, J_h_xb);
    });
  }

  Eigen::MatrixXd processNoise(double dt) const override {
    return blockDiagonal(inner_->processNoise(dt), a_.count, driveVariance(noise_, dt));
  }
  Eigen::MatrixXd processNoiseOf(double dt, const Eigen::VectorXd& u) const override {
    return blockDiagonal(inner_->processNoiseOf(dt, u), a_.count, driveVariance(noise_, dt));
  }
  bool processNoiseDependsOnInput() const override { return inner_->processNoiseDependsOnInput(); }
  int readingsPerStep() const override { return inner_->readingsPerStep(); }

  std::vector<Eigen::Vector2d> landmarks() const override { return inner_->landmarks(); }
  std::vector<Eigen::Vector2d> bodyPoints(const Eigen::VectorXd& xc) const override {
    return inner_->bodyPoints(xc.head(a_.inner_nc));
  }
  std::vector<std::string> bodyPointNames() const override { return inner_->bodyPointNames(); }
  std::optional<Eigen::Vector3d> localPosition(double lat, double lon, double height) const override {
    return inner_->localPosition(lat, lon, height);
  }
  // The inner model's report, then the error states as they are.
  std::vector<std::string> reportNames() const override {
    std::vector<std::string> names = inner_->reportNames();
    const auto& state = this->names().state;
    names.insert(names.end(), state.begin() + a_.inner_nc, state.end());
    return names;
  }
  void report(const Eigen::VectorXd& mean, const Eigen::MatrixXd& covariance, Eigen::VectorXd& value,
              Eigen::VectorXd& sd) const override {
    const int n = a_.inner_nc, nb = dims().nb, m = a_.count;
    std::vector<int> inner(static_cast<std::size_t>(n + nb));
    for (int i = 0; i < n + nb; ++i) inner[static_cast<std::size_t>(i)] = i < n ? i : i + m;
    Eigen::VectorXd v, s;
    inner_->report(mean(inner), covariance(inner, inner), v, s);
    value.resize(v.size() + m), sd.resize(s.size() + m);
    value << v, mean.segment(n, m);
    sd << s, covariance.diagonal().segment(n, m).cwiseSqrt();
  }
  std::vector<std::string> referenceColumns() const override { return inner_->referenceColumns(); }
  Eigen::VectorXd referenceConstants(const Eigen::MatrixXd& rows, const Truth& truth) const override {
    return inner_->referenceConstants(rows, innerTruth(truth));
  }
  Gaussian comparableConstants(const Gaussian& xb, const Truth& truth) const override {
    return inner_->comparableConstants(xb, innerTruth(truth));
  }

 private:
  // y = h_inner(x_c, x_b) + e_channel: J_h_e = I on the channel's own errors
  // (innerH(inner x_c, J on it) writes h_inner into out).
  template <class InnerH>
  void withErrors(int channel, const Eigen::VectorXd& xc, Eigen::VectorXd& out, Eigen::MatrixXd* J_h_xc,
                  InnerH innerH) const {
    const int dim = this->channel(channel).dim();  // range check: throws, naming the channels
    Eigen::MatrixXd J_inner;
    innerH(xc.head(a_.inner_nc), J_h_xc ? &J_inner : nullptr);
    const int o = a_.offset[static_cast<std::size_t>(channel)];
    if (o >= 0) out += xc.segment(o, dim);
    if (!J_h_xc) return;
    J_h_xc->setZero(dim, dims().nc);
    J_h_xc->leftCols(a_.inner_nc) = J_inner;
    if (o >= 0) J_h_xc->block(0, o, dim, dim).setIdentity();
  }

  // The truth in the inner model's stacked components (error states dropped).
  Truth innerTruth(const Truth& truth) const {
    if (truth.components.empty() || a_.count == 0) return truth;
    Truth out = truth;
    out.components.clear();
    std::vector<Eigen::Index> keep;
    for (std::size_t i = 0; i < truth.components.size(); ++i) {
      const int k = truth.components[i];
      if (k >= a_.inner_nc && k < a_.inner_nc + a_.count) continue;
      keep.push_back(static_cast<Eigen::Index>(i));
      out.components.push_back(k < a_.inner_nc ? k : k - a_.count);
    }
    for (auto& row : out.states) row = Eigen::VectorXd(row(keep));
    return out;
  }

  std::unique_ptr<Model> inner_;
  ColoredNoise noise_;
  Augmentation a_;
};

}  // namespace

std::vector<ParamSpec> coloredNoiseParams() {
  using namespace param;
  return {names("colored_noise", "channels",
                "channels whose noise has a first-order Gauss–Markov part (their names, or all; none: white noise)"),
          learnable(real("colored_noise", "tau", "correlation time of that part (s)")),
          learnable(real("colored_noise", "sd", "stationary σ of that part, in each channel's unit"))};
}

ColoredNoise readColoredNoise(const ParamSource& in) {
  ColoredNoise c;
  if (!in.has("colored_noise", "channels")) return c;
  c.channels = in.names("colored_noise", "channels");
  c.tau = in.real("colored_noise", "tau", c.tau);
  c.sd = in.real("colored_noise", "sd", c.sd);
  for (auto [key, value] : {std::pair{"tau", c.tau}, {"sd", c.sd}})
    if (!(value > 0) || !std::isfinite(value))
      throw InputError(in.where("colored_noise", key) + ": must be > 0, got " + std::to_string(value));
  return c;
}

void writeColoredNoise(const ColoredNoise& noise, ParamSink& out) {
  if (!noise.enabled()) return;
  out.names("colored_noise", "channels", noise.channels);
  out.real("colored_noise", "tau", noise.tau);
  out.real("colored_noise", "sd", noise.sd);
}

std::unique_ptr<Model> withColoredNoise(std::unique_ptr<Model> inner, const ColoredNoise& noise) {
  if (!noise.enabled()) return inner;
  if (coloredNoiseOf(*inner))
    throw InvalidArgument("withColoredNoise: model '" + inner->name() + "' has coloured noise already");
  const Augmentation a = layOut(*inner, noise);
  return std::make_unique<ColoredNoiseModel>(std::move(inner), noise, a);
}

const Model& withoutColoredNoise(const Model& model) {
  const auto* c = dynamic_cast<const ColoredNoiseModel*>(&model);
  return c ? c->inner() : model;
}

const ColoredNoise* coloredNoiseOf(const Model& model) {
  const auto* c = dynamic_cast<const ColoredNoiseModel*>(&model);
  return c ? &c->coloredNoise() : nullptr;
}

}  // namespace gssm
