// libFuzzer target: RINEX clock 3.0x reader and the clock interpolation. Must never crash or
// hang; a bad header throws std::runtime_error (the documented contract), bad records are
// counted skips; every stored sample must be finite and sorted, and interpolation inside the
// span must give a finite clock or a reason.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pdnav/gnss/clock_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const pdnav::gnss::ClockFile f = pdnav::gnss::read_rinex_clock(in, "fuzz.clk");
    const pdnav::gnss::ClockInterpolationOptions opt;
    for (const auto& [sat, v] : f.sats) {
      for (std::size_t i = 0; i < v.size(); ++i) {
        if (!std::isfinite(v[i].clock_s)) std::abort();
        if (i > 0 && v[i].gps_ns <= v[i - 1].gps_ns) std::abort();
      }
      if (v.empty()) continue;
      const pdnav::TimeNs mid = v.front().gps_ns / 2 + v.back().gps_ns / 2;
      double clk = 0.0, rate = 0.0;
      std::string why;
      if (pdnav::gnss::interpolate_clock(v, mid, opt, clk, rate, &why)) {
        if (!std::isfinite(clk) || !std::isfinite(rate)) std::abort();
      } else if (why.empty()) {
        std::abort();
      }
    }
  } catch (const std::runtime_error&) {
    // documented: bad header
  }
  return 0;
}
