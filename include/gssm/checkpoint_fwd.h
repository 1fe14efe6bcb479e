#pragma once
// Forward declarations for the classes whose private state checkpoints
// (checkpoint.h) read and write: they befriend internal::CheckpointAccess.
namespace gssm::internal {
struct CheckpointAccess;
class ByteWriter;
class ByteReader;
}  // namespace gssm::internal
