// EphemerisStore: selection, time scales, reasons, and self-consistency on real files.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include <gtest/gtest.h>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/rinex.h"
#include "gps_calendar.h"
#include "test_data.h"

namespace pdnav::gnss {
namespace {

const char* kBrdm = "gnss-orbits-2023-073/BRDM00DLR_S_20230730000_01D_MN.rnx";
const char* kHour = "gnss-mountainview/hour2350.16n";

/// Position of `sat` at `t` from the record with reference time `ref` only.
template <typename Eph>
double switch_jump_m(const std::vector<Eph>& records, const SatId& sat, TimeNs t,
                     SatState (*eval)(const Eph&, TimeNs)) {
  std::vector<Eigen::Vector3d> p;
  for (const auto& r : records)
    if (r.sat == sat) p.push_back(eval(r, t).pos.p_m);
  EXPECT_GE(p.size(), 2u);
  double worst = 0;
  for (std::size_t i = 1; i < p.size(); ++i) worst = std::max(worst, (p[i] - p[0]).norm());
  return worst;
}

// hour2350.16n: consecutive GPS ephemerides of one PRN must agree at the switch time.
TEST(EphemerisConsistency, AdjacentGpsEphemeridesAgreeAtSwitchTime) {
  const RinexNavData nav = read_rinex_nav_file(test::shared_data(kHour));
  std::map<SatId, std::vector<KeplerEphemeris>> by_sat;
  for (const auto& k : nav.kepler) by_sat[k.sat].push_back(k);
  int pairs = 0;
  std::vector<double> clock_jumps_m;
  for (const auto& [sat, list] : by_sat) {
    for (std::size_t i = 1; i < list.size(); ++i) {
      const KeplerEphemeris& a = list[i - 1];
      const KeplerEphemeris& b = list[i];
      if (b.toe_gps_ns - a.toe_gps_ns > 4 * 3600 * kNsPerS || b.toe_gps_ns <= a.toe_gps_ns) continue;
      const TimeNs t = b.toe_gps_ns;  // switch to the newer set at its toe
      const SatState sa = kepler_state(a, t), sb = kepler_state(b, t);
      SCOPED_TRACE(sat.to_string());
      EXPECT_LT((sa.pos.p_m - sb.pos.p_m).norm(), 5.0);
      clock_jumps_m.push_back(std::abs(sa.clock_bias_s - sb.clock_bias_s) * kSpeedOfLight_mps);
      EXPECT_LT((sa.vel_mps - sb.vel_mps).norm(), 0.01);
      ++pairs;
    }
  }
  EXPECT_GT(pairs, 300);
  // Clock continuity at uploads: typically dm; the old Block IIR G11 jumps by up to ~10 m.
  std::sort(clock_jumps_m.begin(), clock_jumps_m.end());
  EXPECT_LT(clock_jumps_m[clock_jumps_m.size() / 2], 0.5);
  EXPECT_LT(clock_jumps_m[clock_jumps_m.size() * 95 / 100], 2.0);
  EXPECT_LT(clock_jumps_m.back(), 12.0);
}

TEST(EphemerisConsistency, AdjacentGlonassBdsQzssRecordsAgreeBetweenReferenceTimes) {
  const RinexNavData nav = read_rinex_nav_file(test::shared_data(kBrdm));
  int checked = 0;
  for (std::size_t i = 1; i < nav.glonass.size(); ++i) {
    const auto& a = nav.glonass[i - 1];
    const auto& b = nav.glonass[i];
    if (!(a.sat == b.sat) || b.tb_gps_ns - a.tb_gps_ns != 1800 * kNsPerS) continue;
    const TimeNs mid = a.tb_gps_ns + 900 * kNsPerS;  // both records are at their +-15 min limit
    const double jump = (glonass_state(a, mid).pos.p_m - glonass_state(b, mid).pos.p_m).norm();
    EXPECT_LT(jump, 10.0) << a.sat.to_string();
    ++checked;
  }
  for (std::size_t i = 1; i < nav.kepler.size(); ++i) {
    const auto& a = nav.kepler[i - 1];
    const auto& b = nav.kepler[i];
    if (!(a.sat == b.sat) || (a.sat.sys != Constellation::kBeidou && a.sat.sys != Constellation::kQzss)) continue;
    const TimeNs mid = (a.toe_gps_ns + b.toe_gps_ns) / 2;
    const double jump = (kepler_state(a, mid).pos.p_m - kepler_state(b, mid).pos.p_m).norm();
    EXPECT_LT(jump, 10.0) << a.sat.to_string();
    ++checked;
  }
  EXPECT_GE(checked, 10);
}

// BeiDou C01/C02 are GEO satellites (BDS-SIS-ICD 5.2.4.12: extra -5 deg rotation about X).
// Known answer of a geostationary orbit: radius 42164 km, latitude within the ~2 deg
// inclination, longitude fixed to < 0.5 deg over 2 h. Treating them with the MEO formula
// swings the latitude by ~5 deg and the ECEF speed to hundreds of m/s.
TEST(EphemerisStore, BeidouGeoSatellitesStayGeostationary) {
  EphemerisStore store;
  store.load_rinex_nav(test::shared_data(kBrdm));
  for (int prn : {1, 2}) {
    SCOPED_TRACE(prn);
    double lon0 = 0;
    for (int minute = 0; minute <= 120; minute += 15) {
      std::string why;
      const auto s = store.state(SatId{Constellation::kBeidou, prn}, test::gps_calendar_ns(2023, 3, 14, 0, minute, 0.0), &why);
      ASSERT_TRUE(s) << why;
      const double r = s->pos.p_m.norm();
      EXPECT_NEAR(r, 42164e3, 30e3);
      const double lon = std::atan2(s->pos.p_m.y(), s->pos.p_m.x()) * kRadToDeg;
      if (minute == 0) lon0 = lon;
      EXPECT_NEAR(lon, lon0, 0.5);
      EXPECT_NEAR(std::asin(s->pos.p_m.z() / r) * kRadToDeg, 0.0, 2.0);
      EXPECT_LT(s->vel_mps.norm(), 150.0);
      EXPECT_NE(s->group_delay_s, 0.0);  // TGD1
    }
    std::printf("C%02d longitude %.2f deg\n", prn, lon0);
  }
  // Same elements through the MEO/IGSO formula: the known-wrong answer is far off (the test
  // above can tell the two apart).
  const RinexNavData nav = read_rinex_nav_file(test::shared_data(kBrdm));
  int geo_records = 0;
  for (const KeplerEphemeris& k : nav.kepler) {
    if (!k.bds_geo) continue;
    KeplerEphemeris meo = k;
    meo.bds_geo = false;
    const TimeNs t = k.toe_gps_ns + 1800 * kNsPerS;
    EXPECT_GT((kepler_state(meo, t).pos.p_m - kepler_state(k, t).pos.p_m).norm(), 100e3) << k.sat.to_string();
    ++geo_records;
  }
  EXPECT_EQ(geo_records, 6);
}

TEST(EphemerisStore, ReasonsForMissingStaleUnsupportedAndUnhealthy) {
  EphemerisStore store;
  store.load_rinex_nav(test::shared_data(kBrdm));
  const TimeNs t = test::gps_calendar_ns(2023, 3, 14, 0, 5, 0.0);
  std::string why;
  EXPECT_TRUE(store.state(SatId{Constellation::kGps, 1}, t, &why)) << why;
  EXPECT_FALSE(store.state(SatId{Constellation::kGps, 30}, t, &why));
  EXPECT_EQ(why, "no ephemeris");
  EXPECT_FALSE(store.state(SatId{Constellation::kGps, 1}, t + 3 * geo::kNsPerDay, &why));
  EXPECT_EQ(why, "stale ephemeris");
  EXPECT_FALSE(store.state(SatId{Constellation::kGlonass, 1}, t + 3 * 3600 * kNsPerS, &why));
  EXPECT_EQ(why, "stale ephemeris");
  EXPECT_FALSE(store.state(SatId{Constellation::kIrnss, 2}, t, &why));
  EXPECT_EQ(why, "unsupported constellation");
  // Unhealthy: the same record with a health flag set is refused unless accepted.
  const RinexNavData nav = read_rinex_nav_file(test::shared_data(kBrdm));
  KeplerEphemeris sick = nav.kepler.front();
  sick.health = 1;
  EphemerisStore strict;
  strict.add(sick);
  EXPECT_FALSE(strict.state(sick.sat, sick.toe_gps_ns, &why));
  EXPECT_EQ(why, "unhealthy");
  EphemerisStoreOptions lax;
  lax.accept_unhealthy = true;
  EphemerisStore tolerant(lax);
  tolerant.add(sick);
  const auto st = tolerant.state(sick.sat, sick.toe_gps_ns, &why);
  ASSERT_TRUE(st);
  EXPECT_FALSE(st->healthy);
}

}  // namespace
}  // namespace pdnav::gnss
