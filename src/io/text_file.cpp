#include "io/text_file.h"

#include <fstream>

#include "gssm/core/error.h"

namespace gssm::io {

std::string readTextFile(const std::string& path, const std::string& what) {
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
