// libFuzzer target: RINEX navigation reader + the orbit/clock evaluation of whatever it
// accepted. Must never crash, hang or return a non-finite state; bad headers throw
// std::runtime_error (the documented contract), bad records are counted.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/rinex.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  pdnav::gnss::RinexNavData nav;
  try {
    nav = pdnav::gnss::read_rinex_nav(in, "fuzz.rnx");
  } catch (const std::runtime_error&) {
    return 0;
  }
  pdnav::gnss::EphemerisStore store;
  for (const auto& k : nav.kepler) store.add(k);
  for (const auto& g : nav.glonass) store.add(g);
  const auto check = [&](const pdnav::gnss::SatId& sat, pdnav::TimeNs t) {
    std::string why;
    const auto s = store.state(sat, t, &why);
    if (s && !(s->pos.p_m.allFinite() && std::isfinite(s->clock_bias_s))) std::abort();
    if (!s && why.empty()) std::abort();
  };
  for (const auto& k : nav.kepler) check(k.sat, k.toe_gps_ns + 1800 * pdnav::kNsPerS);
  for (const auto& g : nav.glonass) check(g.sat, g.tb_gps_ns + 600 * pdnav::kNsPerS);
  return 0;
}
