// Every reader's error names the file, the line and the reason (issue 9; the catalogue is
// docs/reliability.md). Text formats use "file:line: reason"; errors about the file as a
// whole have no line ("file: reason" for the log reader/writer, "file:0: reason" for RINEX);
// the binary DEM tile uses "file: reason" with "header line N" for header lines.
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/rinex.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/io/log_writer.h"
#include "pdnav/route/walk_graph.h"
#include "pdnav/terrain/dem.h"

namespace pdnav::reliability {
namespace {

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

/// Runs f, expects an exception of type E, returns its what().
template <class E, class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no exception";
  return "";
}

const char* const kBadLog =
    "# Version: pdnav-log 1\n"
    "Accel,1700000000000,1000000000,0.1,9.8,0.2\n"
    "Accel,1700000000010,1010000000,0.1,not-a-number,0.2\n"
    "Accel,1700000000020,1020000000,0.1,9.8,0.2\n";

TEST(ErrorMessages, LogReaderStrictNamesFileLineAndReason) {
  io::LogReaderOptions opt;
  opt.strict = true;
  io::LogReader reader(std::make_unique<std::istringstream>(kBadLog), "walk.log", opt);
  try {
    for (Sample s; reader.next(s);) {
    }
    FAIL() << "strict reader accepted a malformed line";
  } catch (const io::IoError& e) {
    EXPECT_EQ(e.file(), "walk.log");
    EXPECT_EQ(e.line(), 3);
    EXPECT_FALSE(e.reason().empty());
    EXPECT_TRUE(starts_with(e.what(), "walk.log:3: ")) << e.what();
  }
}

TEST(ErrorMessages, LogReaderLenientCountsAndReportsTheSkippedLine) {
  io::LogReader reader(std::make_unique<std::istringstream>(kBadLog), "walk.log");
  int n = 0;
  for (Sample s; reader.next(s);) ++n;
  EXPECT_EQ(n, 2);
  ASSERT_EQ(reader.stats().skipped_total(), 1);
  ASSERT_EQ(reader.stats().issues.size(), 1u);
  const std::string msg = reader.stats().issues[0].to_string();
  EXPECT_TRUE(starts_with(msg, "walk.log:3: ")) << msg;
  EXPECT_GT(msg.size(), std::string("walk.log:3: ").size());
}

TEST(ErrorMessages, MissingAndUncreatableFilesNameThePathAtLineZero) {
  const std::string missing = "/nonexistent-dir/walk.log";
  std::string msg = error_of<io::IoError>([&] { io::LogReader r(missing); });
  EXPECT_TRUE(starts_with(msg, missing + ": cannot open")) << msg;  // IoError: "file: reason" at line 0
  msg = error_of<io::IoError>([&] { io::LogWriter w(missing); });
  EXPECT_TRUE(starts_with(msg, missing + ": cannot create")) << msg;
  msg = error_of<std::runtime_error>([&] { gnss::EphemerisStore().load_rinex_nav("/nonexistent-dir/x.16n"); });
  EXPECT_TRUE(starts_with(msg, "/nonexistent-dir/x.16n:0: ")) << msg;
  msg = error_of<std::runtime_error>([&] { route::WalkGraph::load("/nonexistent-dir/x.graph"); });
  EXPECT_TRUE(starts_with(msg, "/nonexistent-dir/x.graph")) << msg;
  msg = error_of<terrain::DemError>([&] { terrain::Dem::load("/nonexistent-dir/x.pdem"); });
  EXPECT_TRUE(starts_with(msg, "/nonexistent-dir/x.pdem: ")) << msg;
}

TEST(ErrorMessages, RinexNamesFileLineAndReason) {
  std::istringstream in("this is not a navigation file\n");
  const std::string msg = error_of<std::runtime_error>([&] { gnss::read_rinex_nav(in, "brdc.16n"); });
  EXPECT_TRUE(starts_with(msg, "brdc.16n:1: ")) << msg;
  EXPECT_NE(msg.find("RINEX"), std::string::npos) << msg;
}

TEST(ErrorMessages, WalkGraphNamesFileLineAndReason) {
  std::istringstream in("pdnav-graph 1\norigin 42.5 1.5 0\nvertices two\n");
  const std::string msg = error_of<std::runtime_error>([&] { route::WalkGraph::parse(in, "town.graph"); });
  EXPECT_TRUE(starts_with(msg, "town.graph:3: ")) << msg;
}

TEST(ErrorMessages, DemNamesFileAndHeaderLine) {
  const std::string text = "PDEM 1\ncrs local_enu\nthis-line-has-no-value\nend_header\n";
  const std::vector<std::uint8_t> bytes(text.begin(), text.end());
  std::string msg = error_of<terrain::DemError>([&] { terrain::Dem::parse(bytes.data(), bytes.size(), "area.pdem"); });
  EXPECT_TRUE(starts_with(msg, "area.pdem: header line 3")) << msg;
  const std::string junk = "GIF89a";
  const std::vector<std::uint8_t> jb(junk.begin(), junk.end());
  msg = error_of<terrain::DemError>([&] { terrain::Dem::parse(jb.data(), jb.size(), "area.pdem"); });
  EXPECT_TRUE(starts_with(msg, "area.pdem: ")) << msg;
  EXPECT_NE(msg.find("magic"), std::string::npos) << msg;
}

}  // namespace
}  // namespace pdnav::reliability
