#pragma once
// A file written at its end through a ~1 MB buffer, from scratch or
// continued at a length it had (an output a checkpoint can resume). The
// one place output files are opened, cut and flushed (CsvWriter, RunFiles).
#include <cstdint>
#include <cstdio>
#include <string>

namespace gssm::io {

class AppendFile {
 public:
  /// Creates `path`, replacing it. InputError naming it if that fails.
  explicit AppendFile(const std::string& path);
  /// Continues `path` at byte `length` (what flush() returned then): cuts it
  /// there and appends. InputError if it is missing or shorter.
  AppendFile(const std::string& path, std::uint64_t length);
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;
  ~AppendFile();  ///< writes what is buffered (call flush() to see errors)

  /// The buffer to append to; written out when it passes ~1 MB.
  std::string& buffer() { return buffer_; }
  void maybeWrite() {
    if (buffer_.size() >= (1u << 20)) write();
  }
  /// Hands everything appended so far to the operating system (it survives
  /// the process being killed); returns the file's length in bytes.
  std::uint64_t flush();
  const std::string& path() const { return path_; }

 private:
  void write();
  std::string path_, buffer_;
  std::FILE* file_ = nullptr;
  std::uint64_t written_ = 0;
};

}  // namespace gssm::io
