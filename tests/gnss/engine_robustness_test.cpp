// GnssEngine on the real Mountain View log with injected faults: clock discontinuity,
// malformed rows, fewer than 4 satellites, no ephemeris. Counted, coasting/reset, never NaN.
#include <cmath>
#include <limits>
#include <memory>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/gnss/gnss_engine.h"
#include "pdnav/gnss/solver_metrics.h"
#include "mountainview_log.h"
#include "test_data.h"

namespace pdnav::gnss {
namespace {

const geo::Geodetic kTruth = geo::Geodetic::from_deg(37.422578, -122.081678, -28.0);

void expect_finite(const std::vector<EpochSolution>& sols) {
  for (const auto& s : sols) {
    ASSERT_TRUE(s.kf.p_m.allFinite());
    ASSERT_TRUE(s.spp.p_m.allFinite());
    ASSERT_TRUE(s.kf_cov_enu.allFinite());
    ASSERT_TRUE(s.tdcp_disp_m.allFinite());
  }
}

/// Flushes the engine after its rows were fed and returns its solutions, all checked finite.
std::vector<EpochSolution> finish(GnssEngine& engine) {
  engine.flush();
  auto sols = engine.take_solutions();
  expect_finite(sols);
  return sols;
}

TEST(EngineRobustness, ClockDiscontinuityResetsTdcpAndKeepsAccuracy) {
  auto rows = test::mountainview_raw();
  ASSERT_GT(rows.size(), 4000u);
  const std::int64_t t_mid = rows[rows.size() / 2].time_nanos;
  for (auto& r : rows) {
    if (r.time_nanos >= t_mid) {
      r.hardware_clock_discontinuity_count = 1;
      r.full_bias_nanos -= 5'000'000;       // the clock jumped 5 ms
      r.time_nanos += 0;                    // same epochs
      r.accumulated_delta_range_m += 2.5; // carrier restarted
    }
  }
  GnssEngine engine(GnssOptions{}, test::mountainview_nav(), 1);
  for (const auto& r : rows) engine.feed(r);
  const auto sols = finish(engine);
  EXPECT_EQ(engine.exclusions().at("clock: hardware clock discontinuity (TDCP and KF clock reset)"), 1);
  const StaticAccuracy a = evaluate_static(sols, kTruth);
  EXPECT_LE(a.kf_rms_h_m, 2.5);
  EXPECT_LE(a.tdcp_rms_enu_m.maxCoeff(), 0.03);
}

TEST(EngineRobustness, FullBiasJumpingAcrossTheInt64RangeIsNotLinked) {
  // Fuzz finding (fuzz_navigator, 2026-11-23): consecutive epochs with FullBiasNanos of
  // -1.16e18 and +8.39e18 overflowed the int64 difference (UBSan in the asan/fuzz builds).
  // The epochs must simply not be linked (no TDCP / smoothing across them), never wrap.
  auto rows = test::mountainview_raw();
  std::vector<std::int64_t> epochs;
  for (const auto& r : rows)
    if (epochs.empty() || r.time_nanos != epochs.back()) epochs.push_back(r.time_nanos);
  ASSERT_GT(epochs.size(), 30u);
  for (auto& r : rows) {
    if (r.time_nanos == epochs[10]) r.full_bias_nanos = -1155938064663285906;
    if (r.time_nanos == epochs[11]) r.full_bias_nanos = 8387194961890077011;
  }
  GnssEngine engine(GnssOptions{}, test::mountainview_nav(), 1);
  for (const auto& r : rows) engine.feed(r);
  const auto sols = finish(engine);
  EXPECT_GE(engine.exclusions().at("epoch: gap or time going backwards (no TDCP)"), 1);
  EXPECT_LE(evaluate_static(sols, kTruth).kf_rms_h_m, 2.5);
}

TEST(EngineRobustness, MalformedValuesAreCountedNeverNaN) {
  auto rows = test::mountainview_raw();
  const double inf = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < rows.size(); i += 7) {
    GnssRawSample& r = rows[i];
    switch (i % 5) {
      case 0: r.cn0_dbhz = kNaN; break;
      case 1: r.pseudorange_rate_mps = 3.4028234663852886e38; r.accumulated_delta_range_uncertainty_m = inf; break;
      case 2: r.received_sv_time_nanos = -5; break;
      case 3: r.constellation_type = 42; break;
      default: r.accumulated_delta_range_m = kNaN; r.bias_nanos = kNaN; break;
    }
  }
  GnssRawSample no_clock = rows[10];
  no_clock.time_nanos = kMissingInt;
  GnssEngine engine(GnssOptions{}, test::mountainview_nav(), 1);
  engine.feed(no_clock);
  for (const auto& r : rows) engine.feed(r);
  const auto sols = finish(engine);
  const auto& ex = engine.exclusions();
  EXPECT_GT(ex.at("cn0: missing"), 0);
  EXPECT_GT(ex.at("doppler: missing or non-finite"), 0);
  EXPECT_GT(ex.at("code: ReceivedSvTimeNanos missing"), 0);
  EXPECT_GT(ex.at("unsupported constellation"), 0);
  EXPECT_EQ(ex.at("row: TimeNanos missing"), 1);
  EXPECT_LE(evaluate_static(sols, kTruth).kf_rms_h_m, 4.0);
  EXPECT_TRUE(engine.estimate().valid());
}

TEST(EngineRobustness, FewerThanFourSatellitesCoastsThenLost) {
  const auto rows = test::mountainview_raw();
  const std::int64_t t0 = rows.front().time_nanos;
  GnssEngine engine(GnssOptions{}, test::mountainview_nav(), 1);
  // first 100 s normal, then only GPS PRNs 5, 12, 21 (3 satellites) for the rest
  const std::set<int> three = {5, 12, 21};
  for (const auto& r : rows) {
    if (r.time_nanos - t0 > 100 * kNsPerS && !(r.constellation_type == 1 && three.count(r.svid))) continue;
    engine.feed(r);
    if (r.time_nanos - t0 == 110 * kNsPerS) {
      const Estimate e = engine.estimate();
      EXPECT_EQ(e.status, EstimateStatus::kDegraded) << e.reason;
    }
  }
  const auto sols = finish(engine);
  EXPECT_GT(engine.exclusions().at("spp: fewer than 4 satellites"), 50);
  const Estimate e = engine.estimate();
  EXPECT_EQ(e.status, EstimateStatus::kLost) << e.reason;
  EXPECT_TRUE(e.position.lat_rad == e.position.lat_rad);
  EXPECT_GT(e.cov_en_m2.trace(), 10.0);  // uncertainty grew while coasting
  // coasting on Doppler of 3 satellites is impossible (4 unknowns): covariance grows, position stays
  EXPECT_LT(horizontal_distance_m(e.position, kTruth), 10.0);
}

TEST(EngineRobustness, UncheckableTdcpWithAnUndetectedSlipDoesNotMoveTheFilter) {
  // Carrier phase on 4 satellites only: the TDCP displacement has no redundant satellite, so its
  // own chi-square test cannot see a slip. From the middle of the log one of them slips by
  // 2.5 m (under the 3 m/s ADR-vs-Doppler check) without a flag: once, and on a static phone.
  // Found on a simulated session (eval-fusion seed 6 walk 20): a 34 m jump in one epoch, the KF
  // then 30 m off at a 4 m sigma for 40 s. The engine checks such a displacement against its
  // KF's prediction and takes the Doppler velocity instead.
  auto rows = test::mountainview_raw();
  // GPS PRNs 21, 29, 20, 12 are above the mask with ephemeris at most epochs (4-satellite TDCP
  // at 171 of 207); PRN 21 slips
  const std::set<int> four = {21, 29, 20, 12};
  const int slipping = 21;
  const std::int64_t t_slip = rows[rows.size() / 2].time_nanos;
  for (auto& r : rows) {
    if (r.constellation_type != 1 || !four.count(r.svid)) {
      r.accumulated_delta_range_state = 0;
      r.accumulated_delta_range_m = 0.0;
    } else if (r.svid == slipping && r.time_nanos >= t_slip) {
      r.accumulated_delta_range_m += 2.5;
    }
  }
  GnssEngine engine(GnssOptions{}, test::mountainview_nav(), 1);
  for (const auto& r : rows) engine.feed(r);
  const auto sols = finish(engine);
  int tdcp4 = 0;
  double worst_m = 0.0;  // after the first 30 epochs (the KF has converged)
  for (std::size_t i = 0; i < sols.size(); ++i) {
    tdcp4 += sols[i].tdcp_ok && sols[i].tdcp_sats == 4;
    if (i >= 30 && sols[i].kf_ok) worst_m = std::max(worst_m, horizontal_distance_m(geo::to_geodetic(sols[i].kf), kTruth));
  }
  EXPECT_GT(tdcp4, 100);  // the test is about 4-satellite TDCP: most epochs had it
  const auto& ex = engine.exclusions();
  const auto refused = ex.find("tdcp: unchecked by its own test and inconsistent with the KF (Doppler used)");
  EXPECT_TRUE(refused != ex.end() && refused->second >= 1);
  // with the check: RMS 1.93 m, worst 2.54 m; without it 2.72 / 4.39 m (a 2.9 m slip: 2.93 / 4.86)
  EXPECT_LE(evaluate_static(sols, kTruth).kf_rms_h_m, 2.3);
  EXPECT_LT(worst_m, 3.5);
}

TEST(EngineRobustness, NoEphemerisMeansNoFixAndACountedReason) {
  const auto rows = test::mountainview_raw();
  GnssEngine engine(GnssOptions{}, nullptr, 1);
  for (std::size_t i = 0; i < 500; ++i) engine.feed(rows[i]);
  engine.flush();
  EXPECT_GT(engine.exclusions().at("ephemeris: no ephemeris"), 100);
  EXPECT_EQ(engine.estimate().status, EstimateStatus::kNotInitialized);
  NavMessageSample bad;
  bad.type = 0x0101;
  bad.svid = 5;
  bad.sub_message_id = 2;
  bad.data = {1, 2, 3};
  engine.feed(bad);  // garbage subframe: counted, no crash
  bad.type = 0x0601;
  engine.feed(bad);
  EXPECT_EQ(engine.exclusions().at("nav: unsupported message type"), 1);
  EXPECT_GE(engine.epochs(), 20);
}

}  // namespace
}  // namespace pdnav::gnss
