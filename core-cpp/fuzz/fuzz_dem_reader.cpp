// libFuzzer target: the .pdem reader must reject any byte string with a DemError, never crash,
// and every accepted tile must answer lookups without crashing. Seeds: tests/fuzz-corpus/dem_reader/.
#include <cstddef>
#include <cstdint>

#include "pdnav/terrain/dem.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const pdnav::terrain::Dem dem = pdnav::terrain::Dem::parse(data, size, "fuzz.pdem");
    const double e = 0.5 * (dem.min_e_m() + dem.max_e_m());
    const double n = 0.5 * (dem.min_n_m() + dem.max_n_m());
    volatile double sink = dem.at_local(e, n).elevation_m + dem.at_local(dem.max_e_m(), dem.max_n_m()).elevation_m;
    sink = sink + static_cast<double>(dem.elevation_or_nan(static_cast<float>(e), static_cast<float>(n)));
    (void)dem.at(dem.to_geodetic(e, n));
  } catch (const pdnav::terrain::DemError&) {
  }
  return 0;
}
