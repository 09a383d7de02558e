// libFuzzer target: arbitrary bytes as a Sensor Logger recording (a zip, or CSV files separated
// by "=== NAME" lines) through io::open_memory_source; checks in fuzz_recording.h.
// Seeds: tests/fuzz-corpus/sensorlogger/ (excerpts of the shared ETHZ walk).
#include "fuzz_recording.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pdnav::fuzz::read_recording(std::string(reinterpret_cast<const char*>(data), size), pdnav::io::Format::kSensorLogger,
                              "TotalAcceleration.csv", true);
  return 0;
}
