// SP3 reader on malformed and edge-case input (the real file is covered in orbit_sp3_truth_test).
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/sp3.h"

namespace pdnav::gnss {
namespace {

Sp3File parse(const std::string& text) {
  std::istringstream in(text);
  return read_sp3(in, "mem.sp3");
}

const char* kHead =
    "#dP2023  3 14  0  0  0.00000000       2 ORBIT IGS20 FIT  XYZ\n"
    "## 2253 172800.00000000   300.00000000 60017 0.0000000000000\n";

TEST(Sp3Reader, UtcTimeSystemIsConvertedAndBadValuesDropped) {
  const std::string text = std::string(kHead) +
                           "%c M  cc UTC ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc\n"
                           "*  2023  3 14  0  0  0.00000000\n"
                           "PG01  21831.572967  14746.989380  -4963.026791 999999.999999\n"
                           "PG02      0.000000      0.000000      0.000000    -614.533740\n"
                           "PG03  12456.868448  16369.826965  1674X.318153    -350.241796\n"
                           "PR05  12456.868448  16369.826965  16745.318153    -350.241796\n"
                           "EOF\n";
  const Sp3File f = parse(text);
  EXPECT_EQ(f.version, 'd');
  EXPECT_EQ(f.time_system, "UTC");
  ASSERT_EQ(f.epochs.size(), 1u);
  EXPECT_EQ(f.epochs[0].gps_ns, (2253LL * 604800 + 172800 + 18) * kNsPerS);
  EXPECT_EQ(f.epochs[0].sats.size(), 2u);  // G01 (no clock) and R05
  EXPECT_FALSE(f.epochs[0].sats.at(SatId{Constellation::kGps, 1}).has_clock);
  EXPECT_EQ(f.skipped_lines, 2);
}

TEST(Sp3Reader, BadInputThrowsWithLine) {
  EXPECT_THROW(parse(""), std::runtime_error);
  EXPECT_THROW(parse("hello\n"), std::runtime_error);
  try {
    parse(std::string(kHead) + "PG01  21831.572967  14746.989380  -4963.026791 1.0\n");
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "mem.sp3:3: position record before the first epoch");
  }
  EXPECT_THROW(parse(std::string(kHead) + "%c M  cc GLO ccc\n"), std::runtime_error);
  EXPECT_THROW(parse(std::string(kHead) + "*  2023 13 14  0  0  0.00000000\n"), std::runtime_error);
}

}  // namespace
}  // namespace pdnav::gnss
