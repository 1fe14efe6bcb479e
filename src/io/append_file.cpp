#include "gssm/io/append_file.h"

#include <filesystem>

#include "gssm/core/error.h"

namespace gssm::io {

AppendFile::AppendFile(const std::string& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw InputError(path + ": cannot write the file");
}

AppendFile::AppendFile(const std::string& path, std::uint64_t length) : path_(path), written_(length) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size < length)
    throw InputError(path + ": cannot continue it at byte " + std::to_string(length) + " (" +
                     (ec ? ec.message() : "it has only " + std::to_string(size) + " bytes") + ")");
  std::filesystem::resize_file(path, length, ec);
  if (ec) throw InputError(path + ": cannot cut it at byte " + std::to_string(length) + ": " + ec.message());
  file_ = std::fopen(path.c_str(), "ab");
  if (!file_) throw InputError(path + ": cannot append to the file");
}

AppendFile::~AppendFile() {
  if (!file_) return;
  if (!buffer_.empty()) std::fwrite(buffer_.data(), 1, buffer_.size(), file_);
  std::fclose(file_);
}

void AppendFile::write() {
  if (buffer_.empty()) return;
  if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
    throw InputError(path_ + ": write failed (disk full?)");
  written_ += buffer_.size();
  buffer_.clear();
}

std::uint64_t AppendFile::flush() {
  write();
  if (std::fflush(file_) != 0) throw InputError(path_ + ": write failed (disk full?)");
  return written_;
}

}  // namespace gssm::io
