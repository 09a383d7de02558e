// Raw -> pseudorange per constellation with known answers: week, day and 100 ms ambiguity
// rollovers, BDT offset, GLONASS UTC(SU)+3h, state bits, and bad values counted.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/measurements.h"
#include "raw_row.h"

namespace pdnav::gnss {
namespace {

constexpr double kTravelS = 0.07;
constexpr std::int64_t kTravelNs = 70'000'000;
const std::int64_t kWeek2200 = std::int64_t{2200} * geo::kNsPerWeek;

/// A row whose receive time (GPS) is rx_gps_ns.
GnssRawSample row_at(std::int64_t rx_gps_ns, int constellation, int svid, std::int64_t state) {
  GnssRawSample r = test::raw_row(5'000'000'000, 1'000'000'000'000, rx_gps_ns, constellation, svid, state, 40.0);
  r.pseudorange_rate_mps = 100.0;
  r.pseudorange_rate_uncertainty_mps = 0.05;
  r.accumulated_delta_range_state = adr_bit::kValid;
  r.accumulated_delta_range_m = 1234.5;
  r.accumulated_delta_range_uncertainty_m = 0.002;
  return r;
}

constexpr std::int64_t kGpsOk = state_bit::kCodeLock | state_bit::kBitSync | state_bit::kSubframeSync | state_bit::kTowDecoded;

double pr_of(const GnssRawSample& r, std::string* why = nullptr) {
  GpsTime rx;
  EXPECT_TRUE(receive_gps_time(r, rx));
  std::string reason;
  const double pr = pseudorange_m(r, rx, 18, reason);
  if (why) *why = reason;
  return pr;
}

TEST(MeasurementsModel, GpsPseudorangeFromTimeOfWeek) {
  const std::int64_t rx = kWeek2200 + 345'678 * kNsPerS + 123'456;
  GnssRawSample r = row_at(rx, 1, 5, kGpsOk);
  r.received_sv_time_nanos = (rx - kWeek2200) - kTravelNs;
  EXPECT_NEAR(pr_of(r), kTravelS * kSpeedOfLight_mps, 1e-6);
}

TEST(MeasurementsModel, GpsWeekRollover) {
  // received 30 ms into week 2201, transmitted 40 ms before the end of week 2200
  const std::int64_t rx = kWeek2200 + geo::kNsPerWeek + 30 * kNsPerMs;
  GnssRawSample r = row_at(rx, 1, 5, kGpsOk);
  r.received_sv_time_nanos = geo::kNsPerWeek - 40 * kNsPerMs;
  EXPECT_NEAR(pr_of(r), kTravelS * kSpeedOfLight_mps, 1e-6);
}

TEST(MeasurementsModel, SubNanosecondBiasIsKept) {
  const std::int64_t rx = kWeek2200 + 1000 * kNsPerS;
  GnssRawSample r = row_at(rx, 1, 5, kGpsOk);
  r.received_sv_time_nanos = 1000 * kNsPerS - kTravelNs;
  r.bias_nanos = 0.25;  // receive time 0.25 ns earlier -> pseudorange 7.5 cm shorter
  EXPECT_NEAR(pr_of(r), kTravelS * kSpeedOfLight_mps - 0.25e-9 * kSpeedOfLight_mps, 1e-6);
}

TEST(MeasurementsModel, BeidouUsesBdtAndItsWeek) {
  const std::int64_t rx = kWeek2200 + 5 * kNsPerS;  // BDT is 14 s behind: previous BDT week
  GnssRawSample r = row_at(rx, 5, 19, kGpsOk);
  r.received_sv_time_nanos = geo::kNsPerWeek - 9 * kNsPerS - kTravelNs;
  EXPECT_NEAR(pr_of(r), kTravelS * kSpeedOfLight_mps, 1e-6);
}

TEST(MeasurementsModel, GlonassTimeOfDayAcrossTheDayBoundary) {
  // GLONASS tod = GPST - 18 s + 3 h (mod day); choose rx 20 ms after the GLONASS midnight
  const std::int64_t day0 = std::int64_t{20000} * geo::kNsPerDay;
  const std::int64_t rx = day0 - 3 * 3600 * kNsPerS + 18 * kNsPerS + 20 * kNsPerMs;
  GnssRawSample r = row_at(rx, 3, 5, state_bit::kCodeLock | state_bit::kGloTodDecoded);
  r.received_sv_time_nanos = geo::kNsPerDay - 50 * kNsPerMs;
  EXPECT_NEAR(pr_of(r), kTravelS * kSpeedOfLight_mps, 1e-6);
}

TEST(MeasurementsModel, GalileoSecondaryCodeHas100MsAmbiguity) {
  const std::int64_t rx = kWeek2200 + 77 * kNsPerS + 31 * kNsPerMs;
  const std::int64_t st = state_bit::kCodeLock | state_bit::kGalE1bcCodeLock | state_bit::kGalE1c2ndCodeLock;
  GnssRawSample r = row_at(rx, 6, 11, st);
  const std::int64_t travel = 85 * kNsPerMs;
  r.received_sv_time_nanos = ((rx - kWeek2200) - travel) % (100 * kNsPerMs);
  EXPECT_NEAR(pr_of(r), 0.085 * kSpeedOfLight_mps, 1e-6);
  // with TOW decoded the full time of week is used
  r.state = st | state_bit::kTowDecoded;
  r.received_sv_time_nanos = (rx - kWeek2200) - travel;
  EXPECT_NEAR(pr_of(r), 0.085 * kSpeedOfLight_mps, 1e-6);
}

TEST(MeasurementsModel, StateBitsGateTheCodePhase) {
  const std::int64_t rx = kWeek2200 + 1000 * kNsPerS;
  std::string why;
  GnssRawSample r = row_at(rx, 1, 5, state_bit::kCodeLock | state_bit::kBitSync);  // no TOW
  r.received_sv_time_nanos = 1000 * kNsPerS - kTravelNs;
  EXPECT_TRUE(std::isnan(pr_of(r, &why)));
  EXPECT_EQ(why, "code: time of week not decoded");
  r.state = state_bit::kTowDecoded;  // no code lock
  EXPECT_TRUE(std::isnan(pr_of(r, &why)));
  EXPECT_EQ(why, "code: no code lock");
  r = row_at(rx, 3, 5, state_bit::kCodeLock | state_bit::kGloStringSync);
  r.received_sv_time_nanos = 1;
  EXPECT_TRUE(std::isnan(pr_of(r, &why)));
  EXPECT_EQ(why, "code: GLONASS time of day not decoded");
}

TEST(MeasurementsModel, DefaultCarrierFrequencies) {
  EXPECT_DOUBLE_EQ(default_carrier_hz(Constellation::kGps), 1575.42e6);
  EXPECT_DOUBLE_EQ(default_carrier_hz(Constellation::kBeidou), 1561.098e6);
  EXPECT_DOUBLE_EQ(default_carrier_hz(Constellation::kGlonass, -7), 1598.0625e6);
  EXPECT_DOUBLE_EQ(default_carrier_hz(Constellation::kGlonass, 6), 1605.375e6);
}

TEST(MeasurementsModel, BuildEpochCountsEveryBadValue) {
  const std::int64_t rx = kWeek2200 + 1000 * kNsPerS;
  auto good = [&](int svid) {
    GnssRawSample r = row_at(rx, 1, svid, kGpsOk);
    r.received_sv_time_nanos = 1000 * kNsPerS - kTravelNs;
    return r;
  };
  std::vector<GnssRawSample> rows;
  rows.push_back(good(1));
  GnssRawSample weak = good(2); weak.cn0_dbhz = 12.0; rows.push_back(weak);
  GnssRawSample nan_cn0 = good(3); nan_cn0.cn0_dbhz = kNaN; rows.push_back(nan_cn0);
  GnssRawSample huge = good(4); huge.accumulated_delta_range_uncertainty_m = 3.4028234663852886e38; rows.push_back(huge);
  GnssRawSample slip = good(5); slip.accumulated_delta_range_state = adr_bit::kValid | adr_bit::kCycleSlip; rows.push_back(slip);
  GnssRawSample sbas = good(120); sbas.constellation_type = 2; rows.push_back(sbas);
  GnssRawSample bad_rate = good(7); bad_rate.pseudorange_rate_mps = std::numeric_limits<double>::infinity(); rows.push_back(bad_rate);
  GnssRawSample bad_unc = good(8); bad_unc.received_sv_time_uncertainty_nanos = 1'000'000'000; rows.push_back(bad_unc);
  GnssRawSample nan_adr = good(9); nan_adr.accumulated_delta_range_m = kNaN; rows.push_back(nan_adr);
  MeasurementEpoch ep;
  ExclusionCounts ex;
  ASSERT_TRUE(build_epoch(rows, MeasurementOptions{}, ep, ex));
  EXPECT_EQ(ex["cn0 < 15 dB-Hz"], 1);
  EXPECT_EQ(ex["cn0: missing"], 1);
  EXPECT_EQ(ex["unsupported constellation"], 1);
  EXPECT_EQ(ex["adr: cycle slip"], 1);
  EXPECT_EQ(ex["doppler: missing or non-finite"], 1);
  EXPECT_EQ(ex["code: uncertainty too large"], 1);
  EXPECT_EQ(ex["adr: non-finite value"], 1);
  ASSERT_EQ(ep.meas.size(), 6u);  // 1, 4, 5, 7, 8 (rate + ADR only), 9
  for (const Measurement& m : ep.meas) {
    if (m.sat.prn == 4) { EXPECT_TRUE(m.adr_ok()); EXPECT_TRUE(std::isnan(m.adr_sigma_m)); }
    if (m.sat.prn == 5) EXPECT_FALSE(m.adr_ok());
    if (m.sat.prn == 8) EXPECT_FALSE(m.code_ok());
    if (m.code_ok()) {
      EXPECT_NEAR(m.pseudorange_m, kTravelS * kSpeedOfLight_mps, 1e-6);
      EXPECT_EQ(m.transmit_gps_ns, rx - kTravelNs);
    }
  }
}

TEST(MeasurementsModel, OneL1SignalPerSatellite) {
  const std::int64_t rx = kWeek2200 + 1000 * kNsPerS;
  GnssRawSample l1 = row_at(rx, 1, 5, kGpsOk);
  l1.received_sv_time_nanos = 1000 * kNsPerS - kTravelNs;
  l1.carrier_frequency_hz = 1575.42e6;
  GnssRawSample l5 = l1;
  l5.carrier_frequency_hz = 1176.45e6;
  GnssRawSample l1_again = l1;
  l1_again.cn0_dbhz = 45.0;
  MeasurementEpoch ep;
  ExclusionCounts ex;
  ASSERT_TRUE(build_epoch({l1, l5, l1_again}, MeasurementOptions{}, ep, ex));
  ASSERT_EQ(ep.meas.size(), 1u);
  EXPECT_DOUBLE_EQ(ep.meas[0].cn0_dbhz, 45.0);
  EXPECT_EQ(ex["signal: not L1/E1/B1 (one band used)"], 1);
  EXPECT_EQ(ex["signal: duplicate satellite in epoch"], 1);
}

TEST(MeasurementsModel, EpochWithoutGpsTimeIsRejected) {
  GnssRawSample r = row_at(kWeek2200, 1, 1, kGpsOk);
  r.full_bias_nanos = kMissingInt;
  MeasurementEpoch ep;
  ExclusionCounts ex;
  EXPECT_FALSE(build_epoch({r}, MeasurementOptions{}, ep, ex));
  EXPECT_EQ(ex["epoch: no GPS time (FullBiasNanos missing)"], 1);
  EXPECT_FALSE(build_epoch({}, MeasurementOptions{}, ep, ex));
}

}  // namespace
}  // namespace pdnav::gnss

namespace pdnav::gnss {
namespace {

// FrequencyMode::kBest: GPS has five satellites with L1 and L5 (moved to L5: code, Doppler
// and carrier of the L5 row), Galileo two with E5a among five (fewer than dual_min_sats = 4:
// the group stays on E1, its E5a rows are counted).
TEST(MeasurementsModel, BestBandMovesAClockGroupWithEnoughL5CodesToL5) {
  const std::int64_t rx = kWeek2200 + 345'678 * kNsPerS;
  std::vector<GnssRawSample> rows;
  auto add = [&](int constellation, int svid, double carrier_hz, double adr_m) {
    GnssRawSample r = row_at(rx, constellation, svid, kGpsOk | state_bit::kGalE1c2ndCodeLock);
    r.received_sv_time_nanos = (rx - kWeek2200) - kTravelNs - svid * 1'000'000;
    r.carrier_frequency_hz = carrier_hz;
    r.accumulated_delta_range_m = adr_m;
    rows.push_back(r);
  };
  for (int sv = 1; sv <= 5; ++sv) {
    add(1, sv, 1575.42e6, 100.0);
    add(1, sv, 1176.45e6, 500.0);
    add(6, sv, 1575.42e6, 100.0);
    if (sv <= 2) add(6, sv, 1176.45e6, 500.0);
  }
  MeasurementOptions opt;
  opt.frequency = FrequencyMode::kBest;
  MeasurementEpoch ep;
  ExclusionCounts ex;
  ASSERT_TRUE(build_epoch(rows, opt, ep, ex));
  ASSERT_EQ(ep.meas.size(), 10u);
  for (const Measurement& m : ep.meas) {
    const bool gps = m.sat.sys == Constellation::kGps;
    EXPECT_EQ(l5_band(m.sat.sys, m.carrier_hz), gps) << m.sat.to_string();
    EXPECT_EQ(m.adr_m, gps ? 500.0 : 100.0) << m.sat.to_string();
    EXPECT_TRUE(m.code_ok()) << m.sat.to_string();
  }
  EXPECT_EQ(ex["best: L5/E5a signal used instead of L1"], 5);
  EXPECT_EQ(ex["best: too few L5/E5a codes in the clock group (L1 kept)"], 2);
  // single frequency: everything on L1
  opt.frequency = FrequencyMode::kSingle;
  MeasurementEpoch l1;
  ASSERT_TRUE(build_epoch(rows, opt, l1, ex));
  for (const Measurement& m : l1.meas) EXPECT_FALSE(l5_band(m.sat.sys, m.carrier_hz)) << m.sat.to_string();
}

}  // namespace
}  // namespace pdnav::gnss
