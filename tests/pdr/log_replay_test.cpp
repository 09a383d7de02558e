// The pdr engine behind the session-log format: a synthetic walk written with io::LogWriter,
// read back with io::LogReader and replayed. Also leaves the log for the CLI check in
// tests/pdr/extra.cmake (fixture pdr_cli_log).
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/io/log_reader.h"
#include "pdnav/io/log_writer.h"
#include "pdnav/pdr/pdr.h"
#include "synthetic_imu.h"
#include "test_data.h"

using namespace pdnav;
using namespace pdnav::pdr;

namespace {

/// 10 s straight north, a 90 degree left turn, 20 s straight: cadence 1.8 Hz.
pdnav::test::SyntheticWalk fixture_walk() {
  pdnav::test::WalkSpec spec;
  spec.tilt_deg = 25.0;
  spec.final_straight_s = 20.0;
  spec.seed = 5;
  return pdnav::test::make_walk(spec, {{10, 90}});
}

void write_log(const std::string& path, const pdnav::test::SyntheticWalk& w) {
  io::LogWriter writer(path);
  for (std::size_t i = 0; i < w.accel.size(); ++i) {
    writer.write(Sample{w.accel[i]});
    writer.write(Sample{w.gyro[i]});
  }
  writer.close();
}

}  // namespace

TEST(PdrLogReplay, StepsAndTurnThroughLogWriterAndReader) {
  const auto walk = fixture_walk();
  const auto dir = pdnav::test::scratch_dir("pdr-log-replay");
  const std::string path = (dir / "walk.txt").string();
  write_log(path, walk);

  io::LogReader reader(path);
  Pdr engine;
  std::vector<PdrTurn> turns;
  Sample s;
  while (reader.next(s)) {
    if (const auto* a = std::get_if<AccelSample>(&s)) engine.feed(*a);
    if (const auto* g = std::get_if<GyroSample>(&s)) engine.feed(*g);
    for (const auto& t : engine.take_turns()) turns.push_back(t);
  }
  EXPECT_EQ(reader.stats().skipped_total(), 0);
  const double expected_steps = walk.duration_s * 1.8;
  EXPECT_NEAR(static_cast<double>(engine.step_count()), expected_steps, 5.0);
  ASSERT_EQ(turns.size(), 1u);
  EXPECT_NEAR(rad_to_deg(turns[0].angle_rad), 90.0, 10.0);
}

// Writes the log the CLI test (pdr_cli_steps_log) reads. Runs as a ctest fixture setup.
TEST(PdrLogReplay, WriteCliFixture) {
  const auto dir = std::filesystem::path(PDNAV_BINARY_DIR) / "test-scratch" / "pdr-cli";
  std::filesystem::create_directories(dir);
  write_log((dir / "walk.txt").string(), fixture_walk());
  EXPECT_TRUE(std::filesystem::exists(dir / "walk.txt"));
}
