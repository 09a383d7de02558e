// SPP on synthetic skies with known answers: exact solution, inter-system bias, FDE of a
// faulty satellite, fewer than 4 satellites, singular geometry, bad inputs.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "pdnav/gnss/solver_synthetic.h"
#include "pdnav/gnss/measurements.h"
#include "pdnav/gnss/spp.h"
#include "synthetic_sky.h"

namespace pdnav::gnss {
namespace {

const geo::Ecef kRx = geo::to_ecef(geo::Geodetic::from_deg(37.422578, -122.081678, -28.0));

TEST(SppSynthetic, ExactObservationsGiveTheTruth) {
  const auto sky = synthetic_sky(kRx, 8, 1);
  const SppSolution s = solve_spp(test::observe(sky, kRx, 1234.5), geo::Ecef(), 0.0, nullptr, test::no_atmosphere());
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_LT((s.pos.p_m - kRx.p_m).norm(), 1e-3);
  EXPECT_NEAR(s.clock_m, 1234.5, 1e-3);
  EXPECT_EQ(s.used.size(), 8u);
  EXPECT_TRUE(s.excluded_fde.empty());
  EXPECT_GT(s.hdop, 0.0);
  EXPECT_GT(s.pdop, s.hdop);
}

TEST(SppSynthetic, EstimatesInterSystemBiases) {
  const auto sky = synthetic_sky(kRx, 12, 2, {Constellation::kGps, Constellation::kGalileo, Constellation::kBeidou});
  const auto obs = test::observe(sky, kRx, -50.0, {{Constellation::kGalileo, 30.0}, {Constellation::kBeidou, -12.0}});
  const SppSolution s = solve_spp(obs, geo::Ecef(), 0.0, nullptr, test::no_atmosphere());
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_EQ(s.clock_system, Constellation::kGps);
  EXPECT_LT((s.pos.p_m - kRx.p_m).norm(), 1e-3);
  EXPECT_NEAR(s.isb_m.at(Constellation::kGalileo), 30.0, 1e-3);
  EXPECT_NEAR(s.isb_m.at(Constellation::kBeidou), -12.0, 1e-3);
  EXPECT_EQ(s.used_by_sys().at(Constellation::kGalileo), 4);
}

TEST(SppSynthetic, NoisyFixWithinItsPredictedSigma) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, 3.0);
  const auto sky = synthetic_sky(kRx, 10, 3);
  int inside = 0;
  for (int trial = 0; trial < 200; ++trial) {
    auto obs = test::observe(sky, kRx, 10.0);
    for (auto& o : obs) o.pseudorange_m += noise(rng);
    const SppSolution s = solve_spp(obs, geo::Ecef(), 0.0, nullptr, test::no_atmosphere());
    ASSERT_TRUE(s.ok);
    const double e = (s.pos.p_m - kRx.p_m).norm();
    inside += e < 3.0 * std::sqrt(s.pos_cov_ecef.trace()) ? 1 : 0;
  }
  EXPECT_GE(inside, 190);  // the weights (a = 4 m^2, b) are conservative for 3 m noise
}

TEST(SppSynthetic, FaultDetectionExcludesTheFaultySatellite) {
  const auto sky = synthetic_sky(kRx, 10, 4);
  auto obs = test::observe(sky, kRx, 0.0);
  obs[3].pseudorange_m += 80.0;
  const SppSolution s = solve_spp(obs, geo::Ecef(), 0.0, nullptr, test::no_atmosphere());
  ASSERT_TRUE(s.ok) << s.reason;
  ASSERT_EQ(s.excluded_fde.size(), 1u);
  EXPECT_EQ(s.excluded_fde[0], sky[3].sat);
  EXPECT_LT((s.pos.p_m - kRx.p_m).norm(), 1e-3);
  EXPECT_EQ(s.excluded.at("spp: FDE residual test"), 1);
}

TEST(SppSynthetic, FewerThanFourSatellites) {
  const auto sky = synthetic_sky(kRx, 3, 5);
  const SppSolution s = solve_spp(test::observe(sky, kRx, 0.0), geo::Ecef(), 0.0, nullptr, test::no_atmosphere());
  EXPECT_FALSE(s.ok);
  EXPECT_EQ(s.reason, "fewer than 4 satellites");
  EXPECT_FALSE(solve_spp({}, geo::Ecef(), 0.0, nullptr, test::no_atmosphere()).ok);
}

TEST(SppSynthetic, SingularGeometryIsRejected) {
  // five satellites on the same line of sight: position along it is not observable
  auto sky = synthetic_sky(kRx, 1, 6);
  const Eigen::Vector3d u = (sky[0].state.pos.p_m - kRx.p_m).normalized();
  for (int i = 1; i < 5; ++i) {
    SyntheticSat s = sky[0];
    s.sat.prn = i + 1;
    s.state.pos.p_m = kRx.p_m + u * (2.0e7 + 1.0e5 * i);
    sky.push_back(s);
  }
  const SppSolution s = solve_spp(test::observe(sky, kRx, 0.0), kRx, 0.0, nullptr, test::no_atmosphere());
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.reason.find("singular"), std::string::npos) << s.reason;
  EXPECT_TRUE(s.pos.p_m.allFinite());
}

TEST(SppSynthetic, NonFiniteInputsAreCountedNotUsed) {
  const auto sky = synthetic_sky(kRx, 9, 7);
  auto obs = test::observe(sky, kRx, 0.0);
  obs[0].pseudorange_m = kNaN;
  obs[1].state.pos.p_m.x() = std::numeric_limits<double>::infinity();
  const SppSolution s = solve_spp(obs, geo::Ecef(), 0.0, nullptr, test::no_atmosphere());
  ASSERT_TRUE(s.ok);
  EXPECT_EQ(s.excluded.at("spp: non-finite input"), 2);
  EXPECT_EQ(s.used.size(), 7u);
}

TEST(SppSynthetic, AtmosphereModelIsRemoved) {
  // observations generated with the same Saastamoinen model: the solver must remove it
  const auto sky = synthetic_sky(kRx, 9, 8);
  auto obs = test::observe(sky, kRx, 0.0);
  const geo::Geodetic g = geo::to_geodetic(kRx);
  for (auto& o : obs) {
    const Eigen::Vector3d sat = rotate_for_travel_time(o.state.pos.p_m, (o.state.pos.p_m - kRx.p_m).norm() / kSpeedOfLight_mps);
    o.pseudorange_m += saastamoinen_delay_m(g, azimuth_elevation(kRx, geo::Ecef(sat)).el_rad);
  }
  SppOptions opt;
  opt.ionosphere = false;
  const SppSolution s = solve_spp(obs, geo::Ecef(), 0.0, nullptr, opt);
  ASSERT_TRUE(s.ok);
  EXPECT_LT((s.pos.p_m - kRx.p_m).norm(), 0.01);
}

TEST(SppSynthetic, ChiSquareQuantileMatchesTables) {
  // NIST/SEMATECH table; Wilson-Hilferty is within 3 % (slightly conservative)
  EXPECT_NEAR(chi_square_quantile(1e-3, 1), 10.828, 0.03 * 10.828);
  EXPECT_NEAR(chi_square_quantile(1e-3, 5), 20.515, 0.03 * 20.515);
  EXPECT_NEAR(chi_square_quantile(1e-3, 10), 29.588, 0.03 * 29.588);
  EXPECT_NEAR(chi_square_quantile(0.05, 4), 9.488, 0.03 * 9.488);
  EXPECT_TRUE(std::isnan(chi_square_quantile(1e-3, 0)));
}

TEST(SppSynthetic, WeightsFallWithSignalAndElevation) {
  EXPECT_GT(cn0_elevation_variance(4, 1.6e5, 25, 1.0), cn0_elevation_variance(4, 1.6e5, 40, 1.0));
  EXPECT_GT(cn0_elevation_variance(4, 1.6e5, 40, 0.2), cn0_elevation_variance(4, 1.6e5, 40, 1.2));
  EXPECT_NEAR(cn0_elevation_variance(0, 1.6e5, 40, kPi / 2), 16.0, 1e-9);
}

}  // namespace
}  // namespace pdnav::gnss
