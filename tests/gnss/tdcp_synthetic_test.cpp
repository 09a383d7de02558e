// TDCP and Doppler displacement on synthetic skies with known motion and clock change.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "pdnav/gnss/solver_synthetic.h"
#include "pdnav/gnss/tdcp.h"

namespace pdnav::gnss {
namespace {

const geo::Ecef kRx = geo::to_ecef(geo::Geodetic::from_deg(46.5, 6.6, 400.0));

/// Carrier observations of a receiver at `rx` with clock `clock_m` and per-satellite
/// integer-ish ambiguities.
std::vector<CarrierObservation> carrier(const std::vector<SyntheticSat>& sky, const Eigen::Vector3d& rx, double clock_m,
                                        const Eigen::Vector3d& vel, double drift_mps) {
  std::vector<CarrierObservation> out;
  for (const auto& s : sky) {
    CarrierObservation c;
    c.sat = s.sat;
    c.state = s.state;
    c.cn0_dbhz = 40.0;
    c.adr_m = sagnac_range_m(s.state.pos.p_m, rx) + clock_m - kSpeedOfLight_mps * s.state.clock_bias_s + 1000.0 * s.sat.prn;
    c.pr_rate_mps = range_rate_mps(s.state, rx, vel) + drift_mps - kSpeedOfLight_mps * s.state.clock_drift_sps;
    c.pr_rate_sigma_mps = 0.05;
    out.push_back(c);
  }
  return out;
}

TEST(TdcpSynthetic, RecoversDisplacementAndClockChange) {
  const auto sky1 = synthetic_sky(kRx, 9, 11);
  const auto sky2 = propagate_sky(sky1, 1.0);
  const Eigen::Vector3d d(0.8, -0.4, 0.25);
  const Eigen::Vector3d v = d;  // 1 s
  const auto e1 = carrier(sky1, kRx.p_m, 100.0, v, 60.0);  // clock drifting 60 m/s
  const auto e2 = carrier(sky2, kRx.p_m + d, 160.0, v, 60.0);
  const DisplacementSolution s = solve_tdcp(e1, e2, 1.0, kRx, TdcpOptions{});
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_EQ(s.source, "tdcp");
  EXPECT_LT((s.disp_ecef_m - d).norm(), 2e-3);
  EXPECT_NEAR(s.clock_change_m, 60.0, 2e-3);
  EXPECT_EQ(s.used.size(), 9u);
  EXPECT_TRUE(s.excluded_fde.empty());
}

TEST(TdcpSynthetic, NoisyCarrierMatchesPredictedCovariance) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.003);
  const auto sky1 = synthetic_sky(kRx, 10, 12);
  const auto sky2 = propagate_sky(sky1, 1.0);
  double sum_sq = 0.0, sum_pred = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    auto e1 = carrier(sky1, kRx.p_m, 0.0, Eigen::Vector3d::Zero(), 0.0);
    auto e2 = carrier(sky2, kRx.p_m, 0.0, Eigen::Vector3d::Zero(), 0.0);
    for (auto& c : e2) c.adr_m += noise(rng);
    const DisplacementSolution s = solve_tdcp(e1, e2, 1.0, kRx, TdcpOptions{});
    ASSERT_TRUE(s.ok);
    sum_sq += s.disp_ecef_m.squaredNorm();
    sum_pred += s.cov_ecef_m2.trace();
  }
  // Walker's SNR variance at 40 dB-Hz is 12.25 mm^2 (3.5 mm), a little above the 3 mm used
  EXPECT_LT(sum_sq, sum_pred);
  EXPECT_GT(sum_sq, 0.3 * sum_pred);
}

TEST(TdcpSynthetic, UndetectedCycleSlipIsExcluded) {
  const auto sky1 = synthetic_sky(kRx, 10, 13);
  const auto sky2 = propagate_sky(sky1, 1.0);
  const auto e1 = carrier(sky1, kRx.p_m, 0.0, Eigen::Vector3d::Zero(), 0.0);
  auto e2 = carrier(sky2, kRx.p_m, 0.0, Eigen::Vector3d::Zero(), 0.0);
  e2[4].adr_m += 0.1903;  // one L1 cycle
  const DisplacementSolution s = solve_tdcp(e1, e2, 1.0, kRx, TdcpOptions{});
  ASSERT_TRUE(s.ok);
  ASSERT_EQ(s.excluded_fde.size(), 1u);
  EXPECT_EQ(s.excluded_fde[0], sky1[4].sat);
  EXPECT_LT(s.disp_ecef_m.norm(), 2e-3);
}

TEST(TdcpSynthetic, SolutionsTheTestCannotVouchForAreMarked) {
  const auto sky1 = synthetic_sky(kRx, 6, 17);
  const auto sky2 = propagate_sky(sky1, 1.0);
  const auto e1 = carrier(sky1, kRx.p_m, 0.0, Eigen::Vector3d::Zero(), 0.0);
  const auto clean = carrier(sky2, kRx.p_m, 0.0, Eigen::Vector3d::Zero(), 0.0);
  EXPECT_TRUE(solve_tdcp(e1, clean, 1.0, kRx, TdcpOptions{}).self_checked);  // 6 satellites, consistent
  // 4 satellites, one slipped 2.5 m: no redundancy, the error goes into the solution unseen
  auto four = std::vector<CarrierObservation>(clean.begin(), clean.begin() + 4);
  four[1].adr_m += 2.5;
  const DisplacementSolution s4 = solve_tdcp(e1, four, 1.0, kRx, TdcpOptions{});
  ASSERT_TRUE(s4.ok);
  EXPECT_FALSE(s4.self_checked);
  EXPECT_GT(s4.disp_ecef_m.norm(), 1.0);
  // 5 satellites, one slipped: the test fails, and with one degree of freedom it cannot tell which
  auto five = std::vector<CarrierObservation>(clean.begin(), clean.begin() + 5);
  five[1].adr_m += 2.5;
  const DisplacementSolution s5 = solve_tdcp(e1, five, 1.0, kRx, TdcpOptions{});
  ASSERT_TRUE(s5.ok);
  EXPECT_FALSE(s5.self_checked);
  five[1].adr_m -= 2.5;
  EXPECT_TRUE(solve_tdcp(e1, five, 1.0, kRx, TdcpOptions{}).self_checked);
}

TEST(TdcpSynthetic, AdrRateInconsistentWithDopplerIsDropped) {
  const auto sky1 = synthetic_sky(kRx, 8, 14);
  const auto sky2 = propagate_sky(sky1, 1.0);
  const auto e1 = carrier(sky1, kRx.p_m, 0.0, Eigen::Vector3d::Zero(), 0.0);
  auto e2 = carrier(sky2, kRx.p_m, 0.0, Eigen::Vector3d::Zero(), 0.0);
  e2[2].adr_m += 10.0;
  const DisplacementSolution s = solve_tdcp(e1, e2, 1.0, kRx, TdcpOptions{});
  ASSERT_TRUE(s.ok);
  EXPECT_EQ(s.excluded.at("tdcp: ADR rate vs pseudorange rate > 3 m/s"), 1);
  EXPECT_EQ(s.used.size(), 7u);
}

TEST(TdcpSynthetic, MissingCarrierOrTooFewSatellites) {
  const auto sky1 = synthetic_sky(kRx, 6, 15);
  const auto sky2 = propagate_sky(sky1, 1.0);
  auto e1 = carrier(sky1, kRx.p_m, 0.0, Eigen::Vector3d::Zero(), 0.0);
  auto e2 = carrier(sky2, kRx.p_m, 0.0, Eigen::Vector3d::Zero(), 0.0);
  for (int i = 0; i < 3; ++i) e2[static_cast<std::size_t>(i)].adr_m = kNaN;  // reset / slipped
  const DisplacementSolution s = solve_tdcp(e1, e2, 1.0, kRx, TdcpOptions{});
  EXPECT_FALSE(s.ok);
  EXPECT_EQ(s.reason, "fewer than 4 satellites");
  EXPECT_FALSE(solve_tdcp(e1, e2, 0.0, kRx, TdcpOptions{}).ok);
  EXPECT_FALSE(solve_tdcp(e1, e2, 1.0, geo::Ecef(kNaN, 0, 0), TdcpOptions{}).ok);
}

TEST(TdcpSynthetic, DopplerVelocityFallback) {
  const auto sky = synthetic_sky(kRx, 9, 16);
  const Eigen::Vector3d v(1.2, 0.3, -0.5);
  auto e = carrier(sky, kRx.p_m, 0.0, v, 45.0);
  for (auto& c : e) c.adr_m = kNaN;
  const DisplacementSolution s = solve_doppler(e, 2.0, kRx, TdcpOptions{});
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_EQ(s.source, "doppler");
  EXPECT_LT((s.disp_ecef_m - 2.0 * v).norm(), 1e-3);
  EXPECT_NEAR(s.clock_change_m, 90.0, 1e-3);
  EXPECT_NEAR(s.dt_s, 2.0, 1e-12);
}

}  // namespace
}  // namespace pdnav::gnss
