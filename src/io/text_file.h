#pragma once
// A text file read whole, for the readers that parse a file's text (CSV,
// INI, RTKLIB solutions). InputError naming the path if it cannot be opened
// ("cannot open the <what>") or read.
#include <string>

namespace gssm::io {

std::string readTextFile(const std::string& path, const std::string& what = "file");

}  // namespace gssm::io
