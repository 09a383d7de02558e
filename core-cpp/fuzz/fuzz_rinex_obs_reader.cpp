// libFuzzer target: RINEX 3 observation reader, its conversion to Android Raw rows and the
// RINEX writer fed with those rows. Must never crash or hang; a bad header throws
// std::runtime_error (the documented contract), bad records are counted; every converted
// row must be finite where it claims a value, and the writer must accept or reject each row
// with a reason.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pdnav/gnss/rinex_obs.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    pdnav::gnss::RinexObsReader reader(in, "fuzz.obs");
    pdnav::gnss::RinexObsEpoch ep;
    std::map<std::string, std::int64_t> skipped;
    pdnav::gnss::RinexObsWriter writer;
    int epochs = 0;
    while (reader.next(ep) && epochs++ < 2000) {
      for (const auto& r : pdnav::gnss::rinex_epoch_to_raw(ep, reader.header(), skipped)) {
        if (!std::isfinite(r.carrier_frequency_hz)) std::abort();
        std::string why;
        if (!writer.add(r, &why) && why.empty()) std::abort();
      }
    }
    std::ostringstream out;
    writer.finish(out);
  } catch (const std::runtime_error&) {
    return 0;
  }
  return 0;
}
