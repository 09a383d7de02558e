// Streaming: a ~50 MB log is written and read back in bounded memory (the reader keeps no
// samples; resident memory grows by far less than the log size).
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "pdnav/io/log_reader.h"
#include "pdnav/io/log_writer.h"
#include "test_data.h"

namespace pdnav {
namespace {

/// Resident set size of this process in bytes (Linux /proc/self/statm).
std::int64_t rss_bytes() {
  std::ifstream in("/proc/self/statm");
  std::int64_t pages = 0, resident = 0;
  in >> pages >> resident;
  return resident * 4096;
}

GnssRawSample raw_at(int i) {
  GnssRawSample r;
  r.t_ns = 1'000'000'000 + TimeNs{i} * 1'000'000;
  r.utc_ms = 1'700'000'000'000 + i;
  r.time_nanos = 61090000000 + TimeNs{i} * 1'000'000;
  r.full_bias_nanos = -1383435750910273353;
  r.bias_nanos = 0.25;
  r.svid = i % 32 + 1;
  r.state = 16431;
  r.received_sv_time_nanos = 258211922049091 + i;
  r.cn0_dbhz = 28.924739837646484;
  r.pseudorange_rate_mps = 673.7922380838304;
  r.accumulated_delta_range_m = 40099.90686538701 + i;
  r.carrier_frequency_hz = 1575420030;
  r.constellation_type = 1;
  r.code_type = "C";
  return r;
}

TEST(Streaming, FiftyMegabyteLogIsReadInBoundedMemory) {
  const std::string path = (test::scratch_dir("io_streaming") / "big.txt").string();
  constexpr int kLines = 230'000;  // ~52 MB of Raw + Accel lines
  {
    io::LogWriter w(path);
    for (int i = 0; i < kLines; ++i) {
      w.write(raw_at(i));
      AccelSample a;
      a.t_ns = raw_at(i).t_ns;
      a.acc_mps2 = Eigen::Vector3d(0.1 * i, 0.2, 9.81);
      w.write(a);
    }
  }
  const auto size = std::filesystem::file_size(path);
  EXPECT_GT(size, 50u << 20);

  const std::int64_t rss0 = rss_bytes();
  std::int64_t rss_max = rss0;
  io::LogReader reader(path);
  Sample s;
  std::int64_t n = 0;
  double last_progress = 0.0;
  while (reader.next(s)) {
    if ((++n & 0x3FFF) == 0) {
      rss_max = std::max(rss_max, rss_bytes());
      EXPECT_GE(reader.progress(), last_progress);
      last_progress = reader.progress();
    }
  }
  EXPECT_EQ(n, 2 * kLines);
  EXPECT_EQ(reader.stats().skipped_total(), 0);
  EXPECT_DOUBLE_EQ(reader.progress(), 1.0);
  EXPECT_LT(rss_max - rss0, 8 << 20) << "resident memory grew by " << (rss_max - rss0) << " bytes";
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace pdnav
