// Truth check of the multi-constellation broadcast ephemeris code: broadcast orbits from the
// DLR BRDM RINEX 3.04 file vs CODE precise SP3 orbits (2023-03-14, GPST epochs 00:00-00:10).
// Bars (issue 7): 3D difference <= 5 m GPS and Galileo, <= 10 m GLONASS, every common satellite.
#include <cstdio>

#include <gtest/gtest.h>

#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/orbit_compare.h"
#include "pdnav/gnss/sp3.h"
#include "test_data.h"

namespace pdnav::gnss {
namespace {

const char* kNav = "gnss-orbits-2023-073/BRDM00DLR_S_20230730000_01D_MN.rnx";
const char* kSp3 = "gnss-orbits-2023-073/COD0OPSRAP_20230730000_01D_05M_ORB.SP3";

TEST(OrbitSp3Truth, BroadcastWithinBoundsOfPreciseOrbitsForEveryCommonSatellite) {
  EphemerisStore store;
  const EphemerisLoadReport rep = store.load_rinex_nav(test::shared_data(kNav));
  const Sp3File sp3 = read_sp3_file(test::shared_data(kSp3));
  ASSERT_EQ(sp3.epochs.size(), 3u);
  const auto rows = compare_broadcast_to_sp3(store, sp3);
  std::map<Constellation, int> sats;
  for (const auto& r : rows) {
    std::printf("%s epochs=%d max_3d_m=%.3f rms_3d_m=%.3f max_radial_m=%.3f max_clock_m=%.3f\n",
                r.sat.to_string().c_str(), r.epochs, r.max_3d_m, r.rms_3d_m, r.max_radial_m, r.max_clock_m);
    SCOPED_TRACE(r.sat.to_string());
    EXPECT_EQ(r.missing, 0) << r.last_reason;
    EXPECT_EQ(r.epochs, 3);
    const double bound = r.sat.sys == Constellation::kGlonass ? 10.0 : 5.0;
    EXPECT_LE(r.max_3d_m, bound);
    EXPECT_GT(r.max_3d_m, 0.05) << "suspiciously exact: broadcast (APC) and SP3 (CoM) differ";
    // Clocks (SP3 convention: periodic relativistic term removed). GPS broadcast clocks are
    // ~0.3-1 m; Galileo I/NAV (E1/E5b) vs the SP3 E1/E5a datum adds ~2 m; GLONASS is coarser.
    const double clock_bound = r.sat.sys == Constellation::kGps ? 1.0 : r.sat.sys == Constellation::kGalileo ? 3.0 : 10.0;
    EXPECT_LE(r.max_clock_m, clock_bound);
    ++sats[r.sat.sys];
  }
  // The file holds 2 satellites per system; G01 G02 E01 E02 R01 R02 are in the SP3 too.
  EXPECT_EQ(sats[Constellation::kGps], 2);
  EXPECT_EQ(sats[Constellation::kGalileo], 2);
  EXPECT_EQ(sats[Constellation::kGlonass], 2);
}

TEST(OrbitSp3Truth, Sp3ReaderReadsEpochsInGpsTime) {
  const Sp3File sp3 = read_sp3_file(test::shared_data(kSp3));
  ASSERT_EQ(sp3.epochs.size(), 3u);
  EXPECT_EQ(sp3.time_system, "GPS");
  // Header: GPS week 2253, 172800 s of week; 300 s interval.
  EXPECT_EQ(sp3.epochs[0].gps_ns, (2253LL * 604800 + 172800) * kNsPerS);
  EXPECT_EQ(sp3.epochs[1].gps_ns - sp3.epochs[0].gps_ns, 300 * kNsPerS);
  EXPECT_EQ(sp3.epochs[0].sats.size(), 78u);
  const Sp3Sample& g01 = sp3.epochs[0].sats.at(SatId{Constellation::kGps, 1});
  EXPECT_NEAR(g01.pos.p_m.x(), 21831572.967, 1e-3);
  EXPECT_NEAR(g01.clock_s, 203.089254e-6, 1e-12);
}

}  // namespace
}  // namespace pdnav::gnss
