// Honest status and start anchoring of the terrain engine (issue 17): a cloud over two
// identical valleys is ambiguous with both modes, a flat tile is "terrain uninformative" with
// a growing sigma and never locked, a wide start on a slope is anchored per particle, a start
// wider than the tile is refused with a clear error.
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pdnav/geo/baro.h"
#include "pdnav/terrain/terrain_engine.h"
#include "synthetic_dem.h"

namespace pdnav::terrain {
namespace {

/// Steps of 0.7 m every 0.55 s along headings, with the barometer reading the DEM under the truth
/// (+-0.5 Pa alternating so that it never looks stuck).
struct Walker {
  std::shared_ptr<const Dem> dem;
  TerrainEngine pf;
  double e, n;
  TimeNs t = kNsPerS;
  std::int64_t k = 0;
  Walker(std::shared_ptr<const Dem> d, const TerrainOptions& o, Eigen::Vector2d truth_start,
         Eigen::Vector2d declared_start, double sigma_m)
      : dem(d), pf(o, d, 7), e(truth_start.x()), n(truth_start.y()) {
    pf.initialize(dem->to_geodetic(declared_start.x(), declared_start.y()), sigma_m, t);
    feed_pressure();  // the anchor sample: taken at the truth's start
  }
  void feed_pressure() {
    PressureSample p;
    p.t_ns = t - kNsPerMs;
    p.pressure_pa = geo::baro_pressure_pa(dem->at_local(e, n).elevation_m, 101325.0, 0.0) + (k % 2 ? 0.5 : -0.5);
    pf.feed(p);
  }
  void step(double heading_rad) {
    ++k;
    t += 550 * kNsPerMs;
    e += 0.7 * std::sin(heading_rad);
    n += 0.7 * std::cos(heading_rad);
    feed_pressure();
    PdrStep s;
    s.t_ns = t;
    s.length_m = 0.7;
    s.heading_rad = heading_rad;
    pf.feed(s);
  }
  void walk(double heading_rad, double metres) {
    for (double m = 0; m < metres; m += 0.7) step(heading_rad);
  }
};

/// One valley-and-knoll feature around (0, 0); the tile holds two copies 1000 m apart.
double feature(double de, double dn) {
  return -80.0 * std::exp(-(de * de / (2 * 120.0 * 120.0) + dn * dn / (2 * 250.0 * 250.0))) +
         25.0 * std::sin(dn / 90.0) * std::exp(-de * de / (2 * 150.0 * 150.0)) +
         15.0 * std::exp(-((de - 60) * (de - 60) + (dn + 100) * (dn + 100)) / (2 * 50.0 * 50.0));
}

TEST(TerrainStatus, TwoIdenticalValleysAreAmbiguousWithBothModes) {
  auto dem = std::make_shared<const Dem>(test::synthetic_dem(141, 141, 30.0, [](double e, double n) {
    return 1000.0 + feature(e - 500.0, n) + feature(e + 500.0, n);
  }));
  TerrainOptions o = TerrainOptions::srtm_tuned();
  o.particles = 4000;
  // Truth in the east valley; the declared start halfway between the two, sigma 400 m.
  Walker w(dem, o, {500.0, -300.0}, {0.0, -300.0}, 400.0);
  w.walk(0.0, 600.0);            // up the valley
  w.walk(kPi / 2, 150.0);        // across it and back
  w.walk(3 * kPi / 2, 300.0);
  w.walk(kPi / 2, 150.0);
  const Estimate est = w.pf.estimate();
  const std::vector<TerrainMode> modes = w.pf.modes();
  EXPECT_EQ(est.status, EstimateStatus::kAmbiguous) << est.reason;
  EXPECT_THAT(est.reason, ::testing::HasSubstr("ambiguous: 2 modes"));
  ASSERT_EQ(modes.size(), 2u) << est.reason;
  const Eigen::Vector2d east(w.e, w.n), west(w.e - 1000.0, w.n);
  const bool first_east = modes[0].en_m.x() > 0.0;
  EXPECT_LT((modes[first_east ? 0 : 1].en_m - east).norm(), 60.0) << est.reason;
  EXPECT_LT((modes[first_east ? 1 : 0].en_m - west).norm(), 60.0) << est.reason;
  for (const TerrainMode& m : modes) {
    EXPECT_GT(m.weight, 0.2) << est.reason;
    EXPECT_LT(std::sqrt(m.cov_en_m2.trace()), 100.0) << "each mode is compact (a tenth of their separation)";
  }
  // The reported ellipse spans both modes instead of claiming one confident position.
  EXPECT_GT(std::sqrt(est.cov_en_m2(0, 0)), 300.0);
}

TEST(TerrainStatus, OneValleyIsNotAmbiguous) {
  // The same walk with only the east valley on the tile: one mode, status ok.
  auto dem = std::make_shared<const Dem>(test::synthetic_dem(141, 141, 30.0, [](double e, double n) {
    return 1000.0 + feature(e - 500.0, n);
  }));
  TerrainOptions o = TerrainOptions::srtm_tuned();
  o.particles = 4000;
  Walker w(dem, o, {500.0, -300.0}, {0.0, -300.0}, 400.0);
  w.walk(0.0, 600.0);
  w.walk(kPi / 2, 150.0);
  w.walk(3 * kPi / 2, 300.0);
  w.walk(kPi / 2, 150.0);
  const Estimate est = w.pf.estimate();
  EXPECT_EQ(est.status, EstimateStatus::kOk) << est.reason;
  EXPECT_EQ(w.pf.modes().size(), 1u) << est.reason;
  EXPECT_LT((est.en_m - Eigen::Vector2d(w.e, w.n)).norm(), 40.0) << est.reason;
}

TEST(TerrainStatus, FlatTileIsUninformativeWithAGrowingSigmaNeverLocked) {
  // Flat at 800 m with +-1.5 m of node noise (a DEM's own noise, below sqrt(R) = 4.5 m).
  auto dem = std::make_shared<const Dem>(test::synthetic_dem(201, 201, 30.0, [](double e, double n) {
    const auto h = static_cast<std::uint32_t>(std::lround(e * 7.0 + n * 13.0)) * 2654435761u;
    return 800.0 + 3.0 * ((h >> 8) % 1000 / 1000.0 - 0.5);
  }));
  for (bool enabled : {true, false}) {
    TerrainOptions o = TerrainOptions::srtm_tuned();
    if (!enabled) o.uninformative_relief_sigmas = 0.0;
    Walker w(dem, o, {0.0, 0.0}, {0.0, 0.0}, 5.0);
    double last_sigma = 0.0;
    bool ever_ok_after_first_update = false, growing = true;
    for (int leg = 0; leg < 6; ++leg) {
      w.walk(leg * kPi / 3, 200.0);
      const Estimate est = w.pf.estimate();
      const double sigma = est.ellipse().semi_major_m;
      growing = growing && sigma > last_sigma;
      last_sigma = sigma;
      ever_ok_after_first_update = ever_ok_after_first_update || est.status == EstimateStatus::kOk;
    }
    const Estimate est = w.pf.estimate();
    if (enabled) {
      EXPECT_EQ(est.status, EstimateStatus::kDegraded) << est.reason;
      EXPECT_THAT(est.reason, ::testing::HasSubstr("terrain uninformative"));
      EXPECT_FALSE(ever_ok_after_first_update);
      EXPECT_TRUE(growing) << "sigma must grow on featureless terrain";
      EXPECT_GT(last_sigma, 40.0);
      EXPECT_EQ(w.pf.stats().updates, 0);
      EXPECT_GT(w.pf.stats().uninformative_updates, 50);
    } else {
      EXPECT_EQ(est.status, EstimateStatus::kOk) << "the check off: the filter claims a lock on noise";
      EXPECT_GT(w.pf.stats().updates, 50);
    }
  }
}

TEST(TerrainStatus, WideStartOnASlopeIsAnchoredPerParticle) {
  // A 30 % slope up north plus hills; the truth starts 150 m north of the declared start
  // (sigma 100 m). Unanchored, every particle assumes the barometer's reference is the DEM
  // at the declared start, 45 m off for the truth's neighbourhood.
  auto dem = std::make_shared<const Dem>(test::synthetic_dem(301, 301, 30.0, [](double e, double n) {
    return test::hills(e, n) + 0.3 * n;
  }));
  double error_m[2] = {0, 0};
  for (bool anchor : {true, false}) {
    TerrainOptions o = TerrainOptions::srtm_tuned();
    o.particles = 2000;
    o.anchor_start_bias = anchor;
    Walker w(dem, o, {0.0, 150.0}, {0.0, 0.0}, 100.0);
    w.walk(kPi / 2, 400.0);
    w.walk(0.0, 400.0);
    w.walk(3 * kPi / 2, 400.0);
    error_m[anchor ? 0 : 1] = (w.pf.estimate().en_m - Eigen::Vector2d(w.e, w.n)).norm();
  }
  EXPECT_LT(error_m[0], 40.0) << "anchored";
  EXPECT_GT(error_m[1], error_m[0] + 20.0) << "unanchored " << error_m[1] << " m";
}

TEST(TerrainStatus, StartWiderThanTheTileIsRefused) {
  auto dem = std::make_shared<const Dem>(test::synthetic_dem(301, 301, 30.0, test::hills));  // 9 x 9 km
  TerrainEngine pf(TerrainOptions::srtm_tuned(), dem, 1);
  const geo::Geodetic start = dem->to_geodetic(0.0, 0.0);
  EXPECT_TRUE(pf.start_problem(start, 1000.0).empty());  // 3 sigma = 3 km < 4.5 km to the edge
  EXPECT_THROW(pf.check_start(start, 2000.0), std::invalid_argument);
  try {
    pf.check_start(start, 2000.0);
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("start sigma 2000 m refused"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("1500 m beyond the DEM tile"));
  }
  pf.initialize(start, 2000.0, kNsPerS);
  const Estimate est = pf.estimate();
  EXPECT_FALSE(est.valid());
  EXPECT_THAT(est.reason, ::testing::HasSubstr("refused"));
  EXPECT_FALSE(pf.start_error().empty());
  pf.initialize(start, 1000.0, kNsPerS);  // a tighter start is accepted
  EXPECT_TRUE(pf.start_error().empty());
  EXPECT_TRUE(pf.estimate().valid());
}

}  // namespace
}  // namespace pdnav::terrain
