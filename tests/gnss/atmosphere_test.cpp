// Known-answer tests of the atmospheric models and look angles.
#include <cmath>

#include <gtest/gtest.h>

#include "pdnav/geo/units.h"
#include "pdnav/gnss/atmosphere.h"

namespace pdnav::gnss {
namespace {

KlobucharParams toolbox_params() {
  KlobucharParams p;
  p.alpha = {0.382e-07, 0.149e-07, -0.179e-06, 0.0};
  p.beta = {0.143e+06, 0.0, -0.328e+06, 0.113e+06};
  return p;
}

// Source: GPS Toolbox, Ola Ovstedal's Klobuchar programs (https://www.ngs.noaa.gov/gps-toolbox/ovstedal.htm),
// test case: lat 40 deg, lon 260 deg, az 210 deg, el 20 deg, t = 593100 s -> 23.784 m on L1.
TEST(Klobuchar, MatchesGpsToolboxWorkedExample) {
  const auto rx = geo::Geodetic::from_deg(40.0, 260.0, 0.0);
  const double d_s = klobuchar_delay_s(toolbox_params(), rx, deg_to_rad(210.0), deg_to_rad(20.0), 593100.0);
  EXPECT_NEAR(d_s * kSpeedOfLight_mps, 23.784, 2e-3);
}

TEST(Klobuchar, NightTimeFloorIsFiveNanosecondsTimesObliquity) {
  // Local time at the pierce point near 02:00 -> |x| >= 1.57 -> F * 5 ns (IS-GPS-200 Figure 20-4).
  const auto rx = geo::Geodetic::from_deg(0.0, 0.0, 0.0);
  const double zenith = klobuchar_delay_s(toolbox_params(), rx, 0.0, deg_to_rad(90.0), 2 * 3600.0);
  EXPECT_NEAR(zenith, (1.0 + 16.0 * std::pow(0.53 - 0.5, 3)) * 5e-9, 1e-15);
}

TEST(Klobuchar, DelayGrowsTowardsTheHorizonAndNeverNegative) {
  const auto rx = geo::Geodetic::from_deg(37.42, -122.08, 0.0);
  double prev = 0.0;
  for (double el_deg = 90.0; el_deg >= 0.0; el_deg -= 5.0) {
    const double d = klobuchar_delay_s(toolbox_params(), rx, 1.0, deg_to_rad(el_deg), 50400.0);
    EXPECT_GT(d, 0.0);
    EXPECT_GE(d, prev);
    prev = d;
  }
  EXPECT_LT(prev * kSpeedOfLight_mps, 100.0);
}

// Standard atmosphere: US Standard Atmosphere 1976 gives 1013.25 hPa at 0 m and 898.76 hPa at
// 1000 m; the Saastamoinen hydrostatic delay (IERS Conventions 2010 eq. 9.11) is
// 0.0022768 P / (1 - 0.00266 cos 2phi - 0.28e-6 H): 2.3070 m at sea level, latitude 45 deg.
TEST(Saastamoinen, HydrostaticZenithDelayMatchesPublishedValues) {
  const auto z45 = saastamoinen_zenith(geo::Geodetic::from_deg(45.0, 0.0, 0.0), 0.0);
  EXPECT_NEAR(z45.hydrostatic_m, 0.0022768 * 1013.25, 1e-6);
  EXPECT_NEAR(z45.hydrostatic_m, 2.3070, 1e-4);
  EXPECT_NEAR(z45.wet_m, 0.0, 1e-12);
  const auto z1000 = saastamoinen_zenith(geo::Geodetic::from_deg(45.0, 0.0, 1000.0), 0.0);
  EXPECT_NEAR(z1000.hydrostatic_m, 0.0022768 * 898.76 / (1.0 - 0.28e-3), 2e-4);
  const auto z0 = saastamoinen_zenith(geo::Geodetic::from_deg(0.0, 0.0, 0.0), 0.0);
  EXPECT_NEAR(z0.hydrostatic_m, 2.30697 / (1.0 - 0.00266), 1e-4);  // 2.3131 m at the equator
}

TEST(Saastamoinen, WetDelayAndSlantDelayAreInThePublishedRange) {
  // Zenith wet delay at sea level, 15 C, 70 % humidity: ~0.1-0.2 m (Saastamoinen 1972 magnitudes).
  const auto z = saastamoinen_zenith(geo::Geodetic::from_deg(45.0, 0.0, 0.0), 0.7);
  EXPECT_GT(z.wet_m, 0.08);
  EXPECT_LT(z.wet_m, 0.20);
  const auto rx = geo::Geodetic::from_deg(45.0, 0.0, 0.0);
  EXPECT_NEAR(saastamoinen_delay_m(rx, deg_to_rad(90.0)), (z.hydrostatic_m + z.wet_m) * 1.001 / std::sqrt(1.002001),
              1e-9);
  // RTCA DO-229 mapping: m(5 deg) = 1.001 / sqrt(0.002001 + sin^2 5deg) = 10.2177.
  EXPECT_NEAR(troposphere_mapping(deg_to_rad(5.0)), 10.2177, 1e-3);
  EXPECT_TRUE(std::isfinite(saastamoinen_delay_m(rx, deg_to_rad(-10.0))));
  EXPECT_TRUE(std::isfinite(saastamoinen_delay_m(geo::Geodetic::from_deg(45.0, 0.0, 1e6), 0.1)));
}

TEST(AzimuthElevation, CardinalDirections) {
  const auto rx_g = geo::Geodetic::from_deg(0.0, 0.0, 0.0);
  const geo::Ecef rx = geo::to_ecef(rx_g);
  const AzEl up = azimuth_elevation(rx, geo::Ecef(rx.p_m + Eigen::Vector3d(2e7, 0, 0)));
  EXPECT_NEAR(up.el_rad, kPi / 2, 1e-9);
  const AzEl north = azimuth_elevation(rx, geo::Ecef(rx.p_m + Eigen::Vector3d(0, 0, 2e7)));
  EXPECT_NEAR(north.az_rad, 0.0, 1e-9);
  EXPECT_NEAR(north.el_rad, 0.0, 1e-9);
  const AzEl east = azimuth_elevation(rx, geo::Ecef(rx.p_m + Eigen::Vector3d(0, 2e7, 0)));
  EXPECT_NEAR(east.az_rad, kPi / 2, 1e-9);
  const AzEl west = azimuth_elevation(rx, geo::Ecef(rx.p_m + Eigen::Vector3d(1e6, -2e7, 0)));
  EXPECT_NEAR(west.az_rad, 3 * kPi / 2, 1e-9);
  EXPECT_GT(west.el_rad, 0.0);
}

}  // namespace
}  // namespace pdnav::gnss
