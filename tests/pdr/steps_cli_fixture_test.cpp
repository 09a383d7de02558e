// Issue 19.4: a session log with a Meta start (Helsinki, 2025: declination ~ +10.5 deg) for
// the `pdnav steps` check in tests/pdr/extra.cmake (fixture steps_cli_meta_log): the command
// must apply the WMM declination from the Meta start, and say headings are magnetic without.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "pdnav/io/log_writer.h"
#include "synthetic_imu.h"

using namespace pdnav;

TEST(StepsCliFixture, WriteMetaStartLog) {
  const auto dir = std::filesystem::path(PDNAV_BINARY_DIR) / "test-scratch" / "steps-cli";
  std::filesystem::create_directories(dir);
  test::WalkSpec spec;
  spec.tilt_deg = 25.0;
  spec.seed = 9;
  const auto w = test::make_walk(spec, {{12, 0}});
  io::LogWriter writer((dir / "walk_meta.txt").string());
  writer.write(Sample{MetaSample{0, "StartLatitudeDegrees", "60.17"}});
  writer.write(Sample{MetaSample{0, "StartLongitudeDegrees", "24.94"}});
  constexpr std::int64_t kStartUnixMs = 1751328000000;  // 2025-07-01T00:00Z
  for (std::size_t i = 0; i < w.accel.size(); ++i) {
    AccelSample a = w.accel[i];
    a.utc_ms = kStartUnixMs + (a.t_ns - w.accel.front().t_ns) / kNsPerMs;
    writer.write(Sample{a});
    writer.write(Sample{w.gyro[i]});
    writer.write(Sample{w.rotation[i]});
  }
  writer.close();
  EXPECT_TRUE(std::filesystem::exists(dir / "walk_meta.txt"));
}
