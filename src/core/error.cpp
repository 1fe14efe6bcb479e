#include "gssm/core/error.h"

#include <cstdint>
#include <cstdio>

namespace gssm {

namespace {
// Code points that print as nothing or as a plain space: controls, format
// characters (zero-width, direction marks, the byte-order mark), and the
// spaces other than U+0020: an error quoting them would look wrong for no
// visible reason.
bool invisible(std::uint32_t c) {
  if (c == '\t' || c == '\n') return false;
  if (c < 0x20 || (c >= 0x7F && c <= 0xA0) || c == 0xAD || c == 0x34F || c == 0x61C) return true;
  if (c == 0x115F || c == 0x1160 || c == 0x17B4 || c == 0x17B5 || c == 0x180E) return true;
  if ((c >= 0x2000 && c <= 0x200F) || (c >= 0x2028 && c <= 0x202F) || (c >= 0x205F && c <= 0x206F)) return true;
  return c == 0x3000 || c == 0x3164 || c == 0xFEFF || c == 0xFFA0 || (c >= 0xFFF9 && c <= 0xFFFB);
}

// Decodes one UTF-8 sequence at text[i]; its length, 0 if malformed.
std::size_t decode(const std::string& text, std::size_t i, std::uint32_t& c) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char b = byte(i);
  const std::size_t n = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : (b >> 3) == 0x1E ? 4 : 0;
  if (n == 0 || i + n > text.size()) return 0;
  c = n == 1 ? b : b & (0x7F >> n);
  for (std::size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    c = (c << 6) | (byte(i + k) & 0x3F);
  }
  const std::uint32_t least[] = {0, 0, 0x80, 0x800, 0x10000};
  const bool surrogate = c >= 0xD800 && c <= 0xDFFF;
  return c >= least[n] && c <= 0x10FFFF && !surrogate ? n : 0;  // no overlong forms
}
}  // namespace

std::string showInvisible(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  char code[16];
  for (std::size_t i = 0; i < text.size();) {
    std::uint32_t c = 0;
    const std::size_t n = decode(text, i, c);
    if (n == 0) {
      std::snprintf(code, sizeof code, "<0x%02X>", static_cast<unsigned char>(text[i]));
      out += code;
      ++i;
    } else if (invisible(c)) {
      std::snprintf(code, sizeof code, "<U+%04X>", static_cast<unsigned>(c));
      out += code;
      i += n;
    } else {
      out.append(text, i, n);
      i += n;
    }
  }
  return out;
}

}  // namespace gssm
