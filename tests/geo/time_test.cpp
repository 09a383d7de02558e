#include <gtest/gtest.h>

#include "pdnav/geo/time.h"

using namespace pdnav;
using namespace pdnav::geo;

TEST(GnssTime, LeapSecondsKnownDates) {
  EXPECT_EQ(leap_seconds_at_unix_ms(kGpsEpochUnixMs), 0);
  EXPECT_EQ(leap_seconds_at_unix_ms(1471902355999), 17);  // 2016-08-22 (Mountain View log)
  EXPECT_EQ(leap_seconds_at_unix_ms(1483228800000 - 1), 17);
  EXPECT_EQ(leap_seconds_at_unix_ms(1483228800000), 18);  // 2017-01-01
  EXPECT_EQ(leap_seconds_at_unix_ms(1699400582000), 18);  // 2023 (Pixel 7 log)
}

TEST(GnssTime, GpsUnixRoundTripAcrossLeap) {
  for (std::int64_t ms : {kGpsEpochUnixMs, std::int64_t{1471902355999}, std::int64_t{1483228799000},
                          std::int64_t{1483228800000}, std::int64_t{1699400582123}}) {
    EXPECT_EQ(gps_ns_to_unix_ms(unix_ms_to_gps_ns(ms)), ms) << ms;
  }
}

TEST(GnssTime, WeekTowAndRollover) {
  // 2016-08-22 00:00:00 GPST is week 1911, TOW 86400 (RINEX file hour2350.16n).
  const double s = calendar_to_epoch_seconds(2016, 8, 22, 0, 0, 0.0);
  const GpsWeekTow wt = gps_ns_to_week_tow(static_cast<TimeNs>(s) * kNsPerS);
  EXPECT_EQ(wt.week, 1911);
  EXPECT_DOUBLE_EQ(wt.tow_s, 86400.0);
  // 2023-03-14 (day 073) is week 2253, Tuesday.
  const GpsWeekTow w2 = gps_ns_to_week_tow(static_cast<TimeNs>(calendar_to_epoch_seconds(2023, 3, 14, 0, 0, 0)) * kNsPerS);
  EXPECT_EQ(w2.week, 2253);
  EXPECT_DOUBLE_EQ(w2.tow_s, 2 * 86400.0);
  EXPECT_EQ(resolve_week_rollover(1911 % 1024, 1900), 1911);
  EXPECT_EQ(resolve_week_rollover(2253 % 1024, 2250), 2253);
  EXPECT_EQ(resolve_week_rollover(1023, 2048), 2047);
  EXPECT_EQ(week_tow_to_gps_ns(1911, 86400.0), static_cast<TimeNs>(s) * kNsPerS);
  EXPECT_DOUBLE_EQ(wrap_week_s(604000.0), 604000.0 - 604800.0);
}
