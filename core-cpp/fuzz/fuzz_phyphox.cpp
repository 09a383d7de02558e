// libFuzzer target: arbitrary bytes as a phyphox CSV export (a zip, or tables separated by
// "=== NAME" lines, meta/time.csv and meta/device.csv included) through
// io::open_memory_source; checks in fuzz_recording.h.
// Seeds: tests/fuzz-corpus/phyphox/ (excerpts of the spec-written fixture tests/data/loggers).
#include "fuzz_recording.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pdnav::fuzz::read_recording(std::string(reinterpret_cast<const char*>(data), size), pdnav::io::Format::kPhyphox,
                              "Accelerometer.csv", true);
  return 0;
}
