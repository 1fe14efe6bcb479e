#pragma once
// The UTF-8 byte-order mark (EF BB BF) that spreadsheets and some editors
// put at the start of a text file: the CSV and INI readers skip it.
#include <cstddef>
#include <string>

namespace gssm::io {

/// 3 when `text` starts with the UTF-8 byte-order mark, else 0.
inline std::size_t byteOrderMarkLength(const std::string& text) {
  return text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
}

}  // namespace gssm::io
