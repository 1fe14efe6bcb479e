// libFuzzer target: the INI reader and its typed getters must either work or
// throw InputError naming the problem, never crash; writing and re-reading a
// parsed document gives the same values.
#include <cstdint>
#include <string>

#include "gssm/core/error.h"
#include "gssm/io/ini.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto ini = gssm::io::IniDocument::parse(text, "fuzz.ini");
    for (const char* key : {"T", "Q", "R", "type", "state_mean", "window"}) {
      for (const char* section : {"model", "prior", "fixed_lag"}) {
        try {
          if (!ini.has(section, key)) continue;
          (void)ini.getDouble(section, key, 0.0);
        } catch (const gssm::InputError&) {
        }
        try {
          (void)ini.getMatrix(section, key);
        } catch (const gssm::InputError&) {
        }
        try {
          (void)ini.getInt(section, key, 0);
        } catch (const gssm::InputError&) {
        }
      }
    }
    (void)gssm::io::IniDocument::parse(ini.toString(), "round-trip.ini");
  } catch (const gssm::InputError&) {
  }
  return 0;
}
