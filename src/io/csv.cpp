#include "gssm/io/csv.h"

#include <cmath>
#include <cstring>

#include "gssm/core/error.h"
#include "gssm/io/number_text.h"
#include "io/byte_order_mark.h"
#include "io/text_file.h"

namespace gssm::io {

namespace {
struct Cell {
  const char* begin;
  const char* end;
  std::string str() const { return std::string(begin, end); }
  bool empty() const { return begin == end; }
};

// Splits [b, e) at commas into cells trimmed of spaces, tabs and '\r'.
void splitLine(const char* b, const char* e, std::vector<Cell>& cells) {
  cells.clear();
  auto trimmed = [](const char* cb, const char* ce) {
    while (cb < ce && (*cb == ' ' || *cb == '\t' || *cb == '\r')) ++cb;
    while (ce > cb && (ce[-1] == ' ' || ce[-1] == '\t' || ce[-1] == '\r')) --ce;
    return Cell{cb, ce};
  };
  const char* start = b;
  for (const char* p = b; p < e; ++p)
    if (*p == ',') {
      cells.push_back(trimmed(start, p));
      start = p + 1;
    }
  cells.push_back(trimmed(start, e));
}

bool blank(const char* b, const char* e) {
  for (; b < e; ++b)
    if (*b != ' ' && *b != '\t' && *b != '\r') return false;
  return true;
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
  int lineno = 0;
  bool have_header = false;
  std::vector<Cell> cells;
  std::vector<double> row;
  const char* p = text.data() + byteOrderMarkLength(text);  // a spreadsheet's UTF-8 mark is no header text
  const char* const text_end = text.data() + text.size();
  while (p < text_end) {
    const char* eol = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(text_end - p)));
    if (!eol) eol = text_end;
    const char* line_begin = p;
    const char* line_end = eol;
    p = eol + 1;
    ++lineno;
    if (blank(line_begin, line_end)) continue;
    splitLine(line_begin, line_end, cells);
    if (!have_header) {
      for (std::size_t i = 0; i < cells.size(); ++i) {
        double number;
        if (cells[i].empty() || parseDouble(cells[i].begin, cells[i].end, number))
          throw InputError(source + ":" + std::to_string(lineno) + ": header expected (column " +
                           std::to_string(i + 1) + " is '" + cells[i].str() +
                           "'); the first line must name the columns, e.g. t,range");
        t.header.push_back(cells[i].str());
        for (std::size_t j = 0; j < i; ++j)
          if (t.header[j] == t.header[i])
            throw InputError(source + ":" + std::to_string(lineno) + ": column '" + t.header[i] +
                             "' appears twice in the header");
      }
      have_header = true;
      t.rows = CsvRows(t.header.size());
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
    row.resize(cells.size());
    bool ok = true;
    for (std::size_t i = 0; i < cells.size() && ok; ++i) {
      if (!parseDouble(cells[i].begin, cells[i].end, row[i]) || !std::isfinite(row[i])) {
        bad(source + ":" + std::to_string(lineno) + ": column '" + t.header[i] + "': value '" + cells[i].str() +
            "' is not a finite number");
        ok = false;
      }
    }
    if (!ok) continue;
    t.rows.push_back(row.data());
    t.line_of_row.push_back(lineno);
  }
  if (!have_header) throw InputError(source + ": empty file (expected a header line and rows)");
  return t;
}

CsvTable readCsv(const std::string& path, std::vector<CsvRowError>* row_errors) {
  return parseCsv(readTextFile(path), path, row_errors);
}

namespace {
void appendCsvLine(std::string& out, const double* values, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (i) out += ',';
    appendDouble(out, values[i]);
  }
}
}  // namespace

std::string csvLine(const std::vector<double>& values) {
  std::string out;
  appendCsvLine(out, values.data(), values.size());
  return out;
}

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& header) : file_(path) {
  std::string& b = file_.buffer();
  for (std::size_t i = 0; i < header.size(); ++i) (b += (i ? "," : "")) += header[i];
  b += '\n';
}

CsvWriter::CsvWriter(const std::string& path, std::uint64_t length) : file_(path, length) {}

void CsvWriter::row(const double* values, std::size_t n) {
  appendCsvLine(file_.buffer(), values, n);
  file_.buffer() += '\n';
  file_.maybeWrite();
}

void writeCsv(const std::string& path, const std::vector<std::string>& header,
              const std::vector<std::vector<double>>& rows) {
  CsvWriter out(path, header);
  for (const auto& r : rows) out.row(r);
  out.flush();
}

}  // namespace gssm::io
