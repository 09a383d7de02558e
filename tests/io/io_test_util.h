// Helpers shared by the io tests: read a whole log held in a string.
#pragma once
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "pdnav/io/log_reader.h"

namespace pdnav::test {

struct ReadResult {
  std::vector<Sample> samples;
  io::ReadStats stats;
};

inline ReadResult read_text(const std::string& text, io::LogReaderOptions opt = {},
                            const std::string& name = "mem") {
  io::LogReader reader(std::make_unique<std::istringstream>(text), name, opt);
  ReadResult r;
  Sample s;
  while (reader.next(s)) r.samples.push_back(s);
  r.stats = reader.stats();
  return r;
}

inline std::int64_t skipped(const io::ReadStats& st, const std::string& reason) {
  auto it = st.skipped_by_reason.find(reason);
  return it == st.skipped_by_reason.end() ? 0 : it->second;
}

}  // namespace pdnav::test
