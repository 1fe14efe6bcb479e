#include "gssm/model/noise_params.h"

#include "gssm/core/error.h"

namespace gssm {

std::vector<ParamSpec> noiseParams(NoiseKeys keys) {
  std::vector<ParamSpec> p{param::real("model", "T", "nominal step (s)")};
  if (keys.Q)
    p.push_back(param::learnable(param::matrix("model", "Q", "process noise covariance of one nominal step (n_c×n_c)")));
  p.push_back(param::learnable(param::matrix("model", "R", "measurement noise covariance (n_y×n_y)")));
  p.push_back(param::vector("prior", "state_mean", "prior mean of x_c(0)"));
  p.push_back(param::matrix("prior", "state_cov", "prior covariance of x_c(0)"));
  if (keys.constants) {
    p.push_back(param::vector("prior", "constants_mean", "prior mean of x_b"));
    p.push_back(param::matrix("prior", "constants_cov", "prior covariance of x_b"));
  }
  return p;
}

namespace {
Eigen::MatrixXd matrixOr(const ParamSource& in, const char* section, const char* key, Eigen::Index n,
                         const Eigen::MatrixXd& fallback) {
  return in.has(section, key) ? in.matrix(section, key, n, n) : fallback;
}
Eigen::VectorXd vectorOr(const ParamSource& in, const char* section, const char* key, Eigen::Index n,
                         const Eigen::VectorXd& fallback) {
  return in.has(section, key) ? in.vector(section, key, n) : fallback;
}
}  // namespace

ModelNoise readNoise(const ParamSource& in, const ModelDims& d, const ModelNoise& fallback, NoiseKeys keys) {
  ModelNoise n = fallback;
  n.T = in.real("model", "T", fallback.T);
  if (keys.Q) n.Q = matrixOr(in, "model", "Q", d.nc, fallback.Q);
  n.R = matrixOr(in, "model", "R", d.ny, fallback.R);
  n.prior_state.mean = vectorOr(in, "prior", "state_mean", d.nc, fallback.prior_state.mean);
  n.prior_state.covariance = matrixOr(in, "prior", "state_cov", d.nc, fallback.prior_state.covariance);
  if (keys.constants) {
    n.prior_constants.mean = vectorOr(in, "prior", "constants_mean", d.nb, fallback.prior_constants.mean);
    n.prior_constants.covariance =
        matrixOr(in, "prior", "constants_cov", d.nb, fallback.prior_constants.covariance);
  }
  return n;
}

void writeNoise(const Model& model, ParamSink& out, NoiseKeys keys) {
  out.real("model", "T", model.nominalStep());
  if (keys.Q) out.matrix("model", "Q", model.noise().Q);
  out.matrix("model", "R", model.noise().R);
  out.vector("prior", "state_mean", model.priorState().mean);
  out.matrix("prior", "state_cov", model.priorState().covariance);
  if (keys.constants && model.dims().nb > 0) {
    out.vector("prior", "constants_mean", model.priorConstants().mean);
    out.matrix("prior", "constants_cov", model.priorConstants().covariance);
  }
}

std::vector<ParamSpec> lossParams(const std::string& section, const std::string& prefix, const std::string& what) {
  return {param::text(section, prefix + "loss", "robust loss on " + what + ": none, huber, cauchy or tukey"),
          param::real(section, prefix + "loss_scale", "where the loss departs from the square (noise sds)")};
}

RobustLoss readLoss(const ParamSource& in, const std::string& section, const std::string& prefix) {
  RobustLoss loss;
  const std::string key = prefix + "loss", scale_key = prefix + "loss_scale";
  const std::string kind = in.text(section, key, "none");
  if (!RobustLoss::named(kind, &loss.kind))
    throw InputError(in.where(section, key) + " = '" + kind + "': expected none, huber, cauchy or tukey");
  loss.scale = in.real(section, scale_key, RobustLoss::defaultScale(loss.kind));
  std::string why;
  if (!loss.validate(&why)) throw InputError(in.where(section, scale_key) + ": " + why);
  return loss;
}

void writeLoss(const RobustLoss& loss, const std::string& section, ParamSink& out, const std::string& prefix) {
  out.text(section, prefix + "loss", RobustLoss::name(loss.kind));
  out.real(section, prefix + "loss_scale", loss.scale);
}

}  // namespace gssm
