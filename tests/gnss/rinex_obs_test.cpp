// RINEX 3 observation reader and writer: known-answer parsing, the conversion to Android Raw
// rows (the code must come back to the RINEX value through measurements.h), malformed input
// counted or rejected with a reason, and the write -> read round trip on the real Mountain
// View log (every code, phase and Doppler value and the engine's solutions).
#include <cmath>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/gnss_engine.h"
#include "pdnav/gnss/measurements.h"
#include "pdnav/gnss/rinex_obs.h"
#include "pdnav/io/log_reader.h"
#include "test_data.h"

namespace pdnav::gnss {
namespace {

std::string pad(const std::string& body, const std::string& label) {
  std::string b = body;
  b.resize(60, ' ');
  return b + label + "\n";
}

std::string header() {
  return pad("     3.03           OBSERVATION DATA    M", "RINEX VERSION / TYPE") +
         pad("G    8 C1C L1C D1C S1C C5X L5X D5X S5X", "SYS / # / OBS TYPES") +
         pad("R    4 C1C L1C D1C S1C", "SYS / # / OBS TYPES") +
         pad("  2021    04    28    22    19   22.4299102     GPS", "TIME OF FIRST OBS") +
         pad(" 2 R05  1 R09 -2", "GLONASS SLOT / FRQ #") + pad("", "END OF HEADER");
}

const char* kBody =
    "> 2021 04 28 22 19 22.4299102  0  3\n"
    "G05  23738869.07025    -16670.84725      3433.06825        33.40025\n"
    "G06  22542877.93724        -0.00024     -2926.05024        26.40024  22540519.77005      7322.44915     -2184.66505        31.00005\n"
    "R09                        -0.00023     -4254.10023        19.60023\n"
    "> 2021 04 28 22 19 23.4299102  0  1\n"
    "G05  23738226.47326    -20104.60226      3433.79526        36.90026\n";

std::vector<RinexObsEpoch> read_all(const std::string& text, RinexObsHeader* hdr = nullptr,
                                    RinexObsReport* rep = nullptr) {
  std::istringstream in(text);
  RinexObsReader r(in, "mem.obs");
  std::vector<RinexObsEpoch> out;
  RinexObsEpoch e;
  while (r.next(e)) out.push_back(e);
  if (hdr) *hdr = r.header();
  if (rep) *rep = r.report();
  return out;
}

TEST(RinexObs, ParsesEpochsSignalsAndFlags) {
  RinexObsHeader hdr;
  const auto eps = read_all(header() + kBody, &hdr);
  EXPECT_DOUBLE_EQ(hdr.version, 3.03);
  EXPECT_EQ(hdr.obs_types.at('G').size(), 8u);
  EXPECT_EQ(hdr.glonass_channel.at(9), -2);
  ASSERT_EQ(eps.size(), 2u);
  // 2021-04-28 22:19:22.4299102 GPS = week 2155, tow 3*86400 + 80362.4299102
  EXPECT_EQ(eps[0].gps_ns, geo::week_tow_to_gps_ns(2155, 0) + (3 * 86400 + 80362) * kNsPerS + 429910200);
  EXPECT_EQ(eps[1].gps_ns - eps[0].gps_ns, kNsPerS);
  ASSERT_EQ(eps[0].sats.size(), 3u);
  const RinexSatObs& g06 = eps[0].sats[1];
  EXPECT_EQ(g06.sat.to_string(), "G06");
  ASSERT_EQ(g06.signals.size(), 2u);
  EXPECT_EQ(g06.signals[1].code, "5X");
  EXPECT_DOUBLE_EQ(g06.signals[1].pseudorange_m, 22540519.770);
  EXPECT_DOUBLE_EQ(g06.signals[1].phase_cycles, 7322.449);
  EXPECT_EQ(g06.signals[1].phase_lli, 1);  // LLI 1: loss of lock
  EXPECT_EQ(g06.signals[0].phase_lli, 2);
  EXPECT_DOUBLE_EQ(g06.signals[0].cn0_dbhz, 26.4);
  EXPECT_TRUE(std::isnan(eps[0].sats[2].signals[0].pseudorange_m));  // R09 has no code
}

TEST(RinexObs, RawRowsGiveBackTheRinexObservables) {
  RinexObsHeader hdr;
  const auto eps = read_all(header() + kBody, &hdr);
  std::map<std::string, std::int64_t> skipped;
  const auto rows = rinex_epoch_to_raw(eps[0], hdr, skipped);
  ASSERT_EQ(rows.size(), 4u);  // G05 L1, G06 L1 + L5, R09 L1
  MeasurementEpoch ep;
  ExclusionCounts ex;
  ASSERT_TRUE(build_epoch(rows, MeasurementOptions{}, ep, ex));
  EXPECT_EQ(ep.rx.ns, eps[0].gps_ns);
  const Measurement* g05 = nullptr;
  for (const auto& m : ep.meas) if (m.sat.to_string() == "G05") g05 = &m;
  ASSERT_NE(g05, nullptr);
  EXPECT_NEAR(g05->pseudorange_m, 23738869.070, 1e-6);
  const double lambda = kSpeedOfLight_mps / 1575.42e6;
  EXPECT_NEAR(g05->adr_m, -16670.847 * lambda, 1e-9);
  EXPECT_NEAR(g05->pr_rate_mps, -3433.068 * lambda, 1e-9);
  // the GLONASS row carries its FDMA frequency (k = -2 from the header)
  bool r09 = false;
  for (const auto& r : rows)
    if (r.constellation_type == 3 && r.svid == 9) { r09 = true; EXPECT_DOUBLE_EQ(r.carrier_frequency_hz, 1602.0e6 - 2 * 0.5625e6); }
  EXPECT_TRUE(r09);
}

TEST(RinexObs, BadInputIsAnErrorWithAReasonOrACountedSkip) {
  auto throws_with = [](const std::string& text, const std::string& what) {
    try {
      read_all(text);
      ADD_FAILURE() << "no exception for: " << what;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  throws_with("", "empty file");
  throws_with("Raw,1,2,3\n", "not a RINEX observation file");
  throws_with(pad("     2.11           OBSERVATION DATA    M", "RINEX VERSION / TYPE") + pad("", "END OF HEADER"),
              "not supported");
  throws_with(pad("     3.03           OBSERVATION DATA    M", "RINEX VERSION / TYPE"), "before END OF HEADER");
  throws_with(pad("     3.03           OBSERVATION DATA    M", "RINEX VERSION / TYPE") + pad("", "END OF HEADER"),
              "no SYS / # / OBS TYPES");
  RinexObsReport rep;
  const std::string broken = header() +
                             "> 2021 04 28 22 19 2x.4299102  0  1\nG05  1.0\n"
                             "> 2021 04 28 22 19 22.4299102  0  2\nX05  23738869.070\nG05  2373886X.070\n"
                             "> 2021 04 28 22 19 23.4299102  0  5\nG05  23738226.473\n";
  const auto eps = read_all(broken, nullptr, &rep);
  ASSERT_EQ(eps.size(), 1u);          // the middle epoch, with no usable satellite left
  EXPECT_TRUE(eps[0].sats.empty());
  EXPECT_EQ(rep.skipped_by_reason.at("epoch: malformed epoch line"), 1);
  EXPECT_EQ(rep.skipped_by_reason.at("satellite: malformed satellite record"), 1);
  EXPECT_EQ(rep.skipped_by_reason.at("satellite: non-numeric observation"), 1);
  EXPECT_EQ(rep.skipped_by_reason.at("epoch: file ends inside an epoch"), 1);
  EXPECT_GE(rep.skipped_by_reason.at("record outside an epoch"), 1);
}

TEST(RinexObs, PowerFailureFlagIsAClockDiscontinuity) {
  RinexObsHeader hdr;
  const std::string text = header() + "> 2021 04 28 22 19 22.4299102  0  1\nG05  23738869.070\n" +
                           "> 2021 04 28 22 19 23.4299102  1  1\nG05  23738226.473\n";
  const auto eps = read_all(text, &hdr);
  ASSERT_EQ(eps.size(), 2u);
  std::map<std::string, std::int64_t> skipped;
  EXPECT_NE(rinex_epoch_to_raw(eps[0], hdr, skipped)[0].hardware_clock_discontinuity_count,
            rinex_epoch_to_raw(eps[1], hdr, skipped)[0].hardware_clock_discontinuity_count);
}

// ---- write -> read on the real Mountain View log (GnssLogger v1.4, GPS/GLONASS/Galileo/BeiDou)

std::vector<GnssRawSample> mountainview_rows() {
  io::LogReader reader(test::shared_data("gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt"));
  std::vector<GnssRawSample> rows;
  Sample s;
  while (reader.next(s))
    if (const auto* r = std::get_if<GnssRawSample>(&s)) rows.push_back(*r);
  return rows;
}

std::string write_rinex(const std::vector<GnssRawSample>& rows, std::map<std::string, int>* skipped = nullptr) {
  RinexObsWriter w;
  for (const auto& r : rows) {
    std::string why;
    if (!w.add(r, &why) && skipped) ++(*skipped)[why];
  }
  std::ostringstream out;
  w.finish(out);
  return out.str();
}

std::vector<EpochSolution> solve(const std::vector<std::vector<GnssRawSample>>& epochs) {
  auto store = std::make_shared<EphemerisStore>();
  store->load_rinex_nav(test::shared_data("gnss-mountainview/hour2350.16n"));
  GnssEngine engine(GnssOptions{}, store, 1);
  for (const auto& ep : epochs) {
    for (const auto& r : ep) engine.feed(r);
    engine.flush();
  }
  return engine.take_solutions();
}

TEST(RinexObsRoundTrip, MountainViewLogWrittenAndReadBackIsLossless) {
  const auto rows = mountainview_rows();
  ASSERT_GT(rows.size(), 1000u);
  std::map<std::string, int> skipped;
  const std::string text = write_rinex(rows, &skipped);
  RinexObsHeader hdr;
  const auto eps = read_all(text, &hdr);
  ASSERT_GT(eps.size(), 200u);
  // same code per satellite and epoch through the measurement layer (mm: the RINEX resolution)
  std::vector<std::vector<GnssRawSample>> from_log, from_rinex;
  for (const auto& r : rows) {
    if (from_log.empty() || from_log.back().front().time_nanos != r.time_nanos) from_log.emplace_back();
    from_log.back().push_back(r);
  }
  std::map<std::string, std::int64_t> sk;
  for (const auto& e : eps) from_rinex.push_back(rinex_epoch_to_raw(e, hdr, sk));
  int compared = 0;
  double worst_code_m = 0.0;
  std::size_t j = 0;
  for (const auto& le : from_log) {
    MeasurementEpoch a, b;
    ExclusionCounts ex;
    if (!build_epoch(le, MeasurementOptions{}, a, ex)) continue;
    while (j < from_rinex.size() && std::llabs(from_rinex[j].front().t_ns - a.rx.ns) > 1000) ++j;
    ASSERT_LT(j, from_rinex.size());
    ASSERT_TRUE(build_epoch(from_rinex[j], MeasurementOptions{}, b, ex));
    for (const auto& ma : a.meas) {
      for (const auto& mb : b.meas) {
        if (!(ma.sat == mb.sat) || !ma.code_ok()) continue;
        ASSERT_TRUE(mb.code_ok()) << ma.sat.to_string();
        worst_code_m = std::max(worst_code_m, std::fabs(ma.pseudorange_m - mb.pseudorange_m));
        EXPECT_NEAR(ma.cn0_dbhz, mb.cn0_dbhz, 0.0006);
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 1500);
  EXPECT_LT(worst_code_m, 0.0006);
  // and the engine gives the same solution from both
  const auto sa = solve(from_log), sb = solve(from_rinex);
  ASSERT_EQ(sa.size(), sb.size());
  double worst_spp_m = 0.0, worst_kf_m = 0.0;
  int both = 0;
  for (std::size_t i = 0; i < sa.size(); ++i) {
    EXPECT_EQ(sa[i].spp_ok, sb[i].spp_ok) << i;
    if (sa[i].spp_ok && sb[i].spp_ok) {
      worst_spp_m = std::max(worst_spp_m, (sa[i].spp.p_m - sb[i].spp.p_m).norm());
      ++both;
    }
    if (sa[i].kf_ok && sb[i].kf_ok) worst_kf_m = std::max(worst_kf_m, (sa[i].kf.p_m - sb[i].kf.p_m).norm());
  }
  EXPECT_GT(both, 190);
  std::printf("round trip: %d signals compared, worst code %.4f m, worst SPP %.4f m, worst KF %.4f m\n", compared,
              worst_code_m, worst_spp_m, worst_kf_m);
  EXPECT_LT(worst_spp_m, 0.01);
  EXPECT_LT(worst_kf_m, 0.3);  // the KF differs only where ADR reset/slip states map to one LLI bit
}

}  // namespace
}  // namespace pdnav::gnss
