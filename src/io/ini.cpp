#include "gssm/io/ini.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "gssm/core/error.h"
#include "io/byte_order_mark.h"
#include "io/text_file.h"

namespace gssm::io {

namespace {
std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::string stripComment(const std::string& line) {
  std::size_t cut = line.size();
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (line[i] == ';' || line[i] == '#') {
      // ';' inside a matrix literal "[a b; c d]" is a row separator.
      if (line[i] == ';') {
        const auto open = line.rfind('[', i);
        const auto close = line.rfind(']', i);
        if (open != std::string::npos && (close == std::string::npos || close < open)) continue;
      }
      cut = i;
      break;
    }
    if (line[i] == '/' && i + 1 < line.size() && line[i + 1] == '/') {
      cut = i;
      break;
    }
  }
  return line.substr(0, cut);
}

// Parses a full string as a finite double, whatever the C locale says a
// decimal point is (std::from_chars: "0.5" is a half under de_DE too).
bool parseFiniteDouble(const std::string& text, double& out) {
  const std::string t = trim(text);
  return io::parseDouble(t.data(), t.data() + t.size(), out) && std::isfinite(out);
}

// "[1 2; 3 4]" → rows of numbers. Returns false on a bad token.
bool parseRows(const std::string& value, std::vector<std::vector<double>>& rows,
               std::string& bad) {
  std::string v = trim(value);
  if (!v.empty() && v.front() == '[') {
    if (v.back() != ']') {
      bad = "missing ']'";
      return false;
    }
    v = v.substr(1, v.size() - 2);
  }
  rows.clear();
  std::stringstream rs(v);
  std::string row;
  while (std::getline(rs, row, ';')) {
    for (char& c : row)
      if (c == ',') c = ' ';
    std::stringstream ts(row);
    std::vector<double> r;
    std::string tok;
    while (ts >> tok) {
      double d;
      if (!parseFiniteDouble(tok, d)) {
        bad = "'" + tok + "' is not a finite number";
        return false;
      }
      r.push_back(d);
    }
    rows.push_back(std::move(r));
  }
  if (rows.size() == 1 && rows[0].empty()) rows.clear();
  return true;
}
}  // namespace

IniDocument IniDocument::parse(const std::string& text, const std::string& source) {
  IniDocument doc;
  doc.source_ = source;
  std::stringstream ss(text.substr(byteOrderMarkLength(text)));  // an editor's UTF-8 mark is no key text
  std::string raw;
  int lineno = 0;
  Section* current = nullptr;
  while (std::getline(ss, raw)) {
    ++lineno;
    const std::string line = trim(stripComment(raw));
    if (line.empty()) continue;
    if (line.front() == '[') {
      if (line.back() != ']' || line.size() < 3)
        throw InputError(source + ":" + std::to_string(lineno) + ": malformed section header '" +
                         line + "' (expected [Name])");
      const std::string name = trim(line.substr(1, line.size() - 2));
      for (auto& s : doc.sections_)
        if (s.name == name)
          throw InputError(source + ":" + std::to_string(lineno) + ": section [" + name +
                           "] appears twice (first at line " + std::to_string(s.line) + ")");
      doc.sections_.push_back({name, "", {}, lineno});
      current = &doc.sections_.back();
      continue;
    }
    const auto eq = line.find('=');
    if (eq == std::string::npos)
      throw InputError(source + ":" + std::to_string(lineno) + ": expected 'key = value', got '" +
                       line + "'");
    if (!current)
      throw InputError(source + ":" + std::to_string(lineno) + ": key '" +
                       trim(line.substr(0, eq)) + "' before any [Section]");
    const std::string key = trim(line.substr(0, eq));
    if (key.empty())
      throw InputError(source + ":" + std::to_string(lineno) + ": empty key before '='");
    for (const auto& e : current->entries)
      if (e.key == key)
        throw InputError(source + ":" + std::to_string(lineno) + ": key '" + key +
                         "' repeated in [" + current->name + "] (first at line " +
                         std::to_string(e.line) + ")");
    current->entries.push_back({key, trim(line.substr(eq + 1)), lineno});
  }
  return doc;
}

IniDocument IniDocument::load(const std::string& path) {
  return parse(readTextFile(path, "configuration file"), path);
}

bool IniDocument::hasSection(const std::string& section) const {
  for (const auto& s : sections_)
    if (s.name == section) return true;
  return false;
}

const IniDocument::Entry* IniDocument::find(const std::string& section,
                                            const std::string& key) const {
  for (const auto& s : sections_)
    if (s.name == section)
      for (const auto& e : s.entries)
        if (e.key == key) return &e;
  return nullptr;
}

bool IniDocument::has(const std::string& section, const std::string& key) const {
  return find(section, key) != nullptr;
}

const IniDocument::Entry& IniDocument::require(const std::string& section,
                                               const std::string& key) const {
  const Entry* e = find(section, key);
  if (!e)
    throw InputError(source_ + ": missing required key '" + key + "' in section [" + section +
                     "]");
  return *e;
}

int IniDocument::lineOf(const std::string& section, const std::string& key) const {
  const Entry* e = find(section, key);
  return e ? e->line : 0;
}

int IniDocument::lastLineOf(const std::string& section) const {
  for (const auto& s : sections_)
    if (s.name == section) {
      int last = s.line;
      for (const auto& e : s.entries) last = std::max(last, e.line);
      return last;
    }
  return 0;
}

std::string IniDocument::where(const std::string& section, const std::string& key) const {
  const Entry* e = find(section, key);
  return source_ + (e ? ":" + std::to_string(e->line) : std::string()) + ": [" + section + "] " + key;
}

void IniDocument::fail(const std::string& section, const Entry& e,
                       const std::string& expected) const {
  throw InputError(source_ + ":" + std::to_string(e.line) + ": [" + section + "] " + e.key +
                   " = '" + e.value + "': " + expected);
}

std::string IniDocument::getString(const std::string& section, const std::string& key) const {
  return require(section, key).value;
}
std::string IniDocument::getString(const std::string& section, const std::string& key,
                                   const std::string& fallback) const {
  const Entry* e = find(section, key);
  return e ? e->value : fallback;
}

double IniDocument::getDouble(const std::string& section, const std::string& key) const {
  const Entry& e = require(section, key);
  double d;
  if (!parseFiniteDouble(e.value, d)) fail(section, e, "expected a finite number");
  return d;
}
double IniDocument::getDouble(const std::string& section, const std::string& key,
                              double fallback) const {
  return has(section, key) ? getDouble(section, key) : fallback;
}

long long IniDocument::getInt(const std::string& section, const std::string& key) const {
  const Entry& e = require(section, key);
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(e.value.c_str(), &end, 10);
  if (e.value.empty() || end != e.value.c_str() + e.value.size() || errno == ERANGE)
    fail(section, e, "expected an integer");
  return v;
}
long long IniDocument::getInt(const std::string& section, const std::string& key,
                              long long fallback) const {
  return has(section, key) ? getInt(section, key) : fallback;
}

bool IniDocument::getBool(const std::string& section, const std::string& key,
                          bool fallback) const {
  const Entry* e = find(section, key);
  if (!e) return fallback;
  if (e->value == "true" || e->value == "1" || e->value == "yes") return true;
  if (e->value == "false" || e->value == "0" || e->value == "no") return false;
  fail(section, *e, "expected true or false");
}

Eigen::VectorXd IniDocument::getVector(const std::string& section, const std::string& key,
                                       Eigen::Index size) const {
  const Entry& e = require(section, key);
  std::vector<std::vector<double>> rows;
  std::string bad;
  if (!parseRows(e.value, rows, bad)) fail(section, e, bad);
  std::vector<double> flat;
  for (const auto& r : rows) flat.insert(flat.end(), r.begin(), r.end());
  if (rows.size() > 1) {
    // a column vector "[a; b; c]" is fine; a matrix is not
    for (const auto& r : rows)
      if (r.size() != 1) fail(section, e, "expected a vector, got a matrix");
  }
  if (size >= 0 && static_cast<Eigen::Index>(flat.size()) != size)
    fail(section, e,
         "expected " + std::to_string(size) + " numbers, got " + std::to_string(flat.size()));
  return Eigen::Map<Eigen::VectorXd>(flat.data(), static_cast<Eigen::Index>(flat.size()));
}

Eigen::MatrixXd IniDocument::getMatrix(const std::string& section, const std::string& key,
                                       Eigen::Index rows, Eigen::Index cols) const {
  const Entry& e = require(section, key);
  std::vector<std::vector<double>> r;
  std::string bad;
  if (!parseRows(e.value, r, bad)) fail(section, e, bad);
  Eigen::MatrixXd m;
  if (r.size() == 1 && rows >= 0 && rows == cols && rows > 1 &&
      static_cast<Eigen::Index>(r[0].size()) == rows) {
    m = Eigen::Map<Eigen::VectorXd>(r[0].data(), rows).asDiagonal();  // diagonal shorthand
  } else {
    const auto nr = static_cast<Eigen::Index>(r.size());
    const auto nc = nr ? static_cast<Eigen::Index>(r[0].size()) : 0;
    m.resize(nr, nc);
    for (Eigen::Index i = 0; i < nr; ++i) {
      if (static_cast<Eigen::Index>(r[i].size()) != nc)
        fail(section, e, "row " + std::to_string(i + 1) + " has " + std::to_string(r[i].size()) +
                             " numbers, row 1 has " + std::to_string(nc));
      for (Eigen::Index j = 0; j < nc; ++j) m(i, j) = r[i][j];
    }
  }
  if ((rows >= 0 && m.rows() != rows) || (cols >= 0 && m.cols() != cols))
    fail(section, e,
         "expected a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix, got " +
             std::to_string(m.rows()) + "x" + std::to_string(m.cols()));
  return m;
}

IniDocument::Section& IniDocument::sectionFor(const std::string& section) {
  for (auto& sec : sections_)
    if (sec.name == section) return sec;
  sections_.push_back({section, "", {}, 0});
  return sections_.back();
}

void IniDocument::set(const std::string& section, const std::string& key,
                      const std::string& value) {
  Section& s = sectionFor(section);
  for (auto& e : s.entries)
    if (e.key == key) {
      e.value = value;
      return;
    }
  s.entries.push_back({key, value, 0});
}

bool IniDocument::hasOverrides(const std::string& prefix) const {
  for (const auto& s : sections_)
    if (s.name.rfind(prefix + ".", 0) == 0) return true;
  return false;
}

IniDocument IniDocument::overriddenBy(const std::string& prefix) const {
  IniDocument out = *this;
  for (const auto& s : sections_) {
    if (s.name.rfind(prefix + ".", 0) != 0) continue;
    const std::string target = s.name.substr(prefix.size() + 1);
    if (!hasSection(target))
      throw InputError(source_ + ":" + std::to_string(s.line) + ": [" + s.name + "] overrides the keys of [" + target +
                       "], which this file does not have");
    Section& t = out.sectionFor(target);
    for (const auto& e : s.entries) {
      auto it = std::find_if(t.entries.begin(), t.entries.end(), [&](const Entry& x) { return x.key == e.key; });
      if (it != t.entries.end()) *it = e;
      else t.entries.push_back(e);
    }
  }
  return out;
}

void IniDocument::set(const std::string& section, const std::string& key, double value) {
  set(section, key, formatDouble(value));
}

void IniDocument::set(const std::string& section, const std::string& key,
                      const Eigen::MatrixXd& value) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < value.rows(); ++i) {
    if (i) out += "; ";
    for (Eigen::Index j = 0; j < value.cols(); ++j) {
      if (j) out += " ";
      out += formatDouble(value(i, j));
    }
  }
  set(section, key, out + "]");
}

void IniDocument::setComment(const std::string& section, const std::string& comment) {
  sectionFor(section).comment = comment;
}

std::string IniDocument::toString() const {
  std::string out;
  for (const auto& s : sections_) {
    if (!out.empty()) out += "\n";
    if (!s.comment.empty()) {
      std::stringstream cs(s.comment);
      std::string l;
      while (std::getline(cs, l)) out += "; " + l + "\n";
    }
    out += "[" + s.name + "]\n";
    for (const auto& e : s.entries) out += e.key + " = " + e.value + "\n";
  }
  return out;
}

void IniDocument::save(const std::string& path) const {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(path + ": cannot write the configuration file");
  out << toString();
  if (!out) throw InputError(path + ": write failed");
}

void IniDocument::requireOnlyKeys(const std::string& section,
                                  const std::vector<std::string>& allowed) const {
  for (const auto& s : sections_) {
    if (s.name != section) continue;
    for (const auto& e : s.entries) {
      bool ok = false;
      for (const auto& a : allowed) ok = ok || a == e.key;
      if (!ok) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        throw InputError(source_ + ":" + std::to_string(e.line) + ": unknown key '" + e.key +
                         "' in [" + section + "] (known keys: " + list + ")");
      }
    }
  }
}

}  // namespace gssm::io
