#include "gssm/io/number_text.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <system_error>

namespace gssm::io {

void appendDouble(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
    return;
  }
  if (v == 0) {
    out += std::signbit(v) ? "-0" : "0";
    return;
  }
  if (std::abs(v) < std::numeric_limits<double>::min()) {
    // Subnormal: fewer than 16 significant digits, so "%.6g" is not the
    // shortest digits padded with zeros; printf as before (rare).
    for (int prec = 6; prec <= 17; ++prec) {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%.*g", prec, v);
      double back = 0;
      if (parseDouble(buf, buf + std::strlen(buf), back) && back == v) {
        out += buf;
        return;
      }
    }
  }
  // Shortest round-trip digits and exponent: "-d.ddde±XX".
  char sci[32];
  const auto r = std::to_chars(sci, sci + sizeof sci, v, std::chars_format::scientific);
  const char* p = sci;
  const bool negative = *p == '-';
  if (negative) ++p;
  char digits[20];
  int n = 0;
  for (; p < r.ptr && *p != 'e'; ++p)
    if (*p != '.') digits[n++] = *p;
  int x = 0;  // the exponent X (d.ddd × 10^X)
  std::from_chars(p + 1 + (p[1] == '+'), r.ptr, x);
  // printf "%.Pg" with P = max(6, n): scientific when X < -4 or X >= P.
  const int P = n > 6 ? n : 6;
  char text[40];  // at most 1 + 17 + 1 + 5 ("-d.dddde-308") or 1 + 2 + 4 + 17 ("-0.0000ddd")
  char* o = text;
  if (negative) *o++ = '-';
  if (x < -4 || x >= P) {
    *o++ = digits[0];
    if (n > 1) {
      *o++ = '.';
      for (int i = 1; i < n; ++i) *o++ = digits[i];
    }
    *o++ = 'e';
    *o++ = x < 0 ? '-' : '+';
    const int ax = x < 0 ? -x : x;
    if (ax < 10) *o++ = '0';
    o = std::to_chars(o, text + sizeof text, ax).ptr;
  } else if (x >= 0) {
    for (int i = 0; i <= x || i < n; ++i) {
      if (i == x + 1) *o++ = '.';
      *o++ = i < n ? digits[i] : '0';
    }
  } else {
    *o++ = '0';
    *o++ = '.';
    for (int i = 0; i < -x - 1; ++i) *o++ = '0';
    for (int i = 0; i < n; ++i) *o++ = digits[i];
  }
  out.append(text, static_cast<std::size_t>(o - text));
}

std::string formatDouble(double v) {
  std::string s;
  appendDouble(s, v);
  return s;
}

bool parseDouble(const char* begin, const char* end, double& value) {
  if (begin < end && *begin == '+') ++begin;  // strtod took a leading '+'; from_chars does not
  if (begin == end) return false;
  const auto r = std::from_chars(begin, end, value);
  return r.ec == std::errc() && r.ptr == end;
}

}  // namespace gssm::io
