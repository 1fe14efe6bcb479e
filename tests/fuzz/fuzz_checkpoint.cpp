// libFuzzer target: the checkpoint reader must either restore an estimator
// that can be read and stepped, or throw CheckpointError naming the problem;
// never crash. Each input is tried as is (header, size and checksum checks)
// and with its header repaired, so mutations reach the payload parser
// (the Bayes tree validation, factor records, estimator state).
#include <cstdint>
#include <cstring>
#include <string>

#include "core/byte_stream.h"
#include "gssm/checkpoint/checkpoint.h"
#include "gssm/models/radar2d.h"

namespace {
void exercise(const gssm::Model& model, const std::string& bytes) {
  try {
    auto est = gssm::restoreCheckpointBytes(model, bytes, "fuzz.ckpt");
    try {
      (void)est->current();
      (void)est->smoothed(est->step() - 1);
      est->addMeasurement(est->time() + 0.05, Eigen::VectorXd::Constant(1, 1000.0));
      (void)est->current();
      (void)gssm::checkpointBytes(*est);
    } catch (const gssm::Error&) {  // numerical trouble from odd but valid numbers
    }
  } catch (const gssm::CheckpointError&) {
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const gssm::models::Radar2D radar;
  const std::string raw(reinterpret_cast<const char*>(data), size);
  exercise(radar, raw);
  if (size >= 28) {  // repair: signature, version, payload size, checksum
    std::string fixed = raw;
    std::memcpy(&fixed[0], "GSSMCKPT", 8);
    const std::uint32_t version = gssm::kCheckpointVersion;
    std::memcpy(&fixed[8], &version, 4);
    const std::uint64_t n = size - 28;
    std::memcpy(&fixed[12], &n, 8);
    const std::uint64_t h = gssm::internal::fnv1a64(fixed.data() + 28, n);
    std::memcpy(&fixed[20], &h, 8);
    exercise(radar, fixed);
  }
  return 0;
}
