#include "gssm/io/rtklib_pos.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/io/append_file.h"
#include "gssm/io/number_text.h"
#include "io/byte_order_mark.h"
#include "io/text_file.h"

namespace gssm::io {

namespace {
constexpr double kSecondsPerDay = 86400.0;

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
long daysFromCivil(long y, long m, long d) {
  y -= m <= 2;
  const long era = (y >= 0 ? y : y - 399) / 400;
  const long yoe = y - era * 400;
  const long doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  return era * 146097 + yoe * 365 + yoe / 4 - yoe / 100 + doy - 719468;
}
const long kGpsEpochDays = daysFromCivil(1980, 1, 6);

struct Token {
  std::string text;
  int column;  // 1-based field number on its line
};

std::vector<Token> fields(const std::string& line) {
  std::vector<Token> out;
  std::istringstream ss(line);
  for (std::string t; ss >> t;) out.push_back({t, static_cast<int>(out.size()) + 1});
  return out;
}

// Where each column the reader uses sits among a data line's fields (−1: absent).
struct Layout {
  int lat = -1, lon = -1, height = -1, q = -1, ns = -1, sd[6] = {-1, -1, -1, -1, -1, -1}, age = -1, ratio = -1;
  int vel[3] = {-1, -1, -1}, sdv[6] = {-1, -1, -1, -1, -1, -1};
  std::size_t fields = 0;  // the time's two fields and every named column
};

[[noreturn]] void fail(const std::string& where, const std::string& what) { throw InputError(where + ": " + what); }

// The layout from the column header (its fields after '%'); refuses what gssm does not read.
Layout layoutOf(const std::vector<Token>& head, const std::string& where) {
  const std::string time = head.empty() ? "" : head[0].text;
  if (time == "UTC" || time == "JST")
    fail(where, "times are " + time + "; gssm reads GPST times (RTKLIB output option 'Time Format': ww ssss GPST or "
                "hh:mm:ss GPST)");
  if (time != "GPST") fail(where, "expected the column header '%  GPST latitude(deg) longitude(deg) height(m) ...'");
  Layout L;
  const std::vector<std::string> sd{"sdn(m)", "sde(m)", "sdu(m)", "sdne(m)", "sdeu(m)", "sdun(m)"};
  const std::vector<std::string> vel{"vn(m/s)", "ve(m/s)", "vu(m/s)"};
  const std::vector<std::string> sdv{"sdvn", "sdve", "sdvu", "sdvne", "sdveu", "sdvun"};
  for (std::size_t i = 1; i < head.size(); ++i) {
    const std::string& n = head[i].text;
    const int at = static_cast<int>(i) + 1;  // the time takes two fields on a data line
    const char* refused = n == "x-ecef(m)"                   ? "an ECEF x/y/z solution"
                          : n == "e-baseline(m)"               ? "an east/north/up baseline solution"
                          : n.rfind("latitude(d'", 0) == 0     ? "latitude in degrees-minutes-seconds"
                                                               : nullptr;
    if (refused)
      fail(where, "column '" + n + "': " + refused + "; gssm reads latitude/longitude/height in degrees (RTKLIB "
                  "output options 'Solution Format': Lat/Lon/Height, 'Lat/Lon Format': ddd.ddddddd)");
    if (n == "latitude(deg)") L.lat = at;
    if (n == "longitude(deg)") L.lon = at;
    if (n == "height(m)") L.height = at;
    if (n == "Q") L.q = at;
    if (n == "ns") L.ns = at;
    if (n == "age(s)") L.age = at;
    if (n == "ratio") L.ratio = at;
    for (int k = 0; k < 6; ++k) {
      if (n == sd[static_cast<std::size_t>(k)]) L.sd[k] = at;
      if (n == sdv[static_cast<std::size_t>(k)]) L.sdv[k] = at;
    }
    for (int k = 0; k < 3; ++k)
      if (n == vel[static_cast<std::size_t>(k)]) L.vel[k] = at;
  }
  L.fields = head.size() + 1;
  const std::pair<int, const char*> required[] = {{L.lat, "latitude(deg)"}, {L.lon, "longitude(deg)"},
                                                   {L.height, "height(m)"},   {L.q, "Q"},
                                                   {L.ns, "ns"},              {L.sd[0], "sdn(m)"},
                                                   {L.sd[1], "sde(m)"},       {L.sd[2], "sdu(m)"}};
  for (const auto& [col, name] : required)
    if (col < 0) fail(where, std::string("the column header has no '") + name + "'");
  return L;
}

// A field as a finite number, or an error naming its line, column and name.
double number(const std::vector<Token>& f, int index, const std::string& where, const char* name) {
  const Token& tok = f[static_cast<std::size_t>(index)];
  double v = 0;
  if (!parseDouble(tok.text.data(), tok.text.data() + tok.text.size(), v) || !std::isfinite(v))
    fail(where + ":" + std::to_string(tok.column), std::string(name) + " '" + tok.text + "' is not a finite number");
  return v;
}

// The time of a data line: "YYYY/MM/DD HH:MM:SS.sss" or "week seconds".
double timeOf(const std::vector<Token>& f, const std::string& where) {
  const std::string& a = f[0].text;
  const std::string& b = f[1].text;
  if (a.find('/') == std::string::npos) {
    const double week = number(f, 0, where, "GPS week"), tow = number(f, 1, where, "GPS seconds of week");
    if (week < 0 || week > 10000 || week != std::floor(week) || tow < 0 || tow >= 7 * kSecondsPerDay)
      fail(where + ":1", "GPS week/seconds '" + a + " " + b + "' out of range");
    return week * 7 * kSecondsPerDay + tow;
  }
  int y, mo, d, h, mi, used = 0;
  double s;
  char tail;
  if (std::sscanf(a.c_str(), "%d/%d/%d%n", &y, &mo, &d, &used) != 3 || used != static_cast<int>(a.size()) ||
      y < 1980 || y > 2200 || mo < 1 || mo > 12 || d < 1 || d > 31)
    fail(where + ":1", "date '" + a + "': expected YYYY/MM/DD (GPS time begins 1980/01/06)");
  if (std::sscanf(b.c_str(), "%d:%d:%lf%c", &h, &mi, &s, &tail) != 3 || h < 0 || h > 23 || mi < 0 || mi > 59 ||
      !(s >= 0 && s < 61))
    fail(where + ":2", "time '" + b + "': expected HH:MM:SS.sss");
  return gpsSeconds(y, mo, d, h, mi, s);
}

// RTKLIB's signed square root of a covariance term back to the term.
double fromSignedRoot(double r) { return r < 0 ? -r * r : r * r; }

Eigen::Matrix3d covarianceOf(const std::vector<Token>& f, const int (&col)[6], const std::string& where,
                             const char* what) {
  double v[6] = {0, 0, 0, 0, 0, 0};
  for (int k = 0; k < 6; ++k)
    if (col[k] >= 0) v[k] = number(f, col[k], where, what);
  for (int k = 0; k < 3; ++k)
    if (v[k] < 0) fail(where + ":" + std::to_string(col[k] + 1), std::string(what) + " standard deviation is negative");
  Eigen::Matrix3d C;
  C << v[0] * v[0], fromSignedRoot(v[3]), fromSignedRoot(v[5]),  // n: ne, un
      fromSignedRoot(v[3]), v[1] * v[1], fromSignedRoot(v[4]),   // e: eu
      fromSignedRoot(v[5]), fromSignedRoot(v[4]), v[2] * v[2];
  return C;
}

GnssFix fixOf(const std::vector<Token>& f, const Layout& L, const std::string& where) {
  GnssFix x;
  x.t = timeOf(f, where);
  x.lat_deg = number(f, L.lat, where, "latitude");
  x.lon_deg = number(f, L.lon, where, "longitude");
  x.height = number(f, L.height, where, "height");
  if (std::abs(x.lat_deg) > 90 || std::abs(x.lon_deg) > 180)
    fail(where + ":" + std::to_string(L.lat + 1), "latitude/longitude out of range");
  const double q = number(f, L.q, where, "Q"), ns = number(f, L.ns, where, "ns");
  if (q < 1 || q > 6 || q != std::floor(q)) fail(where + ":" + std::to_string(L.q + 1), "Q must be 1-6 (RTKLIB's solution status)");
  if (ns < 0 || ns > 1000 || ns != std::floor(ns))
    fail(where + ":" + std::to_string(L.ns + 1), "ns must be a count of satellites");
  x.quality = static_cast<int>(q);
  x.satellites = static_cast<int>(ns);
  x.cov_neu = covarianceOf(f, L.sd, where, "position");
  if (L.age >= 0) x.age = number(f, L.age, where, "age");
  if (L.ratio >= 0) x.ratio = number(f, L.ratio, where, "ratio");
  if (L.vel[0] >= 0 && L.vel[1] >= 0 && L.vel[2] >= 0) {
    x.vel_neu = Eigen::Vector3d(number(f, L.vel[0], where, "vn"), number(f, L.vel[1], where, "ve"),
                                number(f, L.vel[2], where, "vu"));
    x.vel_cov_neu = covarianceOf(f, L.sdv, where, "velocity");
  }
  return x;
}
}  // namespace

double gpsSeconds(int year, int month, int day, int hour, int minute, double second) {
  return static_cast<double>(daysFromCivil(year, month, day) - kGpsEpochDays) * kSecondsPerDay + hour * 3600.0 +
         minute * 60.0 + second;
}

std::string gpstCalendar(double t) {
  // Rounded to the millisecond first, so that 59.9996 s carries into the minute.
  const long long ms = std::llround(t * 1000.0);
  long long days = ms / 86400000LL, rem = ms % 86400000LL;
  if (rem < 0) rem += 86400000LL, --days;
  // civil_from_days (H. Hinnant).
  const long z = static_cast<long>(days) + kGpsEpochDays + 719468;
  const long era = (z >= 0 ? z : z - 146096) / 146097, doe = z - era * 146097;
  const long yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365, doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const long mp = (5 * doy + 2) / 153, d = doy - (153 * mp + 2) / 5 + 1, m = mp < 10 ? mp + 3 : mp - 9;
  const long y = yoe + era * 400 + (m <= 2);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d/%02d/%02d %02d:%02d:%06.3f", static_cast<int>(y), static_cast<int>(m),
                static_cast<int>(d), static_cast<int>(rem / 3600000), static_cast<int>(rem / 60000 % 60),
                static_cast<double>(rem % 60000) / 1000.0);
  return buf;
}

GnssSolution parseRtklibPos(const std::string& text, const std::string& source) {
  GnssSolution out;
  out.source = source;
  std::istringstream in(text.substr(byteOrderMarkLength(text)));
  std::optional<Layout> layout;
  std::vector<Token> head;
  int lineno = 0;
  for (std::string line; std::getline(in, line);) {
    ++lineno;
    const std::string where = source + ":" + std::to_string(lineno);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    if (line[0] == '%') {  // a comment; the last before the data names the columns
      if (!layout) head = fields(line.substr(1));
      continue;
    }
    if (!layout) layout = layoutOf(head, where + " (the header before it)");
    const std::vector<Token> f = fields(line);
    if (f.size() != layout->fields)
      fail(where, std::to_string(f.size()) + " fields, the column header has " + std::to_string(layout->fields) +
                      " (the time counts two)");
    GnssFix x = fixOf(f, *layout, where);
    x.line = lineno;
    if (!out.fixes.empty() && !(x.t > out.fixes.back().t))
      fail(where + ":1", "time " + gpstCalendar(x.t) + " is not after the line before's (" +
                             gpstCalendar(out.fixes.back().t) + ", line " + std::to_string(out.fixes.back().line) + ")");
    out.has_velocity = x.vel_neu.has_value();
    out.fixes.push_back(std::move(x));
  }
  if (out.fixes.empty()) fail(source, "no solution lines (expected RTKLIB's .pos: '%' header lines, then one epoch a line)");
  return out;
}

GnssSolution readRtklibPos(const std::string& path) { return parseRtklibPos(readTextFile(path), path); }

void writeRtklibPos(const std::string& path, const GnssSolution& solution, const std::string& program) {
  std::string out = "% program   : " + program + "\n% pos mode  : smoothed GSSM solution (" + solution.source +
                    ")\n%\n%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)"
                    "   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio";
  if (solution.has_velocity) out += "    vn(m/s)    ve(m/s)    vu(m/s)      sdvn     sdve     sdvu    sdvne    sdveu    sdvun";
  out += "\n";
  auto root = [](double c) { return c < 0 ? -std::sqrt(-c) : std::sqrt(c); };
  char buf[512];
  for (const GnssFix& x : solution.fixes) {
    const Eigen::Matrix3d& C = x.cov_neu;
    std::snprintf(buf, sizeof buf, "%s %14.9f %14.9f %10.4f %3d %3d %8.4f %8.4f %8.4f %8.4f %8.4f %8.4f %6.2f %6.1f",
                  gpstCalendar(x.t).c_str(), x.lat_deg, x.lon_deg, x.height, x.quality, x.satellites,
                  std::sqrt(C(0, 0)), std::sqrt(C(1, 1)), std::sqrt(C(2, 2)), root(C(0, 1)), root(C(1, 2)),
                  root(C(2, 0)), x.age, x.ratio);
    out += buf;
    if (solution.has_velocity) {
      const Eigen::Vector3d v = x.vel_neu.value_or(Eigen::Vector3d::Zero());
      const Eigen::Matrix3d& V = x.vel_cov_neu;
      std::snprintf(buf, sizeof buf, " %10.5f %10.5f %10.5f %9.5f %8.5f %8.5f %8.5f %8.5f %8.5f", v.x(), v.y(), v.z(),
                    std::sqrt(V(0, 0)), std::sqrt(V(1, 1)), std::sqrt(V(2, 2)), root(V(0, 1)), root(V(1, 2)),
                    root(V(2, 0)));
      out += buf;
    }
    out += "\n";
  }
  AppendFile file(path);
  file.buffer() = std::move(out);
  file.flush();
}

Eigen::MatrixXd solutionColumns(const GnssSolution& solution, const std::vector<std::string>& columns) {
  static const char* const kKnown = "t, lat, lon, height, q, ns, sdn, sde, sdu, vn, ve, vu";
  auto value = [&](const GnssFix& f, const std::string& c) -> double {
    if (c == "t") return f.t;
    if (c == "lat") return f.lat_deg;
    if (c == "lon") return f.lon_deg;
    if (c == "height") return f.height;
    if (c == "q") return f.quality;
    if (c == "ns") return f.satellites;
    for (int i = 0; i < 3; ++i) {
      if (c == std::string("sd") + "neu"[i]) return std::sqrt(f.cov_neu(i, i));
      if (c == std::string("v") + "neu"[i]) {
        if (!f.vel_neu) throw InputError(solution.source + ": column '" + c + "' asked for, but the file has no velocities");
        return (*f.vel_neu)[i];
      }
    }
    throw InputError(solution.source + ": no column '" + c + "' in an RTKLIB solution (it has " + kKnown + ")");
  };
  Eigen::MatrixXd out(static_cast<Eigen::Index>(solution.fixes.size()), static_cast<Eigen::Index>(columns.size()));
  for (std::size_t r = 0; r < solution.fixes.size(); ++r)
    for (std::size_t c = 0; c < columns.size(); ++c)
      out(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = value(solution.fixes[r], columns[c]);
  return out;
}

}  // namespace gssm::io
