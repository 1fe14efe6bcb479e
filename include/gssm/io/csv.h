#pragma once
// Numeric CSV tables with a header line. Errors name file, line, column and value.
#include <string>
#include <vector>

namespace gssm::io {

struct CsvTable {
  std::string source;
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
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
/// One CSV line (no newline) in the same format.
std::string csvLine(const std::vector<double>& values);

}  // namespace gssm::io
