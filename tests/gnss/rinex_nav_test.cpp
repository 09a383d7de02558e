// RINEX navigation reader: real files (RINEX 2.10 GPS, RINEX 3.04 mixed) and malformed input.
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/rinex.h"
#include "gps_calendar.h"
#include "test_data.h"

namespace pdnav::gnss {
namespace {

const char* kBrdm = "gnss-orbits-2023-073/BRDM00DLR_S_20230730000_01D_MN.rnx";
const char* kHour = "gnss-mountainview/hour2350.16n";

RinexNavData parse(const std::string& text) {
  std::istringstream in(text);
  return read_rinex_nav(in, "mem.rnx");
}

std::string expect_throw(const std::string& text) {
  try {
    parse(text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no exception";
  return {};
}

TEST(RinexNav, ParsesFortranDoubles) {
  EXPECT_DOUBLE_EQ(*parse_rinex_double(" 0.562459696084D-03"), 0.562459696084e-3);
  EXPECT_DOUBLE_EQ(*parse_rinex_double("-3.865352482535e-12"), -3.865352482535e-12);
  EXPECT_DOUBLE_EQ(*parse_rinex_double("   "), 0.0);
  EXPECT_FALSE(parse_rinex_double("0.12X-03"));
  EXPECT_FALSE(parse_rinex_double("nan"));
  EXPECT_FALSE(parse_rinex_double("1D999"));
}

TEST(RinexNav, Rinex2GpsFileKnownValues) {
  const RinexNavData nav = read_rinex_nav_file(test::shared_data(kHour));
  EXPECT_DOUBLE_EQ(nav.version, 2.0);
  EXPECT_EQ(nav.report.skipped_total(), 0);
  EXPECT_EQ(nav.report.records_by_system.at("GPS"), (3360 - 8) / 8);
  ASSERT_TRUE(nav.klobuchar);
  EXPECT_DOUBLE_EQ(nav.klobuchar->alpha[0], 0.5588e-08);
  EXPECT_DOUBLE_EQ(nav.klobuchar->beta[3], -0.2621e+06);
  // First record: PRN 2, 2016-08-22 00:00:00 GPST = week 1911, 86400 s.
  const KeplerEphemeris& g2 = nav.kepler.front();
  EXPECT_EQ(g2.sat.to_string(), "G02");
  EXPECT_EQ(g2.toc_gps_ns, geo::week_tow_to_gps_ns(1911, 86400.0));
  EXPECT_EQ(g2.toe_gps_ns, g2.toc_gps_ns);
  EXPECT_DOUBLE_EQ(g2.af0_s, 0.562459696084e-03);
  EXPECT_DOUBLE_EQ(g2.sqrt_a_sqrtm, 0.515361358261e+04);
  EXPECT_DOUBLE_EQ(g2.group_delay_s, -0.204890966415e-07);
  EXPECT_EQ(g2.iode, 65);
}

TEST(RinexNav, Rinex3MixedFileCountsAndTimeScales) {
  const RinexNavData nav = read_rinex_nav_file(test::shared_data(kBrdm));
  EXPECT_DOUBLE_EQ(nav.version, 3.04);
  EXPECT_EQ(nav.report.records_by_system.at("GPS"), 6);
  EXPECT_EQ(nav.report.records_by_system.at("GLONASS"), 7);
  EXPECT_EQ(nav.report.records_by_system.at("Galileo"), 6);
  EXPECT_EQ(nav.report.records_by_system.at("BeiDou"), 6);
  EXPECT_EQ(nav.report.records_by_system.at("QZSS"), 6);
  EXPECT_EQ(nav.report.skipped_by_reason.at("IRNSS not supported"), 6);
  EXPECT_EQ(nav.report.skipped_by_reason.at("SBAS not supported"), 6);
  EXPECT_EQ(nav.report.skipped_total(), 12);
  ASSERT_TRUE(nav.klobuchar);  // GPSA / GPSB, not QZSA / BDSA
  EXPECT_DOUBLE_EQ(nav.klobuchar->alpha[0], 2.6077e-08);
  EXPECT_DOUBLE_EQ(nav.klobuchar->beta[3], 1.3107e+05);
  for (const auto& k : nav.kepler) {
    if (k.sat.to_string() == "C01") {  // BDT epoch 00:00:00 = GPST 00:00:14
      EXPECT_EQ(k.toc_gps_ns, test::gps_calendar_ns(2023, 3, 14, 0, 0, 14.0));
      EXPECT_TRUE(k.bds_geo);
      break;
    }
  }
  for (const auto& k : nav.kepler) {
    if (k.sat.to_string() == "E01") {  // I/NAV E5b (data sources 516 = bits 2, 9): BGD(E1,E5b)
      EXPECT_EQ(k.data_source, 516);
      EXPECT_DOUBLE_EQ(k.group_delay_s, 2.328306436539e-10);
      EXPECT_EQ(k.toe_gps_ns, geo::week_tow_to_gps_ns(2253, 172800.0));
      break;
    }
  }
  // GLONASS: RINEX epoch is UTC; 18 leap seconds in 2023.
  const GlonassEphemeris& r01 = nav.glonass.front();
  EXPECT_EQ(r01.sat.to_string(), "R01");
  EXPECT_EQ(r01.tb_gps_ns, test::gps_calendar_ns(2023, 3, 14, 0, 15, 18.0));
  EXPECT_EQ(r01.channel, 1);
  EXPECT_DOUBLE_EQ(r01.pos_m.x(), 5.763751464844e+06);
  EXPECT_DOUBLE_EQ(r01.acc_mps2.y(), -9.313225746155e-07);
}

const char* kHeader3 =
    "     3.04           NAVIGATION DATA     M                   RINEX VERSION / TYPE\n"
    "GPSA   2.6077e-08  7.4506e-09 -1.1921e-07  0.0000e+00       IONOSPHERIC CORR    \n"
    "                                                            END OF HEADER       \n";

const char* kG01 =
    "G01 2023 03 14 00 00 00 2.030883915722e-04-3.865352482535e-12 0.000000000000e+00\n"
    "     1.200000000000e+01-7.940625000000e+01 3.783729036073e-09 2.407791404577e+00\n"
    "    -4.297122359276e-06 1.251155254431e-02 6.118789315224e-06 5.153655818939e+03\n"
    "     1.728000000000e+05-5.587935447693e-09-2.637111594763e+00-1.918524503708e-07\n"
    "     9.847149365104e-01 2.361875000000e+02 1.023197438990e+00-8.031048659028e-09\n"
    "     4.928776451804e-10 1.000000000000e+00 2.253000000000e+03 0.000000000000e+00\n"
    "     2.000000000000e+00 0.000000000000e+00 4.656612873077e-10 1.200000000000e+01\n"
    "     1.655580000000e+05\n";

TEST(RinexNav, BadHeadersThrowWithFileAndLine) {
  EXPECT_EQ(expect_throw(""), "mem.rnx:0: empty file");
  EXPECT_NE(expect_throw("hello world\n").find("mem.rnx:1: not a RINEX file"), std::string::npos);
  EXPECT_NE(expect_throw("     4.00           NAVIGATION DATA     M                   RINEX VERSION / TYPE\n")
                .find("unsupported RINEX version"),
            std::string::npos);
  EXPECT_NE(expect_throw("     3.04           OBSERVATION DATA    M                   RINEX VERSION / TYPE\n")
                .find("not a navigation file"),
            std::string::npos);
  EXPECT_NE(expect_throw("     3.04           NAVIGATION DATA     M                   RINEX VERSION / TYPE\n"
                         "whatever                                                    COMMENT\n")
                .find("mem.rnx:2: no END OF HEADER"),
            std::string::npos);
}

TEST(RinexNav, ShortLastLineIsAcceptedAndBadRecordsAreCountedWithLines) {
  const RinexNavData ok = parse(std::string(kHeader3) + kG01);
  EXPECT_EQ(ok.kepler.size(), 1u);
  EXPECT_EQ(ok.report.skipped_total(), 0);

  std::string bad_number = kG01;
  bad_number.replace(bad_number.find("5.153655818939e+03"), 18, "5.15365581xxxxe+03");
  std::string truncated = kG01;
  truncated.resize(truncated.find("     9.847"));
  const std::string text = std::string(kHeader3) + bad_number + truncated + "X01 2023 03 14 00 00 00\n" +
                           "     1.0 orphan\n" + kG01;
  RinexNavData nav;
  ASSERT_NO_THROW(nav = parse(text));
  EXPECT_EQ(nav.kepler.size(), 1u);
  EXPECT_EQ(nav.report.skipped_by_reason.at("non-numeric field '5.15365581xxxxe+03'"), 1);
  EXPECT_EQ(nav.report.skipped_by_reason.at("truncated record"), 1);
  EXPECT_EQ(nav.report.skipped_by_reason.at("unknown system 'X'"), 1);
  ASSERT_GE(nav.report.issues.size(), 3u);
  EXPECT_EQ(nav.report.issues[0], "mem.rnx:4: non-numeric field '5.15365581xxxxe+03'");
  EXPECT_EQ(nav.report.issues[1], "mem.rnx:12: truncated record");
}

TEST(RinexNav, ImplausibleValuesAreRejectedNotPropagated) {
  std::string huge = kG01;
  huge.replace(huge.find("5.153655818939e+03"), 18, "3.400000000000e+38");
  const RinexNavData nav = parse(std::string(kHeader3) + huge);
  EXPECT_TRUE(nav.kepler.empty());
  EXPECT_EQ(nav.report.skipped_by_reason.at("implausible sqrt(A)"), 1);
}

// RINEX 2.11 GLONASS navigation file (type 'G'): R01 of the mixed file rewritten in the
// RINEX 2 layout (2-digit year, 3-column continuation indent, D exponents).
TEST(RinexNav, Rinex2GlonassFile) {
  const std::string text =
      "     2.11           G: GLONASS NAV DATA                     RINEX VERSION / TYPE\n"
      "                                                            END OF HEADER\n"
      " 1 23  3 14  0 15  0.0 0.247061252594D-04 0.000000000000D+00 0.172830000000D+06\n"
      "    0.576375146484D+04-0.129909038544D+01 0.000000000000D+00 0.000000000000D+00\n"
      "    0.118343261719D+05 0.269378376007D+01-0.931322574615D-09 0.100000000000D+01\n"
      "    0.218588710938D+05-0.111494159698D+01-0.279396772385D-08 0.000000000000D+00\n";
  const RinexNavData nav = parse(text);
  ASSERT_EQ(nav.glonass.size(), 1u);
  EXPECT_EQ(nav.glonass[0].sat.to_string(), "R01");
  EXPECT_EQ(nav.glonass[0].tb_gps_ns, test::gps_calendar_ns(2023, 3, 14, 0, 15, 18.0));
  EXPECT_DOUBLE_EQ(nav.glonass[0].vel_mps.z(), -0.111494159698e+01 * 1e3);
}

}  // namespace
}  // namespace pdnav::gnss
