// geo::geodesic_inverse (GeographicLib, Karney 2013) against published WGS84 values.
#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "pdnav/geo/geodesic.h"
#include "pdnav/geo/units.h"

namespace pdnav::geo {
namespace {

double dms(double d, double m, double s) { return (std::fabs(d) + m / 60.0 + s / 3600.0) * (d < 0 ? -1 : 1); }

TEST(GeodesicInverse, MeridianAndEquatorDegrees) {
  // WGS84: one degree of latitude from the equator 110574.389 m, of longitude on it 111319.491 m
  const GeodesicInverse n = geodesic_inverse(0.0, 10.0, 1.0, 10.0);
  EXPECT_NEAR(n.distance_m, 110574.389, 0.001);
  EXPECT_NEAR(n.initial_bearing_rad, 0.0, 1e-12);
  const GeodesicInverse e = geodesic_inverse(0.0, 0.0, 0.0, 1.0);
  EXPECT_NEAR(e.distance_m, 111319.491, 0.001);
  EXPECT_NEAR(e.initial_bearing_rad, kPi / 2, 1e-12);
  // pole to pole over a meridian: twice the quarter meridian 10001965.729 m
  EXPECT_NEAR(geodesic_inverse(-90.0, 0.0, 90.0, 0.0).distance_m, 2 * 10001965.729, 0.01);
}

TEST(GeodesicInverse, FlindersPeakToBuninyong) {
  // Vincenty (1975) / Geoscience Australia test line on GRS80 (WGS84 differs by < 1 mm here):
  // 54972.271 m, azimuth 306 deg 52' 05.37"
  const GeodesicInverse r = geodesic_inverse(dms(-37, 57, 3.72030), dms(144, 25, 29.52440),
                                             dms(-37, 39, 10.15610), dms(143, 55, 35.38390));
  EXPECT_NEAR(r.distance_m, 54972.271, 0.002);
  EXPECT_NEAR(r.initial_bearing_rad * kRadToDeg, dms(306, 52, 5.37), 1.0 / 3600.0 / 10.0);
}

TEST(GeodesicInverse, BearingInZeroToTwoPiAndSamePoint) {
  const GeodesicInverse sw = geodesic_inverse(42.5, 1.5, 42.49, 1.49);
  EXPECT_GT(sw.initial_bearing_rad, kPi);
  EXPECT_LT(sw.initial_bearing_rad, 1.5 * kPi);
  const GeodesicInverse same = geodesic_inverse(42.5, 1.5, 42.5, 1.5);
  EXPECT_EQ(same.distance_m, 0.0);
  EXPECT_GE(same.initial_bearing_rad, 0.0);
  EXPECT_LT(same.initial_bearing_rad, 2 * kPi);
}

TEST(GeodesicInverse, RejectsBadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(geodesic_inverse(nan, 0, 0, 0), std::invalid_argument);
  EXPECT_THROW(geodesic_inverse(0, 0, 0, std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_THROW(geodesic_inverse(90.5, 0, 0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace pdnav::geo
