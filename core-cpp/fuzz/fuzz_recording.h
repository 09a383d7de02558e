// Shared body of the fuzz targets of the multi-file / other-logger readers (fuzz_sensorlogger,
// fuzz_phyphox, fuzz_getsensordata): arbitrary bytes as a recording through
// io::open_memory_source, lenient and strict. Input: a zip archive (starts with "PK"), a JSON
// export (starts with '['), or files
// separated by lines "=== NAME" (text before the first marker is the file `first_name`).
// Checks, beyond "no crash, no sanitizer report":
//  - merged readers (Sensor Logger, phyphox) return samples in time order;
//  - every sample survives format_line -> LogReader unchanged (io::same_sample): whatever a
//    reader accepts, `pdnav import` writes losslessly;
//  - the statistics are consistent (samples_by_type sums to samples, issues bounded).
#pragma once
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "pdnav/io/log_format.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/io/log_writer.h"
#include "pdnav/io/sample_source.h"

namespace pdnav::fuzz {

[[noreturn]] inline void fail(const char* what, const Sample& s) {
  std::fprintf(stderr, "fuzz recording: %s: %s\n", what, io::format_line(s).c_str());
  std::abort();
}

inline std::vector<std::pair<std::string, std::string>> split_files(const std::string& bytes, const std::string& first_name) {
  std::vector<std::pair<std::string, std::string>> files;
  if (bytes.size() >= 2 && bytes[0] == 'P' && bytes[1] == 'K') {
    files.emplace_back("fuzz.zip", bytes);
    return files;
  }
  if (!bytes.empty() && bytes[0] == '[') {  // Sensor Logger's JSON export
    files.emplace_back("fuzz.json", bytes);
    return files;
  }
  std::string name = first_name, body;
  std::size_t pos = 0;
  while (pos <= bytes.size()) {
    const std::size_t nl = bytes.find('\n', pos);
    const std::string line = bytes.substr(pos, nl == std::string::npos ? std::string::npos : nl - pos + 1);
    if (line.rfind("=== ", 0) == 0) {
      if (!body.empty() || !files.empty() || name != first_name) files.emplace_back(name, body);
      name = line.substr(4);
      while (!name.empty() && (name.back() == '\n' || name.back() == '\r')) name.pop_back();
      body.clear();
    } else {
      body += line;
    }
    if (nl == std::string::npos) break;
    pos = nl + 1;
  }
  files.emplace_back(name, body);
  if (files.size() > 64) files.resize(64);
  return files;
}

inline void check_round_trip(const std::vector<Sample>& samples) {
  std::string text;
  std::vector<const Sample*> expected;
  for (const Sample& s : samples) {
    const std::string line = io::format_line(s);
    if (line.size() >= (1u << 20)) continue;
    text += line;
    text += '\n';
    expected.push_back(&s);
  }
  if (expected.empty()) return;
  io::LogReaderOptions opt;
  opt.drop_backwards_time = false;
  io::LogReader back(std::make_unique<std::istringstream>(text), "round-trip", opt);
  Sample t;
  for (const Sample* s : expected) {
    if (!back.next(t)) fail("formatted line not read back", *s);
    if (!io::same_sample(*s, t)) fail("round trip changed the sample", *s);
  }
}

inline void read_recording(const std::string& bytes, io::Format fmt, const std::string& first_name, bool ordered) {
  for (const bool strict : {false, true}) {
    io::SourceOptions opt;
    opt.log.strict = strict;
    opt.log.max_reported_issues = 8;
    std::vector<Sample> samples;
    try {
      auto src = io::open_memory_source(split_files(bytes, first_name), "fuzz", fmt, opt);
      Sample s;
      while (src->next(s)) {
        if (ordered && !samples.empty() && sample_time_ns(s) < sample_time_ns(samples.back()) &&
            !std::holds_alternative<MetaSample>(samples.back()))
          fail("merged stream out of time order", s);
        samples.push_back(s);
        if (samples.size() > 200000) break;
      }
      const io::ReadStats& st = src->stats();
      std::int64_t sum = 0;
      for (const auto& [type, n] : st.samples_by_type) sum += n;
      if (sum != st.samples || st.issues.size() > 8) std::abort();
    } catch (const io::IoError&) {
      // not a recording of that format, strict mode, or no samples: an error with a position
    }
    if (!strict) check_round_trip(samples);
  }
}

}  // namespace pdnav::fuzz
