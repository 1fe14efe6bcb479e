#pragma once
// The parameters every model has in the same form: the nominal step T, Q, R
// and the priors (docs/DESIGN.md §1, eqs. 1 and 4). Model registrations that
// take their noise in this form declare, read and write it with these.
#include <vector>

#include "gssm/model/model.h"
#include "gssm/model/params.h"

namespace gssm {

struct NoiseKeys {
  bool Q = true;          ///< [model] Q (false: the model builds Q from its own parameters)
  bool constants = true;  ///< [prior] constants_mean, constants_cov (false: n_b = 0)
};

/// [model] T, Q, R and [prior] state_mean, state_cov, constants_mean, constants_cov.
std::vector<ParamSpec> noiseParams(NoiseKeys keys = {});
/// Reads them at the model's sizes; a key the source does not give keeps
/// `fallback`'s value (which must then be of the right size).
ModelNoise readNoise(const ParamSource& in, const ModelDims& dims, const ModelNoise& fallback, NoiseKeys keys = {});
/// Writes the model's T, Q (of one nominal step), R of channel 0 and priors.
void writeNoise(const Model& model, ParamSink& out, NoiseKeys keys = {});

/// [section] `loss` (none | huber | cauchy | tukey) and `loss_scale`
/// (default: RobustLoss::defaultScale of the kind), each after `prefix`,
/// which names the channel a model's loss is for (strapdown_ins: `nhc_`).
std::vector<ParamSpec> lossParams(const std::string& section, const std::string& prefix = "",
                                  const std::string& what = "the measurements");
RobustLoss readLoss(const ParamSource& in, const std::string& section, const std::string& prefix = "");
void writeLoss(const RobustLoss& loss, const std::string& section, ParamSink& out, const std::string& prefix = "");

}  // namespace gssm
