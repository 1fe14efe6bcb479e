#pragma once
// Doubles as text, both ways, fast and exact: the shortest text that reads
// back as the same double (std::to_chars), laid out as printf's "%.Pg" with
// P = max(6, its significant digits) — the format every gssm file has used,
// so files written before and after are byte-identical — and parsing by
// std::from_chars. No locale, no allocation per number.
#include <string>

namespace gssm::io {

/// Appends the shortest round-trip text of v ("nan", "inf", "-inf" when not finite).
void appendDouble(std::string& out, double v);
/// The same as a string.
std::string formatDouble(double v);
/// Parses all of [begin, end) as a double (an optional leading '+' allowed);
/// false when it is not exactly one number.
bool parseDouble(const char* begin, const char* end, double& value);

}  // namespace gssm::io
