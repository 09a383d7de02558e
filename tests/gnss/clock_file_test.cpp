// RINEX clock 3.0x reader (issue 15, --clk): a hand-written fixture with known values, linear
// interpolation, the gap limit, counted skips, header errors with file and line, and the
// equivalence with the SP3 clocks (a clock file made from the SP3 clock column gives the same
// satellite states as --sp3 alone; an offset in the clock file moves the clock by exactly it).
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/clock_file.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/sp3.h"
#include "gps_calendar.h"
#include "test_data.h"

namespace pdnav::gnss {
namespace {

TimeNs gps(int h, int mi, double s) { return test::gps_calendar_ns(2021, 4, 28, h, mi, s); }

TEST(ClockFile, ReadsTheHandWrittenFixture) {
  const ClockFile f = read_rinex_clock_file(test::test_data("gnss/clock_3_04_handwritten.clk"));
  EXPECT_DOUBLE_EQ(f.version, 3.04);
  EXPECT_EQ(f.time_system, "GPS");
  const SatId g01{Constellation::kGps, 1}, e11{Constellation::kGalileo, 11}, g02{Constellation::kGps, 2};
  ASSERT_EQ(f.sats.count(g01), 1u);
  ASSERT_EQ(f.sats.at(g01).size(), 3u);  // the repeated 22:00:30 epoch is dropped
  EXPECT_EQ(f.sats.at(g01)[1].gps_ns, gps(22, 0, 30.0));
  EXPECT_DOUBLE_EQ(f.sats.at(g01)[1].clock_s, 1.0000003e-4);
  EXPECT_DOUBLE_EQ(f.sats.at(g01)[0].sigma_s, 1e-11);
  EXPECT_EQ(f.sats.at(g01)[2].sigma_s, -1.0);  // one value only
  ASSERT_EQ(f.sats.at(e11).size(), 2u);        // the continuation line was not read as a record
  EXPECT_DOUBLE_EQ(f.sats.at(e11)[1].clock_s, -2.50003e-4);
  EXPECT_EQ(f.sats.count(SatId{Constellation::kGps, 3}), 0u);
  EXPECT_EQ(f.records, 7);
  EXPECT_EQ(f.skipped.at("AR: not a satellite clock (AR)"), 1);
  EXPECT_EQ(f.skipped.at("AS: bad clock value"), 1);
  EXPECT_EQ(f.skipped.at("AS: repeated epoch"), 1);
  EXPECT_EQ(f.skipped_total(), 3);

  // known interpolated values
  ClockInterpolationOptions opt;
  double c = 0, r = 0;
  std::string why;
  ASSERT_TRUE(interpolate_clock(f.sats.at(g01), gps(22, 0, 15.0), opt, c, r, &why)) << why;
  EXPECT_NEAR(c, 1.00000015e-4, 1e-17);
  EXPECT_NEAR(r, 3e-11 / 30.0, 1e-20);
  ASSERT_TRUE(interpolate_clock(f.sats.at(g01), gps(22, 0, 45.0), opt, c, r, &why)) << why;
  EXPECT_NEAR(c, 1.0000006e-4, 1e-17);  // second interval: 3e-11 -> 9e-11
  ASSERT_TRUE(interpolate_clock(f.sats.at(g01), gps(22, 1, 0.0), opt, c, r, &why)) << why;  // last sample
  EXPECT_NEAR(c, 1.0000009e-4, 1e-17);
  ASSERT_TRUE(interpolate_clock(f.sats.at(e11), gps(22, 1, 0.0), opt, c, r, &why)) << why;  // 5 min interval
  EXPECT_NEAR(c, -2.5e-4 - 3e-9 / 5.0, 1e-17);
  // refusals with reasons
  EXPECT_FALSE(interpolate_clock(f.sats.at(g02), gps(22, 5, 0.0), opt, c, r, &why));
  EXPECT_EQ(why, "gap in the precise clock");
  EXPECT_FALSE(interpolate_clock(f.sats.at(g01), gps(22, 1, 1.0), opt, c, r, &why));
  EXPECT_EQ(why, "outside the clock file span");
  opt.max_interval_s = 700.0;  // a stated limit: raised, the 10-minute gap is bridged
  EXPECT_TRUE(interpolate_clock(f.sats.at(g02), gps(22, 5, 0.0), opt, c, r, &why));
  EXPECT_NEAR(c, 5.0003e-5, 1e-17);
}

std::string header(const std::string& version_line, const std::string& time_system = "GPS") {
  char ts[128];
  std::snprintf(ts, sizeof ts, "%-60s%s\n", time_system.c_str(), "TIME SYSTEM ID");
  char end[128];
  std::snprintf(end, sizeof end, "%-60s%s\n", "", "END OF HEADER");
  return version_line + ts + end;
}

const std::string kV304 = "     3.04           C                   M                   RINEX VERSION / TYPE\n";

void expect_error(const std::string& text, const std::string& needle) {
  std::istringstream in(text);
  try {
    read_rinex_clock(in, "x.clk");
    ADD_FAILURE() << "no error for: " << needle;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(ClockFile, HeaderErrorsNameFileAndLine) {
  expect_error("", "x.clk:0: empty file");
  expect_error("     3.04           O                   M                   RINEX VERSION / TYPE\n", "x.clk:1: RINEX file type is not C");
  expect_error("     2.00           C                   M                   RINEX VERSION / TYPE\n", "x.clk:1: unsupported RINEX clock version");
  expect_error("AS G01  2021 04 28 22 00  0.000000  1  1.0E-04\n", "x.clk:1: not a RINEX clock file");
  expect_error(kV304 + "just a comment\n", "x.clk:2: no END OF HEADER");
  expect_error(header(kV304, "GLO"), "x.clk:2: unsupported TIME SYSTEM ID 'GLO'");
}

TEST(ClockFile, UtcTimeSystemAndBadRecordsAreCounted) {
  const std::string body =
      "AS G07       2021 04 28 22 00  0.000000  1  2.000000000000E-05\n"
      "AS G07       2021 13 28 22 00  0.000000  1  2.000000000000E-05\n"
      "AS X07       2021 04 28 22 00  0.000000  1  2.000000000000E-05\n"
      "AS G07       2021 04 28\n"
      "ZZ whatever\n"
      "AS G07       2021 04 28 22 00 30.000000  9  2.000000000000E-05\n";
  std::istringstream in(header(kV304, "UTC") + body);
  const ClockFile f = read_rinex_clock(in, "u.clk");
  const SatId g07{Constellation::kGps, 7};
  ASSERT_EQ(f.sats.at(g07).size(), 1u);
  EXPECT_EQ(f.sats.at(g07)[0].gps_ns, gps(22, 0, 18.0));  // UTC + 18 leap seconds
  EXPECT_EQ(f.skipped.at("AS: bad epoch"), 1);
  EXPECT_EQ(f.skipped.at("AS: bad satellite name 'X07'"), 1);
  EXPECT_EQ(f.skipped.at("AS: too few fields"), 1);
  EXPECT_EQ(f.skipped.at("unknown record type"), 1);
  EXPECT_EQ(f.skipped.at("AS: bad number of data values"), 1);
}

/// The SP3 clock column as a clock file (same epochs).
ClockFile clock_file_from_sp3(const Sp3File& sp3, const SatId& offset_sat, double offset_s) {
  ClockFile f;
  for (const Sp3Epoch& e : sp3.epochs)
    for (const auto& [sat, s] : e.sats)
      if (s.has_clock) f.sats[sat].push_back(ClockSample{e.gps_ns, s.clock_s + (sat == offset_sat ? offset_s : 0.0), -1.0});
  return f;
}

TEST(ClockFile, ClockFileFromTheSp3ClocksGivesTheSp3States) {
  const Sp3File sp3 = read_sp3_file(test::shared_data("gnss-gsdc2021-pixel5/COD0MGXFIN_20211180000_01D_05M_ORB.SP3"));
  EphemerisStore a, b;
  ASSERT_GT(a.add_precise(sp3), 100);
  b.add_precise(sp3);
  const SatId g05{Constellation::kGps, 5};
  const SatId e11{Constellation::kGalileo, 11};
  EXPECT_GT(b.add_precise_clocks(clock_file_from_sp3(sp3, e11, 1e-6)), 100);
  const TimeNs t0 = gps(22, 19, 22.43);
  int compared = 0;
  for (const SatId& sat : a.satellites()) {
    for (int k = 0; k < 20; ++k) {
      const TimeNs t = t0 + static_cast<TimeNs>(k) * 47'300'000'000;  // across several 5-min epochs
      std::string why_a, why_b;
      const auto sa = a.state(sat, t, &why_a);
      const auto sb = b.state(sat, t, &why_b);
      ASSERT_EQ(sa.has_value(), sb.has_value()) << sat.to_string() << " " << why_a << " / " << why_b;
      if (!sa) continue;
      const double expected = sat == e11 ? 1e-6 : 0.0;
      EXPECT_NEAR(sb->clock_bias_s - sa->clock_bias_s, expected, 1e-15) << sat.to_string();
      EXPECT_NEAR(sb->clock_drift_sps, sa->clock_drift_sps, 1e-18) << sat.to_string();
      EXPECT_EQ((sb->pos.p_m - sa->pos.p_m).norm(), 0.0);
      ++compared;
    }
  }
  EXPECT_GT(compared, 1000);
  // a clock file with a gap makes that satellite's precise state refuse (no silent SP3 clock)
  ClockFile gap = clock_file_from_sp3(sp3, e11, 0.0);
  auto& v = gap.sats.at(g05);
  const auto it = std::find_if(v.begin(), v.end(), [&](const ClockSample& s) { return s.gps_ns > t0; });
  ASSERT_NE(it, v.end());
  v.erase(it);
  EphemerisStore c;
  c.add_precise(sp3);
  c.add_precise_clocks(gap);
  std::string why;
  EXPECT_FALSE(c.state(g05, t0, &why).has_value());  // no broadcast loaded either
  EXPECT_TRUE(c.state(e11, t0, &why).has_value()) << why;
}

}  // namespace
}  // namespace pdnav::gnss
