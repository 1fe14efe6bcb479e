#pragma once
// Internal: checkpoint records of the factors gssm's estimators create
// (prior, process, measurement, linear Gaussian). A factor of another type
// (a user's own) cannot be saved: writeFactor throws CheckpointError naming it.
#include "core/byte_stream.h"
#include "gssm/factors/factors.h"

namespace gssm::internal {

void writeFactor(ByteWriter& out, const Factor& factor);
/// Reads one factor record; process and measurement factors are rebuilt on
/// `model`, and every dimension is checked against it.
FactorPtr readFactor(ByteReader& in, const Model& model, const std::string& what);

}  // namespace gssm::internal
