// libFuzzer target: the CSV reader must either parse or throw InputError,
// in both strict and row-skipping modes, never crash or hang.
#include <cstdint>
#include <string>

#include "gssm/core/error.h"
#include "gssm/io/csv.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    gssm::io::parseCsv(text, "fuzz.csv");
  } catch (const gssm::InputError&) {
  }
  try {
    std::vector<gssm::io::CsvRowError> errors;
    const auto t = gssm::io::parseCsv(text, "fuzz.csv", &errors);
    for (const auto& row : t.rows)
      if (row.size() != t.header.size()) __builtin_trap();  // every kept row is complete
  } catch (const gssm::InputError&) {
  }
  return 0;
}
