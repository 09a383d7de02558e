// World error models (pdnav/sim/world.h): each has the family docs/simulator.md claims, and
// that family is not the filters' (FOGM heading / baro bias, white DEM error).
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/sim/world.h"

namespace pdnav::sim {
namespace {

double variance(const std::vector<double>& v) {
  double m = 0, s = 0;
  for (double x : v) m += x;
  m /= static_cast<double>(v.size());
  for (double x : v) s += (x - m) * (x - m);
  return s / static_cast<double>(v.size() - 1);
}

HeadingErrorOptions only_random_walk() {
  HeadingErrorOptions o;
  o.mount_sigma_rad = 0;
  o.shift_rate_per_s = 0;
  o.sway_noise_rad = 0;
  return o;
}

// A random walk's variance grows linearly (a FOGM with the filter's 60 s time constant would
// have saturated: the ratio 1800 s / 180 s would be ~1, not ~10).
TEST(WorldHeading, RandomWalkVarianceGrowsLinearly) {
  std::vector<double> at180, at1800;
  for (std::uint64_t seed = 1; seed <= 400; ++seed) {
    Rng rng(seed);
    HeadingError h(only_random_walk(), {}, rng);
    for (double t = 0.1; t <= 1800.0 + 1e-9; t += 0.1) {
      const double e = h.advance(t, Eigen::Vector2d::Zero(), rng);
      if (std::abs(t - 180.0) < 0.05) at180.push_back(e);
      if (std::abs(t - 1800.0) < 0.05) at1800.push_back(e);
    }
  }
  ASSERT_EQ(at180.size(), 400u);
  const double ratio = variance(at1800) / variance(at180);
  EXPECT_GT(ratio, 7.0);
  EXPECT_LT(ratio, 14.0);
  const double expected_sd = only_random_walk().random_walk_rad_per_sqrt_s * std::sqrt(1800.0);
  EXPECT_NEAR(std::sqrt(variance(at1800)), expected_sd, 0.15 * expected_sd);
}

// Phone shifts: piecewise-constant misalignment that changes only at the Poisson shift times.
TEST(WorldHeading, ShiftsArePiecewiseConstantSteps) {
  HeadingErrorOptions o = only_random_walk();
  o.random_walk_rad_per_sqrt_s = 0;
  o.shift_rate_per_s = 1.0 / 60.0;
  Rng rng(7);
  HeadingError h(o, {}, rng);
  double prev = h.advance(0.0, Eigen::Vector2d::Zero(), rng);
  int changes = 0;
  for (double t = 0.5; t < 3600.0; t += 0.5) {
    const double e = h.advance(t, Eigen::Vector2d::Zero(), rng);
    if (e != prev) ++changes;
    prev = e;
  }
  EXPECT_EQ(static_cast<std::size_t>(changes), h.shifts());
  EXPECT_GT(changes, 35);  // ~60 expected in an hour
  EXPECT_LT(changes, 90);
}

// Magnetic anomalies are spatial: the error depends on where the walker is, not on time.
TEST(WorldHeading, AnomalyDeflectsNearTheStructureOnly) {
  HeadingErrorOptions o = only_random_walk();
  o.random_walk_rad_per_sqrt_s = 0;
  o.fusion_lag_s = 0;
  MagneticAnomaly a;
  a.at_en_m = Eigen::Vector2d(100, 0);
  a.radius_m = 10;
  a.peak_rad = 0.4;
  Rng rng(1);
  HeadingError h(o, {a}, rng);
  EXPECT_NEAR(h.advance(1.0, Eigen::Vector2d(100, 0), rng), 0.4, 1e-9);
  EXPECT_NEAR(h.advance(2.0, Eigen::Vector2d(100, 10), rng), 0.4 * std::exp(-0.5), 1e-9);
  EXPECT_NEAR(h.advance(3.0, Eigen::Vector2d(0, 0), rng), 0.0, 1e-9);
  // Structures are placed along a path at the requested density.
  Rng r2(3);
  const auto along = anomalies_along({Eigen::Vector2d(0, 0), Eigen::Vector2d(10000, 0)}, 10.0, HeadingErrorOptions{}, r2);
  EXPECT_GT(along.size(), 70u);
  EXPECT_LT(along.size(), 130u);
  for (const auto& s : along) EXPECT_LE(std::abs(s.at_en_m.y()), 20.0 + 1e-9);
}

TEST(WorldStride, ShorterOnSlopesAndWithFatigue) {
  StrideOptions o;
  o.step_cv = 0.0;
  Rng rng(5);
  const Stride s(o, 0.72, rng);
  const double flat = s.length_m(0.0, 0.0, rng);
  EXPECT_NEAR(flat, 0.72 * s.walker_scale(), 1e-12);
  EXPECT_NEAR(s.length_m(0.0, 0.12, rng) / flat, 1.0 - 0.8 * 0.12, 1e-9);   // uphill 12 %
  EXPECT_NEAR(s.length_m(0.0, -0.12, rng) / flat, 1.0 - 0.5 * 0.12, 1e-9);  // downhill: less
  EXPECT_NEAR(s.length_m(3600.0, 0.0, rng) / flat, 0.97, 1e-9);             // an hour of walking
  // The walker's stride differs from the APT model per walk (~6 %), not per step.
  std::vector<double> scales;
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    Rng r(seed);
    scales.push_back(Stride(StrideOptions{}, 0.72, r).walker_scale());
  }
  EXPECT_NEAR(std::sqrt(variance(scales)), 0.06, 0.012);
}

TEST(WorldBaro, WeatherTrendTideGustsAndQuantisation) {
  BaroWorldOptions o;
  o.gust_rate_per_s = 0.0;
  o.noise_pa = 0.0;
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    Rng rng(seed);
    const BaroWorld b(o, 4 * 3600.0, rng);
    const double change = std::abs(b.weather_pa(3 * 3600.0) - b.weather_pa(0.0));
    // 0.5-3 hPa of synoptic trend over 3 h, plus at most 2 x 0.5 hPa of semidiurnal tide.
    EXPECT_LE(change, 300.0 + 2 * o.tide_amplitude_pa + 1e-9);
    const double p = b.pressure_pa(100.0, 1500.0, rng);
    EXPECT_NEAR(p, std::round(p), 1e-9);  // reported in 0.01 hPa steps
  }
  // Gusts add dynamic-pressure bumps: with gusts on, some samples deviate from the smooth trend.
  BaroWorldOptions og = o;
  og.gust_rate_per_s = 1.0 / 30.0;
  og.quantum_pa = 0.0;
  Rng r1(9), r2(9);
  const BaroWorld calm(o, 3600.0, r1), gusty(og, 3600.0, r2);
  double max_dev = 0.0;
  Rng n1(1), n2(1);
  for (double t = 0; t < 3600; t += 0.2) max_dev = std::max(max_dev, std::abs(gusty.pressure_pa(t, 1500, n2) - calm.pressure_pa(t, 1500, n1)));
  EXPECT_GT(max_dev, 2.0);
  EXPECT_LT(max_dev, 0.5 * 1.1 * 8.0 * 8.0 * 2 + 2.0);
}

// DEM error: spatially correlated (not white), larger on steep slopes, biased up in forests.
TEST(WorldDem, CorrelatedSlopeDependentAndForestBiased) {
  DemErrorOptions o;
  o.forest_fraction = 0.0;
  auto flat = [](double, double) { return 0.0; };
  auto steep = [](double, double) { return 35.0; };
  auto low = [](double, double) { return 1000.0; };
  std::vector<double> a, b, c, flat_e, steep_e;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    Rng r1(seed), r2(seed);
    const DemError ef(o, 0, 0, 20000, 20000, flat, low, r1);
    const DemError es(o, 0, 0, 20000, 20000, steep, low, r2);
    a.push_back(ef.error_m(5000, 5000));
    b.push_back(ef.error_m(5030, 5000));   // 30 m away: nearly the same error
    c.push_back(ef.error_m(12000, 14000)); // far: independent
    flat_e.push_back(ef.error_m(7000, 3000));
    steep_e.push_back(es.error_m(7000, 3000));
  }
  auto corr = [](const std::vector<double>& x, const std::vector<double>& y) {
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
    mx /= static_cast<double>(x.size());
    my /= static_cast<double>(y.size());
    double sxy = 0, sxx = 0, syy = 0;
    for (std::size_t i = 0; i < x.size(); ++i)
      sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx), syy += (y[i] - my) * (y[i] - my);
    return sxy / std::sqrt(sxx * syy);
  };
  EXPECT_GT(corr(a, b), 0.8);
  EXPECT_LT(std::abs(corr(a, c)), 0.3);
  EXPECT_GT(std::sqrt(variance(steep_e)), 1.8 * std::sqrt(variance(flat_e)));
  // Forests: the canopy bias appears where the mask says forest, never above the tree line.
  DemErrorOptions of;
  of.forest_fraction = 0.5;
  Rng r3(11);
  const DemError ed(of, 0, 0, 20000, 20000, flat, low, r3);
  int forest = 0;
  for (int i = 0; i < 400; ++i) forest += ed.forest(50.0 * i, 7000.0) ? 1 : 0;
  EXPECT_GT(forest, 80);
  EXPECT_LT(forest, 320);
  auto high = [](double, double) { return 2500.0; };
  Rng r4(11);
  const DemError eh(of, 0, 0, 20000, 20000, flat, high, r4);
  for (int i = 0; i < 400; ++i) EXPECT_FALSE(eh.forest(50.0 * i, 7000.0));
}

}  // namespace
}  // namespace pdnav::sim
