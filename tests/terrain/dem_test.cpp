// DEM tile reader and bilinear lookups: exact on planes, validity flags, every malformed-file path.
#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pdnav/terrain/dem.h"
#include "synthetic_dem.h"
#include "test_data.h"

namespace pdnav::terrain {
namespace {

using ::testing::HasSubstr;
using test::pdem_bytes;
using test::synthetic_dem;
using test::synthetic_info;

Dem parse_string(const std::string& s) {
  return Dem::parse(reinterpret_cast<const std::uint8_t*>(s.data()), s.size(), "mem.pdem");
}

std::string error_of(const std::string& bytes) {
  try {
    parse_string(bytes);
  } catch (const DemError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Dem, BilinearIsExactOnAPlane) {
  const Dem dem = synthetic_dem(11, 9, 30.0, [](double e, double n) { return 1000.0 + 0.3 * e - 0.2 * n; });
  for (double e : {-140.0, -77.7, 0.0, 12.3, 149.9}) {
    for (double n : {-119.0, -3.3, 0.0, 55.5, 119.9}) {
      const DemSample s = dem.at_local(e, n);
      ASSERT_TRUE(s.valid()) << e << "," << n;
      EXPECT_NEAR(s.elevation_m, 1000.0 + 0.3 * e - 0.2 * n, 1e-3);
      EXPECT_NEAR(dem.elevation_or_nan(static_cast<float>(e), static_cast<float>(n)), s.elevation_m, 2e-3);
    }
  }
}

TEST(Dem, OffMapAndVoidAreFlaggedNotNaNValued) {
  DemInfo info = synthetic_info(4, 4, 10.0);
  std::vector<float> v(16, 500.0f);
  v[5] = std::numeric_limits<float>::quiet_NaN();  // node (1,1) void
  const Dem dem = Dem::from_grid(info, v);
  EXPECT_EQ(dem.info().voids, 1);
  EXPECT_EQ(dem.at_local(-15.0 + 10.0, -15.0 + 10.0).validity, DemValidity::kVoid);
  EXPECT_EQ(dem.at_local(-15.0 + 25.0, -15.0 + 25.0).validity, DemValidity::kValid);  // cell (2,2) clear of the void
  EXPECT_EQ(dem.at_local(100.0, 0.0).validity, DemValidity::kOffMap);
  EXPECT_EQ(dem.at_local(std::nan(""), 0.0).validity, DemValidity::kOffMap);
  EXPECT_TRUE(std::isnan(dem.elevation_or_nan(1e9f, 0.0f)));
  EXPECT_TRUE(std::isnan(dem.elevation_or_nan(-5.0f, -5.0f)));  // touches the void node
  EXPECT_STREQ(to_string(DemValidity::kOffMap), "off-map");
}

TEST(Dem, GeodeticLookupMatchesLocalFrame) {
  const Dem dem = synthetic_dem(101, 101, 50.0, test::hills);
  for (double e : {-2000.0, 0.0, 1234.5}) {
    for (double n : {-2100.0, 17.0, 2400.0}) {
      const geo::Geodetic g = dem.to_geodetic(e, n);
      const Eigen::Vector2d back = dem.to_local(g);
      EXPECT_NEAR(back.x(), e, 1e-4);
      EXPECT_NEAR(back.y(), n, 1e-4);
      EXPECT_NEAR(dem.at(g).elevation_m, dem.at_local(e, n).elevation_m, 1e-6);
    }
  }
}

TEST(Dem, RoundTripThroughTheFileFormat) {
  const DemInfo info = synthetic_info(5, 3, 20.0);
  std::vector<float> v{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, -32768, 12, 13, 14, 15};
  const auto dir = test::scratch_dir("terrain_dem_roundtrip");
  const std::string path = (dir / "t.pdem").string();
  {
    std::ofstream f(path, std::ios::binary);
    f << pdem_bytes(info, v, "source_sha256 abc\n");
  }
  const Dem dem = Dem::load(path);
  EXPECT_EQ(dem.info().cols, 5);
  EXPECT_EQ(dem.info().rows, 3);
  EXPECT_EQ(dem.info().voids, 1);
  EXPECT_EQ(dem.info().source_sha256, "abc");
  EXPECT_FLOAT_EQ(dem.node(2, 1), 8.0f);  // row-major, south row first
  EXPECT_TRUE(std::isnan(dem.node(0, 2)));
  EXPECT_NEAR(dem.at_local(info.x0_m + 10.0, info.y0_m).elevation_m, 1.5, 1e-9);
}

TEST(Dem, MalformedFilesGiveClearErrors) {
  const DemInfo info = synthetic_info(3, 3, 10.0);
  const std::vector<float> v(9, 100.0f);
  const std::string good = pdem_bytes(info, v);
  ASSERT_NO_THROW(parse_string(good));
  EXPECT_THAT(error_of(""), HasSubstr("empty file"));
  EXPECT_THAT(error_of("GIF89a\n"), HasSubstr("bad magic"));
  EXPECT_THAT(error_of(good.substr(0, good.size() - 3)), HasSubstr("truncated"));
  EXPECT_THAT(error_of(good + "xx"), HasSubstr("trailing bytes"));
  std::string corrupt = good;
  corrupt[corrupt.size() - 2] ^= 0x10;
  EXPECT_THAT(error_of(corrupt), HasSubstr("checksum mismatch"));
  std::string no_end = good.substr(0, good.find("end_header"));
  EXPECT_THAT(error_of(no_end), HasSubstr("end_header"));
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  EXPECT_THAT(error_of(replace("cols 3", "cols 2000000")), HasSubstr("out of range"));
  EXPECT_THAT(error_of(replace("cols 3", "cols 99999999999999")), HasSubstr("out of range"));
  EXPECT_THAT(error_of(replace("cols 3", "cols x3")), HasSubstr("not an integer"));
  EXPECT_THAT(error_of(replace("cell_m 10", "cell_m nan")), HasSubstr("cell_m"));
  EXPECT_THAT(error_of(replace("crs local_enu", "crs utm31")), HasSubstr("unsupported crs"));
  EXPECT_THAT(error_of(replace("PDEM 1", "PDEM 7")), HasSubstr("unsupported .pdem version"));
  EXPECT_THAT(error_of(replace("vertical_datum EGM96\n", "")), HasSubstr("missing key 'vertical_datum'"));
  EXPECT_THAT(error_of(replace("source test\n", "source test\nsource again\n")), HasSubstr("duplicate key"));
  EXPECT_THAT(error_of(pdem_bytes(info, std::vector<float>(9, -32768.0f))), HasSubstr("every node is void"));
  try {
    Dem::load("/nonexistent/dir/x.pdem");
    FAIL() << "no exception";
  } catch (const DemError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/dir/x.pdem: cannot open"));
  }
}

TEST(Dem, Crc32MatchesZlib) {
  const std::string s = "123456789";
  EXPECT_EQ(crc32(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()), 0xCBF43926u);  // IEEE check value
}

}  // namespace
}  // namespace pdnav::terrain
