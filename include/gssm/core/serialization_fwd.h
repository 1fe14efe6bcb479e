#pragma once
// Forward declarations of the byte streams with which each stateful class
// (EKF, smoothers, estimators) saves and loads its own fields for
// checkpoints (gssm/checkpoint/checkpoint.h frames the bytes).
namespace gssm::internal {
class ByteWriter;
class ByteReader;
}  // namespace gssm::internal
