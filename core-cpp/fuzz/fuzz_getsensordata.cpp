// libFuzzer target: arbitrary bytes as a GetSensorData (IPIN logger) text log through
// io::open_memory_source; checks in fuzz_recording.h (its stream is in file order per type,
// not globally merged). Seeds: tests/fuzz-corpus/getsensordata/ (excerpts of the spec-written
// fixture tests/data/loggers/getsensordata-walk.txt).
#include "fuzz_recording.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::pair<std::string, std::string>> files{{"log.txt", text}};
  for (const bool strict : {false, true}) {
    pdnav::io::SourceOptions opt;
    opt.log.strict = strict;
    opt.log.max_reported_issues = 8;
    std::vector<pdnav::Sample> samples;
    try {
      auto src = pdnav::io::open_memory_source(files, "fuzz", pdnav::io::Format::kGetSensorData, opt);
      pdnav::Sample s;
      while (src->next(s)) samples.push_back(s);
      const pdnav::io::ReadStats& st = src->stats();
      std::int64_t sum = 0;
      for (const auto& [type, n] : st.samples_by_type) sum += n;
      if (sum != st.samples || st.issues.size() > 8 || st.samples + st.skipped_total() > 2 * st.lines) std::abort();
    } catch (const pdnav::io::IoError&) {
    }
    if (!strict) pdnav::fuzz::check_round_trip(samples);
  }
  return 0;
}
