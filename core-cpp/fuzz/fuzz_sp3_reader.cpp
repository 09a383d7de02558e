// libFuzzer target: SP3-c/d precise orbit reader. Must never crash or hang; a bad header or
// epoch throws std::runtime_error (the documented contract), bad satellite lines are counted
// skips; every stored position and clock must be finite.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pdnav/gnss/sp3.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const pdnav::gnss::Sp3File f = pdnav::gnss::read_sp3(in, "fuzz.sp3");
    if (f.skipped_lines < 0) std::abort();
    for (const auto& e : f.epochs)
      for (const auto& [sat, s] : e.sats) {
        if (!s.pos.p_m.allFinite()) std::abort();
        if (s.has_clock ? !std::isfinite(s.clock_s) : s.clock_s != 0.0) std::abort();
      }
  } catch (const std::runtime_error&) {
    // documented: bad header or epoch line
  }
  return 0;
}
