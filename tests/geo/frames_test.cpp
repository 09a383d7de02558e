#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

#include "pdnav/geo/baro.h"
#include "pdnav/geo/estimate.h"
#include "pdnav/geo/frames.h"

using namespace pdnav;
using namespace pdnav::geo;

// Known answer: NGS/NIMA example; the Mountain View truth site of the GNSS log.
TEST(Frames, GeodeticToEcefKnownPoint) {
  const Ecef x = to_ecef(Geodetic::from_deg(0.0, 0.0, 0.0));
  EXPECT_NEAR(x.p_m.x(), Wgs84::a_m, 1e-6);
  EXPECT_NEAR(x.p_m.y(), 0.0, 1e-6);
  const Ecef np = to_ecef(Geodetic::from_deg(90.0, 0.0, 0.0));
  EXPECT_NEAR(np.p_m.z(), Wgs84::b_m, 1e-6);
  // Mountain View site, value from RTKLIB pos2ecef for (37.422578, -122.081678, -28).
  const Ecef mv = to_ecef(Geodetic::from_deg(37.422578, -122.081678, -28.0));
  EXPECT_NEAR(mv.p_m.norm(), 6370286.0, 3000.0);
}

TEST(Frames, RoundTripPolesDateLineAndOrbit) {
  const double lats[] = {-90.0, -89.9999, -45.0, 0.0, 37.4, 89.9999, 90.0};
  const double lons[] = {-180.0, -179.9999, 0.0, 179.9999, 180.0};
  const double hs[] = {-100.0, 0.0, 3000.0, 20200e3};
  for (double lat : lats)
    for (double lon : lons)
      for (double h : hs) {
        const Geodetic g = Geodetic::from_deg(lat, lon, h);
        const Geodetic r = to_geodetic(to_ecef(g));
        const Ecef a = to_ecef(g), b = to_ecef(r);
        EXPECT_LT((a.p_m - b.p_m).norm(), 1e-6) << lat << "," << lon << "," << h;
        EXPECT_NEAR(r.h_m, h, 1e-6);
        EXPECT_NEAR(r.lat_rad, g.lat_rad, 1e-12);
      }
}

TEST(Frames, EnuOfNearbyPoint) {
  const Geodetic o = Geodetic::from_deg(42.5, 1.5, 1000.0);
  const LocalFrame f(o);
  // 1 arc-minute north is ~1852 m * (meridian radius / mean radius)
  const Enu n = f.to_enu(Geodetic::from_deg(42.5 + 1.0 / 60.0, 1.5, 1000.0));
  EXPECT_NEAR(n.n_m(), 1852.0, 6.0);
  EXPECT_NEAR(n.e_m(), 0.0, 1e-6);
  const Enu up = f.to_enu(Geodetic::from_deg(42.5, 1.5, 1100.0));
  EXPECT_NEAR(up.u_m(), 100.0, 1e-6);
  const Enu p(123.4, -567.8, 9.0);
  EXPECT_LT((f.to_enu(f.to_ecef(p)).p_m - p.p_m).norm(), 1e-7);
}

TEST(Baro, StandardAtmosphereKnownValues) {
  // ICAO standard atmosphere: 1000 m -> 898.75 hPa, 3000 m -> 701.09 hPa.
  EXPECT_NEAR(baro_altitude_m(89875.0, 101325.0, 0.0), 1000.0, 1.0);
  EXPECT_NEAR(baro_altitude_m(70109.0, 101325.0, 0.0), 3000.0, 2.0);
  EXPECT_NEAR(baro_pressure_pa(1000.0, 101325.0, 0.0), 89875.0, 5.0);
  EXPECT_TRUE(std::isnan(baro_altitude_m(-1.0, 101325.0, 0.0)));
  EXPECT_TRUE(std::isnan(baro_altitude_m(std::nan(""), 101325.0, 0.0)));
}

TEST(Baro, AltimeterAnchorsOnFirstSample) {
  BaroAltimeter alt;
  EXPECT_TRUE(std::isnan(alt.update(90000.0)));
  alt.anchor(1500.0);
  EXPECT_NEAR(alt.update(85000.0), 1500.0, 1e-9);
  EXPECT_GT(alt.update(84000.0), 1500.0 + 90.0);  // ~ 8.4 m/hPa at this height
}

TEST(Ellipse, FromCovariance) {
  Eigen::Matrix2d c;
  c << 4.0, 0.0, 0.0, 1.0;  // east sigma 2, north sigma 1
  const ErrorEllipse e = ErrorEllipse::from_covariance(c);
  EXPECT_NEAR(e.semi_major_m, 2.0, 1e-12);
  EXPECT_NEAR(e.semi_minor_m, 1.0, 1e-12);
  EXPECT_NEAR(e.orientation_rad, kPi / 2, 1e-12);
  EXPECT_NEAR(ErrorEllipse::scale_for_probability(0.95), 2.4477, 1e-4);
}

// Where an error falls in its stated 2-D Gaussian: the chi^2(2) CDF in percent, against a
// Monte Carlo of unit-covariance offsets (fixed seed) and its closed-form points.
TEST(Ellipse, Chi2TwoDofPercentIsTheShareOfGaussianOffsetsInside) {
  EXPECT_NEAR(chi2_2dof_percent(kOneSigmaM2), 68.2689, 1e-3);
  EXPECT_NEAR(chi2_2dof_percent(2.0 * std::log(2.0)), 50.0, 1e-9);
  EXPECT_EQ(chi2_2dof_percent(0.0), 0.0);
  EXPECT_EQ(chi2_2dof_percent(std::numeric_limits<double>::infinity()), 100.0);
  EXPECT_TRUE(std::isnan(chi2_2dof_percent(std::numeric_limits<double>::quiet_NaN())));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix2d cov;
  cov << 4.0, 1.0, 1.0, 2.0;
  const Eigen::LLT<Eigen::Matrix2d> llt(cov);
  const int draws = 20000;
  for (const double m2 : {0.5, 1.386, 3.0}) {
    int inside = 0;
    for (int k = 0; k < draws; ++k) {
      const Eigen::Vector2d d = llt.matrixL() * Eigen::Vector2d(n(rng), n(rng));
      inside += mahalanobis2(cov, d) <= m2;
    }
    // binomial sd at 20000 draws <= 0.36 %: 4 sd
    EXPECT_NEAR(100.0 * inside / draws, chi2_2dof_percent(m2), 1.5) << "m2 " << m2;
  }
}

// The median of squared Mahalanobis distances counts a distance that is not finite (no positive
// definite covariance, a NaN error) as outside every region, as the coverage figures do.
TEST(Ellipse, MedianMahalanobisCountsNonFiniteDistancesAsOutside) {
  EXPECT_TRUE(std::isnan(median_mahalanobis2({})));
  EXPECT_EQ(median_mahalanobis2({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(median_mahalanobis2({4.0, 1.0, 2.0, 3.0}), 2.5);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(median_mahalanobis2({0.5, nan, nan}), inf);
  EXPECT_EQ(median_mahalanobis2({0.5, 1.0, nan}), 1.0);
  EXPECT_EQ(median_mahalanobis2({0.5, 1.0, 3.0, inf}), 2.0);
  EXPECT_EQ(chi2_2dof_percent(median_mahalanobis2({nan})), 100.0);
}

TEST(Units, Wrap) {
  EXPECT_NEAR(wrap_pi(3 * kPi / 2), -kPi / 2, 1e-12);
  EXPECT_NEAR(wrap_pi(-kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_two_pi(-kPi / 2), 3 * kPi / 2, 1e-12);
}
