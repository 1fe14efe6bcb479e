#include "factors/factor_io.h"

namespace gssm::internal {

namespace {
// Measurement is the default channel (format v1); MeasurementOnChannel
// names its channel (written only for channels other than 0, so
// single-channel checkpoints keep their v1 bytes).
enum class FactorTag : std::uint8_t {
  Prior = 1, Process = 2, Measurement = 3, LinearGaussian = 4, MeasurementOnChannel = 5, PriorWithAngles = 6,
  ProcessBetween = 7,  // between any two states (an inserted one), since format version 3
  MeasurementWithRegressors = 8  // on a channel whose h reads known values (Measurement::regressors)
};

void requireDim(ByteReader& in, const Model& model, const Key& k, Eigen::Index size, const std::string& what) {
  if (size != variableDim(model, k))
    in.fail(what + ": " + k.toString() + " has size " + std::to_string(size) + " here but " +
            std::to_string(variableDim(model, k)) + " in model '" + model.name() + "'");
}
}  // namespace

void writeFactor(ByteWriter& out, const Factor& f) {
  if (const auto* p = dynamic_cast<const PriorFactor*>(&f)) {
    out.u8(static_cast<std::uint8_t>(p->angles().empty() ? FactorTag::Prior : FactorTag::PriorWithAngles));
    out.key(p->keys()[0]);
    out.gaussian({p->mean(), p->noise().covariance()});
    if (!p->angles().empty()) out.ints(p->angles());
  } else if (const auto* q = dynamic_cast<const ProcessFactor*>(&f)) {
    const bool chain = q->keys()[0].step >= 0 && q->keys()[1].step == q->keys()[0].step + 1;
    out.u8(static_cast<std::uint8_t>(chain ? FactorTag::Process : FactorTag::ProcessBetween));
    if (chain) {
      out.i64(q->keys()[0].step);
    } else {
      out.key(q->keys()[0]);
      out.key(q->keys()[1]);
    }
    out.vec(q->input());
    out.f64(q->dt());
  } else if (const auto* m = dynamic_cast<const MeasurementFactor*>(&f)) {
    const bool known = m->regressors().size() > 0;
    out.u8(static_cast<std::uint8_t>(known               ? FactorTag::MeasurementWithRegressors
                                     : m->channel() == 0 ? FactorTag::Measurement
                                                         : FactorTag::MeasurementOnChannel));
    out.i64(m->keys()[0].step);
    if (known || m->channel() != 0) out.i32(m->channel());
    out.vec(m->measurement());
    out.mat(m->noise().covariance());
    if (known) out.vec(m->regressors());
  } else if (const auto* l = dynamic_cast<const LinearGaussianFactor*>(&f)) {
    out.u8(static_cast<std::uint8_t>(FactorTag::LinearGaussian));
    out.keys(l->keys());
    out.u64(l->A().size());
    for (const auto& a : l->A()) out.mat(a);
    out.vec(l->b());
    out.values(l->linearizationPoint());
  } else {
    throw CheckpointError("checkpoint: factor '" + f.describe() +
                          "' is of a type the checkpoint format does not know; only prior, "
                          "process, measurement and linear Gaussian factors can be saved");
  }
}

FactorPtr readFactor(ByteReader& in, const Model& model, const std::string& what) {
  const std::uint8_t tag = in.u8((what + " type").c_str());
  switch (static_cast<FactorTag>(tag)) {
    case FactorTag::Prior:
    case FactorTag::PriorWithAngles: {
      const Key k = in.key(what + " key");
      const Gaussian g = in.gaussian(what + " prior");
      requireDim(in, model, k, g.mean.size(), what);
      std::vector<int> angles;
      if (static_cast<FactorTag>(tag) == FactorTag::PriorWithAngles) angles = in.ints(what + " angle components");
      for (int a : angles)
        if (a < 0 || a >= g.mean.size()) in.fail(what + ": angle component " + std::to_string(a) + " out of range");
      // Its rotation blocks are the model's in its variable (every prior is on a state or on x_b).
      return std::make_shared<PriorFactor>(k, g, std::move(angles), model.rotationBlocksIn(k.isConstants()));
    }
    case FactorTag::Process: {
      const std::int64_t k = in.i64((what + " step").c_str());
      if (k < 0 || k >= (std::int64_t(1) << 53)) in.fail(what + ": step " + std::to_string(k) + " out of range");
      const Eigen::VectorXd u = in.vec(what + " input");
      const double dt = in.f64(what + " dt");
      return std::make_shared<ProcessFactor>(model, k, u, dt);
    }
    case FactorTag::ProcessBetween: {
      const Key from = in.key(what + " from"), to = in.key(what + " to");
      if (from.isConstants() || to.isConstants()) in.fail(what + ": a process factor joins two states");
      const Eigen::VectorXd u = in.vec(what + " input");
      const double dt = in.f64(what + " dt");
      return std::make_shared<ProcessFactor>(model, from, to, u, dt);
    }
    case FactorTag::Measurement:
    case FactorTag::MeasurementOnChannel:
    case FactorTag::MeasurementWithRegressors: {
      const std::int64_t k = in.i64((what + " step").c_str());
      if (k <= -(std::int64_t(1) << 53) || k >= (std::int64_t(1) << 53))
        in.fail(what + ": step " + std::to_string(k) + " out of range");
      const int channel = static_cast<FactorTag>(tag) == FactorTag::Measurement ? 0 : in.i32((what + " channel").c_str());
      if (channel < 0 || channel >= model.numChannels())
        in.fail(what + ": channel " + std::to_string(channel) + " but model '" + model.name() + "' has " +
                std::to_string(model.numChannels()));
      const Eigen::VectorXd y = in.vec(what + " measurement");
      const Eigen::MatrixXd R = in.mat(what + " noise covariance");
      const int ny = model.channel(channel).dim();
      if (y.size() != ny || R.rows() != ny || R.cols() != ny)
        in.fail(what + ": measurement or noise covariance is not of the channel's size " + std::to_string(ny));
      Eigen::VectorXd known;
      if (static_cast<FactorTag>(tag) == FactorTag::MeasurementWithRegressors) known = in.vec(what + " regressors");
      if (known.size() != model.channel(channel).regressors)
        in.fail(what + ": " + std::to_string(known.size()) + " known values (regressors) but channel '" +
                model.channel(channel).name + "' reads " + std::to_string(model.channel(channel).regressors));
      return std::make_shared<MeasurementFactor>(model, k, y, channel, GaussianNoise(R, what + " noise"), known);
    }
    case FactorTag::LinearGaussian: {
      std::vector<Key> keys = in.keys(what + " keys");
      const std::size_t n = in.count(what + " blocks", 16);
      if (n != keys.size()) in.fail(what + ": " + std::to_string(n) + " blocks for " + std::to_string(keys.size()) + " keys");
      std::vector<Eigen::MatrixXd> A(n);
      for (auto& a : A) a = in.mat(what + " block");
      Eigen::VectorXd b = in.vec(what + " b");
      Values x0 = in.values(what + " linearization point");
      for (std::size_t i = 0; i < keys.size(); ++i) {
        if (!x0.contains(keys[i])) in.fail(what + ": no linearization point for " + keys[i].toString());
        requireDim(in, model, keys[i], x0.at(keys[i]).size(), what);
      }
      return std::make_shared<LinearGaussianFactor>(std::move(keys), std::move(A), std::move(b), std::move(x0));
    }
  }
  in.fail(what + ": unknown factor type " + std::to_string(tag));
}

}  // namespace gssm::internal
