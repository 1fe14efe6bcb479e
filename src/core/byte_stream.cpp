#include "core/byte_stream.h"

#include <cmath>
#include <cstring>
#include <sstream>

namespace gssm::internal {

namespace {
// Largest dimension of one stored matrix side: far above any GSSM block,
// small enough that rows × cols × 8 cannot overflow.
constexpr std::int64_t kMaxDim = 1 << 20;
// Steps beyond this are corruption (and k + 1 must not overflow).
constexpr std::int64_t kMaxStep = std::int64_t(1) << 53;
}  // namespace

std::uint64_t fnv1a64(const char* data, std::size_t n, std::uint64_t h) {
  for (std::size_t i = 0; i < n; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

// ---- writer -----------------------------------------------------------------------
void ByteWriter::str(const std::string& s) {
  u64(s.size());
  raw(s.data(), s.size());
}
void ByteWriter::key(const Key& k) {
  u8(static_cast<std::uint8_t>(k.kind));
  i64(k.step);
}
void ByteWriter::keys(const std::vector<Key>& ks) {
  u64(ks.size());
  for (const auto& k : ks) key(k);
}
void ByteWriter::ints(const std::vector<int>& v) {
  u64(v.size());
  for (int i : v) i32(i);
}
void ByteWriter::vec(const Eigen::VectorXd& v) {
  u64(static_cast<std::uint64_t>(v.size()));
  raw(v.data(), static_cast<std::size_t>(v.size()) * sizeof(double));
}
void ByteWriter::mat(const Eigen::MatrixXd& m) {
  i64(m.rows());
  i64(m.cols());
  raw(m.data(), static_cast<std::size_t>(m.size()) * sizeof(double));  // column-major
}
void ByteWriter::values(const Values& v) {
  u64(v.size());
  for (const auto& kv : v) {
    key(kv.first);
    vec(kv.second);
  }
}
void ByteWriter::gaussian(const Gaussian& g) {
  vec(g.mean);
  mat(g.covariance);
}

void ByteWriter::times(const std::deque<double>& t) {
  u64(t.size());
  for (double v : t) f64(v);
}

// ---- reader -----------------------------------------------------------------------
void ByteReader::fail(const std::string& what) const {
  std::ostringstream os;
  os << source_ << ": byte " << offset() << ": " << what;
  throw CheckpointError(os.str());
}

void ByteReader::raw(void* p, std::size_t n, const std::string& what) {
  if (n > size_ - pos_) {
    std::ostringstream os;
    os << "truncated while reading " << what << " (needs " << n << " bytes, " << size_ - pos_
       << " left)";
    fail(os.str());
  }
  if (n) std::memcpy(p, data_ + pos_, n);
  pos_ += n;
}

double ByteReader::f64(const std::string& what, bool allow_nonfinite) {
  double v;
  raw(&v, sizeof v, what);
  if (!allow_nonfinite && !std::isfinite(v)) fail(what + " is not finite");
  return v;
}
bool ByteReader::boolean(const char* what) {
  const std::uint8_t v = u8(what);
  if (v > 1) fail(std::string(what) + ": expected a boolean (0 or 1), found " + std::to_string(v));
  return v == 1;
}
std::size_t ByteReader::count(const std::string& what, std::size_t min_bytes_each) {
  const std::uint64_t n = u64(what.c_str());
  const std::size_t left = size_ - pos_;
  if (min_bytes_each > 0 && n > left / min_bytes_each) {
    std::ostringstream os;
    os << what << ": count " << n << " cannot fit in the " << left << " bytes left (corrupted)";
    fail(os.str());
  }
  return static_cast<std::size_t>(n);
}
std::string ByteReader::str(const std::string& what) {
  const std::size_t n = count(what + " (length)", 1);
  std::string s(n, '\0');
  raw(s.data(), n, what);
  return s;
}
Key ByteReader::key(const std::string& what) {
  const std::uint8_t kind = u8(what.c_str());
  const std::int64_t step = i64(what.c_str());
  if (kind > 1) fail(what + ": unknown variable kind " + std::to_string(kind));
  if (kind == 1 && step != 0) fail(what + ": the constants carry step 0, found " + std::to_string(step));
  if (kind == 0 && (step < -kMaxStep || step > kMaxStep)) fail(what + ": step " + std::to_string(step) + " out of range");
  return kind == 1 ? Key::constants() : Key::state(step);
}
std::vector<Key> ByteReader::keys(const std::string& what) {
  std::vector<Key> out(count(what + " (count)", 9));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = key(what + "[" + std::to_string(i) + "]");
  return out;
}
std::vector<int> ByteReader::ints(const std::string& what) {
  std::vector<int> out(count(what + " (count)", 4));
  for (auto& v : out) v = i32(what.c_str());
  return out;
}
Eigen::VectorXd ByteReader::vec(const std::string& what) {
  const std::size_t n = count(what + " (size)", sizeof(double));
  Eigen::VectorXd v(static_cast<Eigen::Index>(n));
  raw(v.data(), n * sizeof(double), what);
  if (!v.allFinite()) fail(what + " has a non-finite entry");
  return v;
}
Eigen::MatrixXd ByteReader::mat(const std::string& what) {
  const std::int64_t r = i64(what.c_str()), c = i64(what.c_str());
  if (r < 0 || c < 0 || r > kMaxDim || c > kMaxDim)
    fail(what + ": impossible size " + std::to_string(r) + " x " + std::to_string(c));
  const std::size_t bytes = static_cast<std::size_t>(r) * static_cast<std::size_t>(c) * sizeof(double);
  if (bytes > size_ - pos_)
    fail("truncated while reading " + what + " (" + std::to_string(r) + " x " + std::to_string(c) + ")");
  Eigen::MatrixXd m(r, c);
  raw(m.data(), bytes, what);
  if (!m.allFinite()) fail(what + " has a non-finite entry");
  return m;
}
Values ByteReader::values(const std::string& what) {
  Values out;
  const std::size_t n = count(what + " (count)", 17);
  for (std::size_t i = 0; i < n; ++i) {
    const Key k = key(what + " key");
    if (out.contains(k)) fail(what + ": " + k.toString() + " appears twice");
    out.insert(k, vec(what + " " + k.toString()));
  }
  return out;
}
Gaussian ByteReader::gaussian(const std::string& what) {
  Gaussian g;
  g.mean = vec(what + " mean");
  g.covariance = mat(what + " covariance");
  if (g.covariance.rows() != g.mean.size() || g.covariance.cols() != g.mean.size())
    fail(what + ": covariance is " + std::to_string(g.covariance.rows()) + " x " +
         std::to_string(g.covariance.cols()) + " for a mean of size " + std::to_string(g.mean.size()));
  return g;
}

std::deque<double> ByteReader::times(const std::string& what) {
  std::deque<double> t(count(what + " (count)", sizeof(double)));
  for (double& v : t) v = f64(what);
  return t;
}

}  // namespace gssm::internal
