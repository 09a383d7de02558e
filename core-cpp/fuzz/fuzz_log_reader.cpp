// libFuzzer target: arbitrary bytes as a session log / GnssLogger log through io::LogReader
// (lenient and strict). Checks, beyond "no crash, no sanitizer report":
//  - every sample read is finite in time and survives format_line -> LogReader unchanged
//    (io::same_sample), i.e. the writer/reader pair is lossless for whatever the reader accepts;
//  - the statistics are consistent (samples + skipped <= lines, issues bounded).
// Seeds: tests/fuzz-corpus/log_reader/ (excerpts of the real logs in ../shared/data).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "pdnav/io/log_format.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/io/log_writer.h"

namespace {

[[noreturn]] void fail(const char* what, const pdnav::Sample& s) {
  std::fprintf(stderr, "fuzz_log_reader: %s: %s\n", what, pdnav::io::format_line(s).c_str());
  std::abort();
}

/// Formats every accepted sample (one text, default columns) and reads it back in one pass:
/// the same samples must come out, in the same order.
void check_round_trip(const std::vector<pdnav::Sample>& samples) {
  std::string text;
  std::vector<const pdnav::Sample*> expected;
  for (const pdnav::Sample& s : samples) {
    const std::string line = pdnav::io::format_line(s);
    if (line.size() >= (1u << 20)) continue;  // above the reader's line cap by design
    text += line;
    text += '\n';
    expected.push_back(&s);
  }
  if (expected.empty()) return;
  pdnav::io::LogReader back(std::make_unique<std::istringstream>(text), "round-trip");
  pdnav::Sample t;
  for (const pdnav::Sample* s : expected) {
    if (!back.next(t)) fail("formatted line not read back", *s);
    if (!pdnav::io::same_sample(*s, t)) fail("round trip changed the sample", *s);
  }
  if (back.next(t)) fail("extra sample read back", t);
}

void read_all(const std::string& text, bool strict) {
  pdnav::io::LogReaderOptions opt;
  opt.strict = strict;
  opt.max_reported_issues = 8;
  std::vector<pdnav::Sample> samples;
  try {
    pdnav::io::LogReader reader(std::make_unique<std::istringstream>(text), "fuzz", opt);
    pdnav::Sample s;
    while (reader.next(s)) samples.push_back(s);
    const pdnav::io::ReadStats& st = reader.stats();
    if (st.samples + st.skipped_total() > st.lines || st.issues.size() > 8) std::abort();
  } catch (const pdnav::io::IoError&) {
    // strict mode, or empty input: an error with a position is the expected outcome
  }
  if (!strict) check_round_trip(samples);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  read_all(text, false);
  read_all(text, true);
  return 0;
}
