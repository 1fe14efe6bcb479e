#pragma once
// Internal: the byte streams of the checkpoint format (docs/DESIGN.md §7). Each stateful class writes and reads its own fields with
// them; the checkpoint layer only frames the bytes. Scalars are written in the machine's native representation
// (little-endian IEEE-754 on every platform we build for), so a value read
// back has the same bits as the one written — what bit-identical continuation
// needs. The reader never reads past its end and never trusts a count it has
// not checked against the bytes left: a truncated or corrupted payload gives
// a CheckpointError naming the byte offset and the field being read.
#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "gssm/core/error.h"
#include "gssm/core/gaussian.h"
#include "gssm/core/key.h"
#include "gssm/core/values.h"

namespace gssm::internal {

class ByteWriter {
 public:
  void u8(std::uint8_t v) { raw(&v, 1); }
  void u32(std::uint32_t v) { raw(&v, sizeof v); }
  void u64(std::uint64_t v) { raw(&v, sizeof v); }
  void i32(std::int32_t v) { raw(&v, sizeof v); }
  void i64(std::int64_t v) { raw(&v, sizeof v); }
  void f64(double v) { raw(&v, sizeof v); }
  void boolean(bool v) { u8(v ? 1 : 0); }
  void str(const std::string& s);
  void key(const Key& k);
  void keys(const std::vector<Key>& ks);
  void ints(const std::vector<int>& v);
  void vec(const Eigen::VectorXd& v);
  void mat(const Eigen::MatrixXd& m);
  void values(const Values& v);
  void gaussian(const Gaussian& g);
  void times(const std::deque<double>& t);
  const std::string& bytes() const { return buf_; }

 private:
  void raw(const void* p, std::size_t n) { buf_.append(static_cast<const char*>(p), n); }
  std::string buf_;
};

class ByteReader {
 public:
  /// `source` names the checkpoint in error messages (a file name).
  ByteReader(const std::string& bytes, std::string source, std::size_t base_offset = 0)
      : data_(bytes.data()), size_(bytes.size()), source_(std::move(source)), base_(base_offset) {}

  std::uint8_t u8(const char* what) { return scalar<std::uint8_t>(what); }
  std::uint32_t u32(const char* what) { return scalar<std::uint32_t>(what); }
  std::uint64_t u64(const char* what) { return scalar<std::uint64_t>(what); }
  std::int32_t i32(const char* what) { return scalar<std::int32_t>(what); }
  std::int64_t i64(const char* what) { return scalar<std::int64_t>(what); }
  /// Finite unless `allow_nonfinite` (e.g. a NaN NIS before any measurement).
  double f64(const std::string& what, bool allow_nonfinite = false);
  bool boolean(const char* what);
  std::string str(const std::string& what);
  Key key(const std::string& what);
  std::vector<Key> keys(const std::string& what);
  std::vector<int> ints(const std::string& what);
  /// A count of elements of at least `min_bytes_each`, checked against the bytes left.
  std::size_t count(const std::string& what, std::size_t min_bytes_each);
  Eigen::VectorXd vec(const std::string& what);
  Eigen::MatrixXd mat(const std::string& what);
  Values values(const std::string& what);
  Gaussian gaussian(const std::string& what);
  /// Finite time stamps (a count, then each).
  std::deque<double> times(const std::string& what);

  bool atEnd() const { return pos_ == size_; }
  /// The format version of what is being read (records added in a later
  /// version are read only from files of that version on).
  std::uint32_t version() const { return version_; }
  void setVersion(std::uint32_t v) { version_ = v; }
  std::size_t offset() const { return base_ + pos_; }
  /// Throws CheckpointError "source: byte N: what".
  [[noreturn]] void fail(const std::string& what) const;

 private:
  void raw(void* p, std::size_t n, const std::string& what);
  template <class T>
  T scalar(const char* what) {
    T v;
    raw(&v, sizeof v, what);
    return v;
  }
  const char* data_;
  std::size_t size_, pos_ = 0;
  std::string source_;
  std::size_t base_;
  std::uint32_t version_ = ~0u;  // unset: the current format
};

/// Visits one record's field list with a writer or a reader, so the two
/// directions of a record cannot drift apart: a class writes
///   template <class Io> void fields(Io& io, Options& o) { io(o.a, "a"); io(o.b, "b"); }
/// once and calls it with FieldWriter{out} (on a copy) or FieldReader{in}.
struct FieldWriter {
  ByteWriter& out;
  /// The format written: always the newest (fields added later are read only from versions that have them).
  static constexpr std::uint32_t version() { return ~std::uint32_t{0}; }
  void operator()(const double& v, const char*, bool = false) { out.f64(v); }
  void operator()(const int& v, const char*) { out.i32(v); }
  void operator()(const bool& v, const char*) { out.boolean(v); }
  void operator()(const std::size_t& v, const char*) { out.u64(v); }
  void operator()(const std::int64_t& v, const char*) { out.i64(v); }
  void operator()(const std::string& v, const char*) { out.str(v); }
  void operator()(const Eigen::VectorXd& v, const char*) { out.vec(v); }
  template <class Enum>
  void enumeration(const Enum& v, int, const char*) { out.u8(static_cast<std::uint8_t>(v)); }
};

struct FieldReader {
  ByteReader& in;
  std::uint32_t version() const { return in.version(); }
  /// `allow_nonfinite`: ∞ or NaN are legitimate values of this field.
  void operator()(double& v, const char* what, bool allow_nonfinite = false) { v = in.f64(what, allow_nonfinite); }
  void operator()(int& v, const char* what) { v = in.i32(what); }
  void operator()(bool& v, const char* what) { v = in.boolean(what); }
  void operator()(std::size_t& v, const char* what) { v = in.u64(what); }
  void operator()(std::int64_t& v, const char* what) { v = in.i64(what); }
  void operator()(std::string& v, const char* what) { v = in.str(what); }
  void operator()(Eigen::VectorXd& v, const char* what) { v = in.vec(what); }
  template <class Enum>
  void enumeration(Enum& v, int max, const char* what) {
    const std::uint8_t raw = in.u8(what);
    if (raw > max) in.fail(std::string(what) + ": unknown value " + std::to_string(raw));
    v = static_cast<Enum>(raw);
  }
};

/// FNV-1a, 64 bit: the payload checksum. Pass the previous hash as `h` to
/// continue over more bytes.
constexpr std::uint64_t kFnv1a64Basis = 1469598103934665603ull;
std::uint64_t fnv1a64(const char* data, std::size_t n, std::uint64_t h = kFnv1a64Basis);

}  // namespace gssm::internal
