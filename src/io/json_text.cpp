#include "gssm/io/json_text.h"

#include <cmath>

#include "gssm/io/number_text.h"

#include <cstdio>

namespace gssm::io {

namespace {
// Length of the valid UTF-8 sequence starting at s[i] (2–4), or 0.
std::size_t utf8Sequence(std::string_view s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = byte(i);
  std::size_t n = c >= 0xF0 && c <= 0xF4 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 && c <= 0xDF ? 2 : 0;
  if (n == 0 || i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k)
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
  // No overlong forms, no surrogates, nothing above U+10FFFF.
  const unsigned char c1 = byte(i + 1);
  if ((c == 0xE0 && c1 < 0xA0) || (c == 0xED && c1 >= 0xA0) || (c == 0xF0 && c1 < 0x90) || (c == 0xF4 && c1 >= 0x90))
    return 0;
  return n;
}

void appendControl(std::string& out, unsigned char c) {
  switch (c) {
    case '\b': out += "\\b"; return;
    case '\f': out += "\\f"; return;
    case '\n': out += "\\n"; return;
    case '\r': out += "\\r"; return;
    case '\t': out += "\\t"; return;
    default: {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    }
  }
}
}  // namespace

std::string jsonQuoted(std::string_view text) {
  std::string out = "\"";
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '"' || c == '\\') {
      out += '\\', out += static_cast<char>(c), ++i;
    } else if (c < 0x20 || c == 0x7F) {
      appendControl(out, c), ++i;
    } else if (c < 0x80) {
      out += static_cast<char>(c), ++i;
    } else if (const std::size_t n = utf8Sequence(text, i)) {
      out.append(text.substr(i, n)), i += n;
    } else {
      out += "\\ufffd", ++i;  // not UTF-8: say so rather than write an invalid file
    }
  }
  return out + "\"";
}

std::string jsonNumber(double v) { return std::isfinite(v) ? formatDouble(v) : "null"; }

}  // namespace gssm::io
