// Dual frequency (issue 15): the L1/L5 ionosphere-free code removes a known ionospheric delay
// and the satellite group delay, the receiver's large L1-L5 bias does not leak into the
// position, a clock group with too few L5 satellites falls back to L1 + Klobuchar, an L1-only
// satellite of an IF group loses its code (or is kept on request), and build_epoch pairs the
// L5/E5a rows with their L1 rows only in dual mode.
#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "pdnav/gnss/measurements.h"
#include "pdnav/gnss/solver_smoothing.h"
#include "pdnav/gnss/solver_synthetic.h"
#include "pdnav/gnss/spp.h"
#include "raw_row.h"

namespace pdnav::gnss {
namespace {

const geo::Ecef kRx = geo::to_ecef(geo::Geodetic::from_deg(37.422578, -122.081678, -28.0));
constexpr double kGamma = (1575.42 / 1176.45) * (1575.42 / 1176.45);  // I5 / I1
constexpr double kClockM = 150.0;
const std::map<Constellation, double> kL1L5BiasM = {{Constellation::kGps, 2353.0}, {Constellation::kGalileo, 1913.0}};

/// Klobuchar coefficients of a real broadcast header (hour1180.21n order of magnitude).
KlobucharParams klobuchar() {
  KlobucharParams k;
  k.alpha = {1.1176e-08, 7.4506e-09, -5.9605e-08, -5.9605e-08};
  k.beta = {8.8064e+04, 3.2768e+04, -1.3107e+05, -6.5536e+04};
  return k;
}

/// The "true" L1 ionosphere of satellite i: 2 to 16 m, unrelated to Klobuchar.
double iono_l1_m(std::size_t i) { return 2.0 + 1.75 * static_cast<double>(i % 9); }

struct Scenario {
  std::vector<SyntheticSat> sky;
  std::vector<Measurement> meas;
};

/// L1 code = range + clock - c (dtsv - TGD) + I; L5 = range + clock + bias - c (dtsv - gamma TGD) + gamma I.
/// `dual[i]` false: L1 only.
Scenario make(const std::vector<bool>& dual, const std::vector<Constellation>& systems, std::uint64_t seed) {
  Scenario s;
  s.sky = synthetic_sky(kRx, static_cast<int>(dual.size()), seed, systems);
  for (std::size_t i = 0; i < s.sky.size(); ++i) {
    const SatState& st = s.sky[i].state;
    const double geo_m = sagnac_range_m(st.pos.p_m, kRx.p_m) + kClockM - kSpeedOfLight_mps * st.clock_bias_s;
    Measurement m;
    m.sat = s.sky[i].sat;
    m.cn0_dbhz = 40.0;
    m.carrier_hz = 1575.42e6;
    m.pseudorange_m = geo_m + kSpeedOfLight_mps * st.group_delay_s + iono_l1_m(i);
    if (dual[i]) {
      m.pseudorange_l5_m = geo_m + kL1L5BiasM.at(m.sat.sys) * -1.0 + kGamma * kSpeedOfLight_mps * st.group_delay_s +
                           kGamma * iono_l1_m(i);
      m.cn0_l5_dbhz = 40.0;
    }
    s.meas.push_back(m);
  }
  return s;
}

std::vector<SppObservation> to_spp(const Scenario& s, bool use_if_flags) {
  std::vector<SppObservation> obs;
  for (std::size_t i = 0; i < s.meas.size(); ++i) {
    const Measurement& m = s.meas[i];
    if (!m.code_ok()) continue;
    SppObservation o{m.sat, m.pseudorange_m, m.cn0_dbhz, 1575.42e6, s.sky[i].state};
    if (use_if_flags) {
      o.iono_free = m.iono_free;
      o.cn0_l5_dbhz = m.cn0_l5_dbhz;
    }
    obs.push_back(o);
  }
  return obs;
}

SppOptions iono_only() {
  SppOptions o;
  o.troposphere = false;
  o.elevation_mask_deg = 0.0;
  return o;
}

TEST(DualFrequency, IonosphereFreeCodeRemovesAKnownIonosphere) {
  Scenario s = make(std::vector<bool>(10, true), {Constellation::kGps, Constellation::kGalileo}, 11);
  ExclusionCounts ex;
  MeasurementOptions opt;
  opt.frequency = FrequencyMode::kDual;
  const Scenario single = s;
  combine_dual_frequency(s.meas, opt, ex);
  for (const Measurement& m : s.meas) {
    EXPECT_TRUE(m.iono_free) << m.sat.to_string();
    EXPECT_EQ(m.cn0_l5_dbhz, 40.0);
    // equal noise model and C/N0 on both bands: the IF variance is alpha^2 + beta^2 = 6.70 x L1
    const CodeNoiseModel same = CodeNoiseModel::uniform(4.0, 1.6e5);
    EXPECT_NEAR(iono_free_variance_m2(same, m.sat.sys, 40.0, 40.0, 0.7) /
                    same.variance_m2(m.sat.sys, 1575.42e6, 40.0, 0.7),
                kIfAlpha * kIfAlpha + kIfBeta * kIfBeta, 1e-9);
  }
  EXPECT_EQ(ex["dual: ionosphere-free code used"], 10);
  const KlobucharParams k = klobuchar();
  const SppSolution dual = solve_spp(to_spp(s, true), geo::Ecef(), 345600.0, &k, iono_only());
  ASSERT_TRUE(dual.ok) << dual.reason;
  EXPECT_LT((dual.pos.p_m - kRx.p_m).norm(), 0.01);  // ionosphere, TGD and the 2.35 km L1-L5 bias gone
  // the same codes without the IF flags (Klobuchar and TGD applied on top of the IF code): wrong
  const SppSolution no_branch = solve_spp(to_spp(s, false), geo::Ecef(), 345600.0, &k, iono_only());
  ASSERT_TRUE(no_branch.ok) << no_branch.reason;
  EXPECT_GT((no_branch.pos.p_m - kRx.p_m).norm(), 0.5);
  // single frequency + Klobuchar cannot remove an ionosphere that Klobuchar does not describe
  const SppSolution l1 = solve_spp(to_spp(single, true), geo::Ecef(), 345600.0, &k, iono_only());
  ASSERT_TRUE(l1.ok) << l1.reason;
  EXPECT_GT((l1.pos.p_m - kRx.p_m).norm(), 2.0);
}

TEST(DualFrequency, GroupWithFewL5SatellitesFallsBackToL1) {
  // GPS: 5 of 6 dual (combined, the L1-only one loses its code); Galileo: 1 of 5 (stays L1)
  const std::vector<bool> dual = {true, true, true, false, true, false, true, false, true, false, false};
  const std::vector<Constellation> sys = {Constellation::kGps, Constellation::kGalileo};  // round robin
  Scenario s = make(dual, sys, 12);
  const Scenario before = s;
  MeasurementOptions opt;
  opt.frequency = FrequencyMode::kDual;
  ExclusionCounts ex;
  combine_dual_frequency(s.meas, opt, ex);
  int gps_if = 0, gps_dropped = 0;
  for (std::size_t i = 0; i < s.meas.size(); ++i) {
    const Measurement& m = s.meas[i];
    if (m.sat.sys == Constellation::kGalileo) {
      EXPECT_FALSE(m.iono_free);
      EXPECT_EQ(m.pseudorange_m, before.meas[i].pseudorange_m);  // single frequency, unchanged
    } else if (dual[i]) {
      EXPECT_TRUE(m.iono_free);
      ++gps_if;
    } else {
      EXPECT_FALSE(m.code_ok());
      ++gps_dropped;
    }
  }
  EXPECT_EQ(gps_if, 5);
  EXPECT_EQ(gps_dropped, 1);
  EXPECT_EQ(ex["dual: L1-only satellite of an IF group (code not used)"], 1);
  EXPECT_EQ(ex["dual: too few dual-frequency satellites in the clock group (single frequency)"], 1);
  // a mixed GPS/IF + Galileo/L1 epoch solves: Galileo's ISB absorbs its own clock
  const KlobucharParams k = klobuchar();
  const SppSolution sol = solve_spp(to_spp(s, true), geo::Ecef(), 345600.0, &k, iono_only());
  ASSERT_TRUE(sol.ok) << sol.reason;
  EXPECT_EQ(sol.used.size(), 10u);
  // keep-single: the L1-only GPS code stays
  Scenario kept = before;
  opt.dual_keep_single = true;
  ExclusionCounts ex2;
  combine_dual_frequency(kept.meas, opt, ex2);
  EXPECT_TRUE(kept.meas[10].code_ok());  // index 10 is GPS (even), L1 only
  EXPECT_FALSE(kept.meas[10].iono_free);
  EXPECT_EQ(ex2["dual: L1-only satellite kept in an IF group"], 1);
}

TEST(DualFrequency, L5OutlierLosesItsCode) {
  Scenario s = make(std::vector<bool>(8, true), {Constellation::kGps}, 13);
  s.meas[3].pseudorange_l5_m += 45.0;  // an L5 multipath / tracking error
  MeasurementOptions opt;
  opt.frequency = FrequencyMode::kDual;
  ExclusionCounts ex;
  combine_dual_frequency(s.meas, opt, ex);
  EXPECT_FALSE(s.meas[3].code_ok());
  EXPECT_EQ(ex["dual: L1-L5 difference far from the group median (code dropped)"], 1);
  EXPECT_EQ(ex["dual: ionosphere-free code used"], 7);
}

GnssRawSample raw(int svid, double carrier_hz, std::int64_t sv_time_ns, std::int64_t rx_gps_ns) {
  GnssRawSample r = test::raw_row(1'000'000'000, 2'000'000'000'000, rx_gps_ns, /*GPS*/ 1, svid,
                                  state_bit::kCodeLock | state_bit::kTowDecoded, 35.0);
  r.received_sv_time_nanos = sv_time_ns;
  r.carrier_frequency_hz = carrier_hz;
  r.pseudorange_rate_mps = 10.0;
  r.pseudorange_rate_uncertainty_mps = 0.1;
  return r;
}

TEST(DualFrequency, BuildEpochPairsL5RowsOnlyInDualMode) {
  const std::int64_t week = std::int64_t{2155} * 604'800'000'000'000;
  const std::int64_t rx = week + 300'000 * kNsPerS;
  std::vector<GnssRawSample> rows;
  for (int sv = 1; sv <= 5; ++sv) {
    const std::int64_t tx = 300'000 * kNsPerS - 70'000'000 - sv * 1000;
    rows.push_back(raw(sv, 1575.42e6, tx, rx));
    if (sv <= 4) rows.push_back(raw(sv, 1176.45e6, tx + 10, rx));  // L5 code 10 ns (3 m) shorter
  }
  MeasurementEpoch ep;
  ExclusionCounts ex;
  MeasurementOptions opt;
  ASSERT_TRUE(build_epoch(rows, opt, ep, ex));
  EXPECT_EQ(ep.meas.size(), 5u);
  EXPECT_EQ(ex["signal: not L1/E1/B1 (one band used)"], 4);
  for (const auto& m : ep.meas) EXPECT_FALSE(m.iono_free);
  opt.frequency = FrequencyMode::kDual;
  ExclusionCounts ex2;
  ASSERT_TRUE(build_epoch(rows, opt, ep, ex2));
  ASSERT_EQ(ep.meas.size(), 5u);
  int combined = 0;
  for (const auto& m : ep.meas) {
    if (m.sat.prn <= 4) {
      ASSERT_TRUE(m.iono_free) << m.sat.to_string();
      // all four have the same L1-L5 difference: the median removes it, P_IF = P1
      EXPECT_NEAR(m.pseudorange_m, m.pseudorange_l1_m, 1e-6);
      EXPECT_NEAR(m.pseudorange_l1_m - m.pseudorange_l5_m, 10e-9 * kSpeedOfLight_mps, 1e-6);
      ++combined;
    } else {
      EXPECT_FALSE(m.code_ok());  // L1-only in an IF group (4 of 5 = 0.8 >= 0.75)
    }
  }
  EXPECT_EQ(combined, 4);
  EXPECT_EQ(ex2.count("signal: not L1/E1/B1 (one band used)"), 0u);
}

TEST(DualFrequency, SmootherAveragesTheIfCorrectionAndRestartsOnASwitch) {
  // no carrier smoothing (window 0) isolates the ionosphere average: the IF correction is
  // -4 m +- 3 m (alternating noise); averaged over 300 s it converges to -4 m
  SmoothingOptions o;
  o.window_s = 0.0;
  o.iono_window_s = 300.0;
  CodeSmoother sm(o);
  const SatId g{Constellation::kGps, 3};
  double last = 0.0;
  for (int k = 0; k < 400; ++k) {
    sm.begin_epoch(k == 0 ? 0.0 : 1.0, 0.0);
    const double l1 = 2.2e7 + 10.0 * k;
    const double corr = -4.0 + (k % 2 == 0 ? 3.0 : -3.0);
    SmoothingInput in{g, l1 + corr, kNaN, kNaN, true, l1};
    last = sm.smooth_epoch({in})[0] - l1;
  }
  EXPECT_NEAR(last, -4.0, 0.05);  // raw IF: -7 or -1
  // the same satellite as single frequency: the raw L1 code, no leftover correction
  sm.begin_epoch(1.0, 0.0);
  const double l1 = 2.3e7;
  SmoothingInput single{g, l1, kNaN, kNaN, false, kNaN};
  EXPECT_EQ(sm.smooth_epoch({single})[0], l1);
  // back to IF: restarted (the raw correction, not the old average)
  sm.begin_epoch(1.0, 0.0);
  SmoothingInput again{g, l1 + 2.0, kNaN, kNaN, true, l1};
  EXPECT_NEAR(sm.smooth_epoch({again})[0] - l1, 2.0, 1e-9);
}

}  // namespace
}  // namespace pdnav::gnss
