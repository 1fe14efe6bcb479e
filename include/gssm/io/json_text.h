#pragma once
// JSON text for the files gssm writes (metrics.json): strings quoted per
// RFC 8259, whatever bytes they hold.
#include <string>
#include <string_view>

namespace gssm::io {

/// `text` as a JSON string literal: '"' and '\' escaped, every control
/// character (U+0000–U+001F, U+007F) as `\b \f \n \r \t` or `\u00XX`, valid
/// UTF-8 kept as it is, and each byte of invalid UTF-8 as U+FFFD, so the
/// result always parses.
std::string jsonQuoted(std::string_view text);
/// A number in round-trip form; null when not finite (JSON has no NaN).
std::string jsonNumber(double v);

}  // namespace gssm::io
