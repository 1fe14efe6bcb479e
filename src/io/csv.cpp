#include "gssm/io/csv.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/io/ini.h"

namespace gssm::io {

namespace {
std::vector<std::string> splitLine(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::stringstream ss(line);
  while (std::getline(ss, cell, ',')) {
    const auto b = cell.find_first_not_of(" \t\r");
    const auto e = cell.find_last_not_of(" \t\r");
    out.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
  }
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}
}  // namespace

int CsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  return -1;
}

CsvTable parseCsv(const std::string& text, const std::string& source, std::vector<CsvRowError>* row_errors) {
  CsvTable t;
  t.source = source;
  std::stringstream ss(text);
  std::string line;
  int lineno = 0;
  bool have_header = false;
  while (std::getline(ss, line)) {
    ++lineno;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    std::vector<std::string> cells = splitLine(line);
    if (!have_header) {
      for (std::size_t i = 0; i < cells.size(); ++i) {
        double dummy;
        char* end = nullptr;
        dummy = std::strtod(cells[i].c_str(), &end);
        (void)dummy;
        if (cells[i].empty() || (end == cells[i].c_str() + cells[i].size()))
          throw InputError(source + ":" + std::to_string(lineno) + ": header expected (column " +
                           std::to_string(i + 1) + " is '" + cells[i] +
                           "'); the first line must name the columns, e.g. t,range");
        for (std::size_t j = 0; j < i; ++j)
          if (cells[j] == cells[i])
            throw InputError(source + ":" + std::to_string(lineno) + ": column '" + cells[i] +
                             "' appears twice in the header");
      }
      t.header = std::move(cells);
      have_header = true;
      continue;
    }
    auto bad = [&](const std::string& message) {
      if (!row_errors) throw InputError(message);
      row_errors->push_back({lineno, message});
    };
    if (cells.size() != t.header.size()) {
      bad(source + ":" + std::to_string(lineno) + ": " + std::to_string(cells.size()) +
          " fields, the header has " + std::to_string(t.header.size()));
      continue;
    }
    std::vector<double> row(cells.size());
    bool ok = true;
    for (std::size_t i = 0; i < cells.size() && ok; ++i) {
      errno = 0;
      char* end = nullptr;
      const double v = std::strtod(cells[i].c_str(), &end);
      if (cells[i].empty() || end != cells[i].c_str() + cells[i].size() || errno == ERANGE ||
          !std::isfinite(v)) {
        bad(source + ":" + std::to_string(lineno) + ": column '" + t.header[i] + "': value '" + cells[i] +
            "' is not a finite number");
        ok = false;
      }
      row[i] = v;
    }
    if (!ok) continue;
    t.rows.push_back(std::move(row));
    t.line_of_row.push_back(lineno);
  }
  if (!have_header) throw InputError(source + ": empty file (expected a header line and rows)");
  return t;
}

CsvTable readCsv(const std::string& path, std::vector<CsvRowError>* row_errors) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parseCsv(ss.str(), path, row_errors);
}

std::string csvLine(const std::vector<double>& values) {
  std::string out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) out += ",";
    out += formatDouble(values[i]);
  }
  return out;
}

void writeCsv(const std::string& path, const std::vector<std::string>& header,
              const std::vector<std::vector<double>>& rows) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(path + ": cannot write the file");
  for (std::size_t i = 0; i < header.size(); ++i) out << (i ? "," : "") << header[i];
  out << "\n";
  for (const auto& r : rows) out << csvLine(r) << "\n";
  if (!out) throw InputError(path + ": write failed");
}

}  // namespace gssm::io
