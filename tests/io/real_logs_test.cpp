// The two real GnssLogger logs (v1.4 and v3) parse completely, with exact counts, exact
// 64-bit integers, and times placed on the elapsed timeline as docs/log-format.md says.
#include <cmath>

#include <gtest/gtest.h>

#include "io_test_util.h"
#include "pdnav/geo/time.h"
#include "pdnav/io/log_format.h"
#include "pdnav/io/log_writer.h"
#include "test_data.h"

namespace pdnav {
namespace {

struct Loaded {
  std::vector<Sample> samples;
  io::ReadStats stats;
  std::map<std::string, std::string> header;
};

Loaded load(const std::string& path) {
  io::LogReader reader(path);
  Loaded l;
  Sample s;
  while (reader.next(s)) l.samples.push_back(s);
  EXPECT_DOUBLE_EQ(reader.progress(), 1.0);
  l.stats = reader.stats();
  l.header = reader.header_info();
  return l;
}

std::int64_t count(const io::ReadStats& st, const std::string& type) {
  auto it = st.samples_by_type.find(type);
  return it == st.samples_by_type.end() ? 0 : it->second;
}

/// UTC (ns) of a Raw line from its clock, computed here independently of the reader.
std::int64_t clock_utc_ns(const GnssRawSample& r) {
  const std::int64_t gps_ns = r.time_nanos - r.full_bias_nanos - std::llround(r.bias_nanos);
  return gps_ns + geo::kGpsEpochUnixMs * kNsPerMs - geo::leap_seconds_at_gps_ns(gps_ns) * kNsPerS;
}

TEST(RealLogs, MountainViewV14ParsesWithOnlyTheFixBeforeAnyTimeBaseSkipped) {
  const Loaded l = load(test::shared_data("gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt"));
  // grep -c '^Raw,' = 5041, grep -c '^Fix,' = 207; wc -l = 5259
  EXPECT_EQ(l.stats.lines, 5259);
  EXPECT_EQ(count(l.stats, "Raw"), 5041);
  EXPECT_EQ(count(l.stats, "Fix"), 206);
  EXPECT_EQ(l.stats.samples, 5041 + 206);
  EXPECT_EQ(l.stats.skipped_total(), 1);
  EXPECT_EQ(test::skipped(l.stats, "no elapsed-time base yet"), 1);
  ASSERT_EQ(l.stats.issues.size(), 1u);
  EXPECT_EQ(l.stats.issues[0].line, 12);  // the first Fix precedes every Raw line
  EXPECT_EQ(l.header.at("Version"), "1.4.0.0");
  EXPECT_EQ(l.header.at("Platform"), "N");

  const auto& r0 = std::get<GnssRawSample>(l.samples.at(0));
  EXPECT_EQ(r0.t_ns, 344412380LL * kNsPerMs);  // ElapsedRealtimeMillis
  EXPECT_EQ(r0.time_nanos, 10084000000);
  EXPECT_EQ(r0.full_bias_nanos, -1155937562915873645);
  EXPECT_EQ(r0.received_sv_time_nanos, 164772920063716);
  EXPECT_EQ(r0.received_sv_time_uncertainty_nanos, 16);
  EXPECT_EQ(r0.svid, 2);
  EXPECT_EQ(r0.state, 39);
  EXPECT_EQ(r0.constellation_type, 1);
  EXPECT_EQ(r0.cn0_dbhz, 34.9620475769043);
  EXPECT_EQ(r0.accumulated_delta_range_uncertainty_m, 0.0016227936139330268);
  EXPECT_EQ(r0.leap_second, kMissingInt);
  EXPECT_TRUE(std::isnan(r0.carrier_frequency_hz));
  EXPECT_EQ(r0.utc_ms, kMissingInt);

  // Every Fix is mapped through the offset of the Raw line just before it.
  const GnssRawSample* last_raw = nullptr;
  int fixes = 0;
  for (const Sample& s : l.samples) {
    if (const auto* r = std::get_if<GnssRawSample>(&s)) last_raw = r;
    if (const auto* f = std::get_if<FixSample>(&s)) {
      ASSERT_NE(last_raw, nullptr);
      EXPECT_EQ(f->t_ns, last_raw->t_ns + (f->utc_ms * kNsPerMs - clock_utc_ns(*last_raw)));
      EXPECT_EQ(f->provider, "gps");
      EXPECT_TRUE(std::isnan(f->bearing_deg));
      ++fixes;
    }
  }
  EXPECT_EQ(fixes, 206);
  const auto& f0 = std::get<FixSample>(l.samples.at(22));  // file line 35
  EXPECT_EQ(f0.utc_ms, 1471902356999);
  EXPECT_EQ(f0.lat_deg, 37.422596);
  EXPECT_EQ(f0.lon_deg, -122.081712);
  EXPECT_EQ(f0.alt_m, -19.384802);
  EXPECT_EQ(f0.accuracy_m, 4.0);
  // 344412386 ms elapsed <-> 1471902355.999873645 s UTC (GPS - 17 leap s), fix 0.999126355 s later
  EXPECT_EQ(f0.t_ns, 344413385126355);
}

TEST(RealLogs, Pixel7V3ParsesEveryLineWithNothingSkipped) {
  const Loaded l = load(test::shared_data("gnss-pixel7-format/gnsslogger_v3_pixel7.txt"));
  EXPECT_EQ(l.stats.lines, 1322);
  EXPECT_EQ(l.stats.skipped_total(), 0) << (l.stats.issues.empty() ? "" : l.stats.issues[0].to_string());
  // grep -c: Raw 930, Fix 243, Agc 80, 10 each of UncalAccel/UncalGyro/UncalMag/OrientationDeg
  EXPECT_EQ(count(l.stats, "Raw"), 930);
  EXPECT_EQ(count(l.stats, "Fix"), 243);
  EXPECT_EQ(count(l.stats, "Agc"), 80);
  EXPECT_EQ(count(l.stats, "UncalAccel"), 10);
  EXPECT_EQ(count(l.stats, "UncalGyro"), 10);
  EXPECT_EQ(count(l.stats, "UncalMag"), 10);
  EXPECT_EQ(count(l.stats, "OrientationDeg"), 10);
  EXPECT_EQ(l.stats.samples, 1293);
  EXPECT_EQ(l.header.at("Version"), "v3.0.6.4");
  EXPECT_EQ(l.header.at("Model"), "Pixel 7");
  EXPECT_EQ(l.header.at("Manufacturer"), "Google");

  const auto& fix = std::get<FixSample>(l.samples.at(0));
  EXPECT_EQ(fix.provider, "GPS");
  EXPECT_EQ(fix.t_ns, 16124559129000);
  EXPECT_EQ(fix.lat_deg, 37.4265079783);
  EXPECT_EQ(fix.vertical_accuracy_m, 3.0);
  EXPECT_TRUE(std::isnan(fix.bearing_deg));

  const auto& raw = std::get<GnssRawSample>(l.samples.at(5));
  EXPECT_EQ(raw.t_ns, 16136559319000);  // ChipsetElapsedRealtimeNanos
  EXPECT_EQ(raw.utc_ms, 1699400594000);
  EXPECT_EQ(raw.full_bias_nanos, -1383435750910273353);
  EXPECT_EQ(raw.received_sv_time_nanos, 258211922049091);
  EXPECT_EQ(raw.accumulated_delta_range_uncertainty_m, 3.4028234663852886e38);
  EXPECT_EQ(raw.code_type, "C");
  EXPECT_EQ(raw.baseband_cn0_dbhz, 25.324739456176758);
  EXPECT_EQ(raw.full_inter_signal_bias_nanos, -0.20372681261465636);
  EXPECT_EQ(clock_utc_ns(raw) / kNsPerMs, raw.utc_ms);  // the clock and utcTimeMillis agree

  // Agc lines have no elapsed column: mapped through the latest Raw clock offset.
  const GnssRawSample* last_raw = nullptr;
  int agc = 0;
  for (const Sample& s : l.samples) {
    if (const auto* r = std::get_if<GnssRawSample>(&s)) last_raw = r;
    if (const auto* a = std::get_if<AgcSample>(&s)) {
      ASSERT_NE(last_raw, nullptr);
      EXPECT_EQ(a->t_ns, last_raw->t_ns + (a->utc_ms * kNsPerMs - clock_utc_ns(*last_raw)));
      ++agc;
    }
  }
  EXPECT_EQ(agc, 80);
}

TEST(RealLogs, ExcerptFixturesMatchTheirSourceNote) {
  const Loaded mv = load(test::test_data("logs/mountainview_v1_4_excerpt.txt"));
  EXPECT_EQ(count(mv.stats, "Raw"), 68);
  EXPECT_EQ(count(mv.stats, "Fix"), 2);
  EXPECT_EQ(test::skipped(mv.stats, "no elapsed-time base yet"), 1);
  const Loaded p7 = load(test::test_data("logs/pixel7_v3_excerpt.txt"));
  EXPECT_EQ(p7.stats.samples, 90 + 30 + 8 + 4);
  EXPECT_EQ(p7.stats.skipped_total(), 0);
}

TEST(RealLogs, SessionLogRewriteOfARealLogReadsBackIdentically) {
  const Loaded l = load(test::test_data("logs/pixel7_v3_excerpt.txt"));
  std::string text = io::log_header("Pixel 7");
  for (const Sample& s : l.samples) text += io::format_line(s) + "\n";
  const test::ReadResult r = test::read_text(text);
  ASSERT_EQ(r.samples.size(), l.samples.size());
  EXPECT_EQ(r.stats.skipped_total(), 0);
  for (std::size_t i = 0; i < r.samples.size(); ++i) EXPECT_TRUE(io::same_sample(r.samples[i], l.samples[i])) << i;
}

}  // namespace
}  // namespace pdnav
