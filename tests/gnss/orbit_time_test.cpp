// Time-scale handling inside the ephemeris code: GPS week rollover (toe in the next week,
// 10-bit LNAV week), leap seconds at a GLONASS (UTC) day boundary, BeiDou BDT = GPST - 14 s.
#include <sstream>

#include <gtest/gtest.h>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/rinex.h"
#include "gps_calendar.h"

namespace pdnav::gnss {
namespace {

RinexNavData parse(const std::string& text) {
  std::istringstream in(text);
  return read_rinex_nav(in, "mem.rnx");
}

const char* kHeader3 =
    "     3.04           NAVIGATION DATA     M                   RINEX VERSION / TYPE\n"
    "                                                            END OF HEADER       \n";

std::string kepler_record(const std::string& sat_epoch, const std::string& toe_field) {
  return sat_epoch +
         " 2.030883915722e-04-3.865352482535e-12 0.000000000000e+00\n"
         "     1.200000000000e+01-7.940625000000e+01 3.783729036073e-09 2.407791404577e+00\n"
         "    -4.297122359276e-06 1.251155254431e-02 6.118789315224e-06 5.153655818939e+03\n"
         "    " + toe_field + "-5.587935447693e-09-2.637111594763e+00-1.918524503708e-07\n"
         "     9.847149365104e-01 2.361875000000e+02 1.023197438990e+00-8.031048659028e-09\n"
         "     4.928776451804e-10 1.000000000000e+00 2.253000000000e+03 0.000000000000e+00\n"
         "     2.000000000000e+00 0.000000000000e+00 4.656612873077e-10 1.200000000000e+01\n"
         "     1.655580000000e+05\n";
}

std::string glonass_record(const std::string& epoch) {
  return "R01 " + epoch +
         " 2.470612525940e-05 0.000000000000e+00 1.728300000000e+05\n"
         "     5.763751464844e+03-1.299090385437e+00 0.000000000000e+00 0.000000000000e+00\n"
         "     1.183432617188e+04 2.693783760071e+00-9.313225746155e-10 1.000000000000e+00\n"
         "     2.185887109375e+04-1.114941596985e+00-2.793967723846e-09 0.000000000000e+00\n";
}

TEST(OrbitTime, GpsToeInTheNextWeekIsNotAWeekEarlier) {
  // 2023-03-18 23:59:44 is Saturday, week 2253 sow 604784; toe = 0 belongs to week 2254.
  const RinexNavData nav = parse(std::string(kHeader3) +
                                 kepler_record("G01 2023 03 18 23 59 44", " 0.000000000000e+00"));
  ASSERT_EQ(nav.kepler.size(), 1u);
  EXPECT_EQ(nav.kepler[0].toc_gps_ns, geo::week_tow_to_gps_ns(2253, 604784.0));
  EXPECT_EQ(nav.kepler[0].toe_gps_ns, geo::week_tow_to_gps_ns(2254, 0.0));
  // And a state just after the week boundary uses tk = +10 s, not -604790 s.
  EphemerisStore store;
  store.add(nav.kepler[0]);
  std::string why;
  EXPECT_TRUE(store.state(nav.kepler[0].sat, geo::week_tow_to_gps_ns(2254, 10.0), &why)) << why;
}

TEST(OrbitTime, TenBitWeekResolvesAcrossRollovers) {
  EXPECT_EQ(geo::resolve_week_rollover(2253 % 1024, 2253), 2253);
  EXPECT_EQ(geo::resolve_week_rollover(1023, 1024), 1023);   // just before the 1999 rollover
  EXPECT_EQ(geo::resolve_week_rollover(0, 2047), 2048);      // 2019-04-07 rollover
  EXPECT_EQ(geo::resolve_week_rollover(1911 % 1024, 1911), 1911);
}

TEST(OrbitTime, GlonassUtcEpochsAcrossTheEnd2016LeapSecond) {
  // GPS-UTC was 17 s until 2016-12-31 23:59:60 UTC and 18 s after (IERS Bulletin C 52).
  const RinexNavData nav = parse(std::string(kHeader3) + glonass_record("2016 12 31 23 45 00") +
                                 glonass_record("2017 01 01 00 15 00"));
  ASSERT_EQ(nav.glonass.size(), 2u);
  EXPECT_EQ(nav.glonass[0].tb_gps_ns, test::gps_calendar_ns(2016, 12, 31, 23, 45, 17.0));
  EXPECT_EQ(nav.glonass[1].tb_gps_ns, test::gps_calendar_ns(2017, 1, 1, 0, 15, 18.0));
  EXPECT_EQ(nav.glonass[1].tb_gps_ns - nav.glonass[0].tb_gps_ns, 1801 * kNsPerS);
  // Across the UTC day boundary the nearest record is chosen by GPS time: at 00:05:00 GPST
  // the 00:15 UTC record (10 min 18 s away) wins over the 23:45 UTC one (19 min 43 s away).
  EphemerisStore store;
  for (const auto& g : nav.glonass) store.add(g);
  std::string why;
  const auto s = store.state(SatId{Constellation::kGlonass, 1}, test::gps_calendar_ns(2017, 1, 1, 0, 5, 0.0), &why);
  ASSERT_TRUE(s) << why;
  EXPECT_EQ(s->toe_gps_ns, nav.glonass[1].tb_gps_ns);
  EXPECT_EQ(s->glonass_channel, 1);
}

TEST(OrbitTime, BeidouEpochsAreBdtAndWeeksAlignWithTheBdtWeek) {
  // BDT 2023-03-14 00:00:00 (toe 172800 s of BDT week 897) = GPST 00:00:14 of GPS week 2253.
  std::string rec = kepler_record("C11 2023 03 14 00 00 00",  " 1.728000000000e+05");
  const RinexNavData nav = parse(std::string(kHeader3) + rec);
  ASSERT_EQ(nav.kepler.size(), 1u);
  EXPECT_EQ(nav.kepler[0].toe_gps_ns, geo::week_tow_to_gps_ns(2253, 172814.0));
  EXPECT_EQ(nav.kepler[0].toe_gps_ns - geo::kBdsEpochMinusGpsEpochS * kNsPerS,
            static_cast<TimeNs>(897) * geo::kNsPerWeek + 172800 * kNsPerS);
  EXPECT_FALSE(nav.kepler[0].bds_geo);
}

}  // namespace
}  // namespace pdnav::gnss
