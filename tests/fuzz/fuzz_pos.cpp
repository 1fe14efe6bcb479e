// libFuzzer target: the RTKLIB solution reader must either parse or throw
// InputError, never crash or hang; what it keeps is in strict time order.
#include <cstdint>
#include <string>

#include "gssm/core/error.h"
#include "gssm/io/rtklib_pos.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const gssm::io::GnssSolution s = gssm::io::parseRtklibPos(text, "fuzz.pos");
    for (std::size_t i = 1; i < s.fixes.size(); ++i)
      if (!(s.fixes[i].t > s.fixes[i - 1].t)) __builtin_trap();
  } catch (const gssm::InputError&) {
  }
  return 0;
}
