#include "io/text_file.h"

#include <filesystem>
#include <fstream>

#include "gssm/core/error.h"

namespace gssm::io {

std::string readTextFile(const std::string& path, const std::string& what) {
  // A directory opens as a stream on Linux, and its end offset can be 2^63 − 1.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path + ": is a directory, not the " + what);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the " + what);
  std::string text;
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size > 0) {  // one read into a string of the file's size
    text.resize(static_cast<std::size_t>(size));
    in.seekg(0);
    in.read(text.data(), size);
  }
  if (!in) throw InputError(path + ": read failed");
  return text;
}

}  // namespace gssm::io
