#include "gssm/checkpoint/checkpoint.h"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/byte_stream.h"
#include "gssm/model/registry.h"

namespace gssm {

namespace {
constexpr char kMagic[8] = {'G', 'S', 'S', 'M', 'C', 'K', 'P', 'T'};
constexpr std::size_t kHeaderBytes = 8 + 4 + 8 + 8;

// What identifies a model: name, dimensions, and a hash of its noise and
// priors, so a checkpoint is not continued on a different model by mistake.
void writeModelIdentity(internal::ByteWriter& out, const Model& m) {
  out.str(m.name());
  out.i32(m.dims().nc);
  out.i32(m.dims().nb);
  out.i32(m.dims().nu);
  out.i32(m.dims().ny);
  internal::ByteWriter params;
  params.f64(m.nominalStep());
  params.mat(m.processNoise(m.nominalStep()));
  params.mat(m.measurementNoise());
  params.gaussian(m.priorState());
  params.gaussian(m.priorConstants());
  out.u64(internal::fnv1a64(params.bytes().data(), params.bytes().size()));
}

// The checkpoint's model tag names m's type: the same name, or an older
// name the type still answers to ("radar2d" for radar_2d).
bool sameModelType(const std::string& tag, const Model& m) {
  if (tag == m.name()) return true;
  const ModelType* t = findModelType(tag);
  return t && t == findModelType(m.name());
}

void checkModelIdentity(internal::ByteReader& in, const Model& m, CheckpointInfo& info) {
  info.model = in.str("model name");
  int dims[4];
  for (int& d : dims) d = in.i32("model dimensions");
  const std::uint64_t fingerprint = in.u64("model parameter fingerprint");
  internal::ByteWriter mine;
  writeModelIdentity(mine, m);
  const ModelDims& d = m.dims();
  std::ostringstream os;
  if (!sameModelType(info.model, m) || dims[0] != d.nc || dims[1] != d.nb || dims[2] != d.nu || dims[3] != d.ny) {
    os << "written by model '" << info.model << "' (n_c " << dims[0] << ", n_b " << dims[1] << ", n_u "
       << dims[2] << ", n_y " << dims[3] << "), cannot continue on model '" << m.name() << "' (n_c " << d.nc
       << ", n_b " << d.nb << ", n_u " << d.nu << ", n_y " << d.ny << ")";
    in.fail(os.str());
  }
  std::uint64_t expected;
  std::memcpy(&expected, mine.bytes().data() + mine.bytes().size() - sizeof expected, sizeof expected);
  if (fingerprint != expected)
    in.fail("written by model '" + info.model +
            "' with other noise or prior parameters (T, Q, R or priors differ); restore with the "
            "configuration that wrote it");
}
}  // namespace

std::string checkpointBytes(const Estimator& estimator, const std::string& user_data) {
  internal::ByteWriter payload;
  writeModelIdentity(payload, estimator.model());
  internal::writeOptions(payload, estimator.options());
  payload.str(user_data);
  estimator.save(payload);
  const std::string& p = payload.bytes();
  internal::ByteWriter header;
  header.u32(kCheckpointVersion);
  header.u64(p.size());
  header.u64(internal::fnv1a64(p.data(), p.size()));
  return std::string(kMagic, sizeof kMagic) + header.bytes() + p;
}

void saveCheckpoint(const Estimator& estimator, const std::string& path, const std::string& user_data) {
  const std::string bytes = checkpointBytes(estimator, user_data);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw CheckpointError("cannot write checkpoint '" + tmp + "'");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) throw CheckpointError("writing checkpoint '" + tmp + "' failed (disk full?)");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw CheckpointError("cannot move checkpoint '" + tmp + "' to '" + path + "'");
}

std::unique_ptr<Estimator> restoreCheckpointBytes(const Model& model, const std::string& bytes,
                                                  const std::string& source, CheckpointInfo* info_out) {
  CheckpointInfo info;
  internal::ByteReader header(bytes, source);
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw CheckpointError(source + ": not a gssm checkpoint (no GSSMCKPT signature)");
  header.u64("signature");
  info.version = header.u32("format version");
  if (info.version < 1 || info.version > kCheckpointVersion)
    throw CheckpointError(source + ": checkpoint format version " + std::to_string(info.version) +
                          ", this build reads versions 1 to " + std::to_string(kCheckpointVersion));
  const std::uint64_t size = header.u64("payload size");
  const std::uint64_t checksum = header.u64("checksum");
  if (bytes.size() - kHeaderBytes != size) {
    std::ostringstream os;
    os << source << ": " << (bytes.size() - kHeaderBytes < size ? "truncated" : "has trailing bytes")
       << ": the header promises " << size << " payload bytes, the file has " << bytes.size() - kHeaderBytes;
    throw CheckpointError(os.str());
  }
  if (internal::fnv1a64(bytes.data() + kHeaderBytes, size) != checksum)
    throw CheckpointError(source + ": corrupted: the payload checksum does not match");

  const std::string payload = bytes.substr(kHeaderBytes);
  internal::ByteReader in(payload, source, kHeaderBytes);
  in.setVersion(info.version);
  std::unique_ptr<Estimator> est;
  try {
    checkModelIdentity(in, model, info);
    const EstimatorOptions options = internal::readOptions(in);
    std::string why;
    if (!options.validate(model, &why)) in.fail("invalid estimator options: " + why);
    info.method = options.method;
    info.user_data = in.str("user data");
    est = makeEstimator(model, options);
    est->load(in);
    if (!in.atEnd()) in.fail("unexpected bytes after the estimator state");
  } catch (const CheckpointError&) {
    throw;
  } catch (const Error& e) {  // a record the constructors reject (bad covariance, sizes)
    std::ostringstream os;
    os << source << ": byte " << in.offset() << ": inconsistent checkpoint: " << e.what();
    throw CheckpointError(os.str());
  }
  info.step = est->step();
  info.time = est->time();
  if (info_out) *info_out = std::move(info);
  return est;
}

std::unique_ptr<Estimator> restoreCheckpoint(const Model& model, const std::string& path,
                                             CheckpointInfo* info) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw CheckpointError("cannot open checkpoint '" + path + "'");
  std::ostringstream ss;
  ss << f.rdbuf();
  return restoreCheckpointBytes(model, ss.str(), path, info);
}

}  // namespace gssm
