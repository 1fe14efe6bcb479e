#pragma once
// Numeric CSV tables with a header line. Errors name file, line, column and value.
#include <cstdint>
#include <string>
#include <vector>

#include "gssm/io/append_file.h"

namespace gssm::io {

/// The numbers of a table, row-major in one block (no allocation per row:
/// a 10⁶-row log reads without a million small vectors).
class CsvRows {
 public:
  /// One row, a view into the block.
  struct Row {
    const double* p;
    std::size_t n;
    double operator[](std::size_t c) const { return p[c]; }
    const double* data() const { return p; }
    std::size_t size() const { return n; }
    const double* begin() const { return p; }
    const double* end() const { return p + n; }
  };
  struct Iterator {
    const CsvRows* rows;
    std::size_t r;
    Row operator*() const { return (*rows)[r]; }
    Iterator& operator++() { return ++r, *this; }
    bool operator!=(const Iterator& o) const { return r != o.r; }
  };
  explicit CsvRows(std::size_t columns = 0) : cols_(columns) {}
  std::size_t size() const { return cols_ ? values_.size() / cols_ : 0; }
  bool empty() const { return values_.empty(); }
  Row operator[](std::size_t r) const { return {values_.data() + r * cols_, cols_}; }
  Row back() const { return (*this)[size() - 1]; }
  Iterator begin() const { return {this, 0}; }
  Iterator end() const { return {this, size()}; }
  /// Appends a row of exactly columns() values.
  void push_back(const double* values) { values_.insert(values_.end(), values, values + cols_); }
  std::size_t columns() const { return cols_; }

 private:
  std::size_t cols_;
  std::vector<double> values_;
};

struct CsvTable {
  std::string source;
  std::vector<std::string> header;
  CsvRows rows;
  std::vector<int> line_of_row;  ///< 1-based file line of each row
  /// Index of a column by name, or -1.
  int column(const std::string& name) const;
};

/// A data row that could not be used, with the full message.
struct CsvRowError {
  int line = 0;
  std::string message;  ///< "source:line: column 'name': value 'v' is not a finite number"
};

/// Parses text; throws InputError "source:line: column 'name': value 'v' ...".
/// With `row_errors`, bad data rows are recorded there and left out instead
/// (a missing header or an empty file still throws).
CsvTable parseCsv(const std::string& text, const std::string& source,
                  std::vector<CsvRowError>* row_errors = nullptr);
CsvTable readCsv(const std::string& path, std::vector<CsvRowError>* row_errors = nullptr);

/// Writes header and rows with round-trip number formatting (deterministic).
void writeCsv(const std::string& path, const std::vector<std::string>& header,
              const std::vector<std::vector<double>>& rows);
/// Writes a CSV table row by row (nothing held but a ~1 MB buffer), numbers
/// in the same round-trip format. Errors (InputError) name the file.
class CsvWriter {
 public:
  /// Creates `path` (replacing it) and writes the header line.
  CsvWriter(const std::string& path, const std::vector<std::string>& header);
  /// Continues a file this class wrote: cuts it at byte `length` (what
  /// flush() returned then) and appends from there.
  CsvWriter(const std::string& path, std::uint64_t length);
  // Destroying it writes what is buffered (call flush() to see errors).

  void row(const double* values, std::size_t n);
  void row(const std::vector<double>& values) { row(values.data(), values.size()); }
  /// Hands everything written so far to the operating system; returns the
  /// file's length in bytes.
  std::uint64_t flush() { return file_.flush(); }

 private:
  AppendFile file_;
};

/// One CSV line (no newline) in the same format.
std::string csvLine(const std::vector<double>& values);

}  // namespace gssm::io
