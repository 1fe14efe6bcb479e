#include "factors/factor_io.h"

namespace gssm::internal {

namespace {
enum class FactorTag : std::uint8_t { Prior = 1, Process = 2, Measurement = 3, LinearGaussian = 4 };

void requireDim(ByteReader& in, const Model& model, const Key& k, Eigen::Index size, const std::string& what) {
  if (size != variableDim(model, k))
    in.fail(what + ": " + k.toString() + " has size " + std::to_string(size) + " here but " +
            std::to_string(variableDim(model, k)) + " in model '" + model.name() + "'");
}
}  // namespace

void writeFactor(ByteWriter& out, const Factor& f) {
  if (const auto* p = dynamic_cast<const PriorFactor*>(&f)) {
    out.u8(static_cast<std::uint8_t>(FactorTag::Prior));
    out.key(p->keys()[0]);
    out.gaussian({p->mean(), p->noise().covariance()});
  } else if (const auto* q = dynamic_cast<const ProcessFactor*>(&f)) {
    out.u8(static_cast<std::uint8_t>(FactorTag::Process));
    out.i64(q->keys()[0].step);
    out.vec(q->input());
    out.f64(q->dt());
  } else if (const auto* m = dynamic_cast<const MeasurementFactor*>(&f)) {
    out.u8(static_cast<std::uint8_t>(FactorTag::Measurement));
    out.i64(m->keys()[0].step);
    out.vec(m->measurement());
    out.mat(m->noise().covariance());
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
    case FactorTag::Prior: {
      const Key k = in.key(what + " key");
      const Gaussian g = in.gaussian(what + " prior");
      requireDim(in, model, k, g.mean.size(), what);
      return std::make_shared<PriorFactor>(k, g);
    }
    case FactorTag::Process: {
      const std::int64_t k = in.i64((what + " step").c_str());
      if (k < 0 || k >= (std::int64_t(1) << 53)) in.fail(what + ": step " + std::to_string(k) + " out of range");
      const Eigen::VectorXd u = in.vec(what + " input");
      const double dt = in.f64(what + " dt");
      return std::make_shared<ProcessFactor>(model, k, u, dt);
    }
    case FactorTag::Measurement: {
      const std::int64_t k = in.i64((what + " step").c_str());
      if (k < 0 || k >= (std::int64_t(1) << 53)) in.fail(what + ": step " + std::to_string(k) + " out of range");
      const Eigen::VectorXd y = in.vec(what + " measurement");
      const Eigen::MatrixXd R = in.mat(what + " noise covariance");
      if (R.rows() != model.dims().ny || R.cols() != model.dims().ny)
        in.fail(what + ": noise covariance is not " + std::to_string(model.dims().ny) + " x " +
                std::to_string(model.dims().ny));
      return std::make_shared<MeasurementFactor>(model, k, y, GaussianNoise(R, what + " noise"));
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
