// dem-tools output read by the core: the Andorra SRTM tile (voids kept / filled) and a UTM
// GeoTIFF made with GDAL (a plane: the tile must reproduce it at geodetic check points).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "pdnav/terrain/dem.h"
#include "test_data.h"

namespace pdnav::terrain {
namespace {

std::string tool() { return std::string(PDNAV_SOURCE_DIR) + "/dem-tools/pdnav_dem.py"; }

int run(const std::string& cmd) {
  const int rc = std::system((cmd + " > /dev/null").c_str());
  return rc;
}

std::string andorra() {
  return "/vsizip/" + test::shared_data("terrain-andorra/N42E001.hgt.zip") + "/N42E001.hgt";
}

TEST(DemTools, AndorraTileKeepsOrFillsVoids) {
  const auto dir = test::scratch_dir("terrain_dem_tools_andorra");
  const std::string raw = (dir / "raw.pdem").string(), filled = (dir / "filled.pdem").string();
  const std::string area = " --center 42.72833 1.5275 --radius 1500 --cell 30";
  ASSERT_EQ(run("/usr/bin/python3 " + tool() + " tile " + andorra() + " -o " + raw + area), 0);
  ASSERT_EQ(run("/usr/bin/python3 " + tool() + " tile " + andorra() + " -o " + filled + area + " --fill-voids"), 0);
  const Dem a = Dem::load(raw);
  const Dem b = Dem::load(filled);
  EXPECT_GT(a.info().voids, 10);
  EXPECT_EQ(b.info().voids, 0);
  EXPECT_EQ(a.info().vertical_datum, "EGM96");
  EXPECT_EQ(a.info().source, "N42E001.hgt");
  EXPECT_EQ(a.at_local(0.0, 0.0).validity, DemValidity::kVoid);  // centred on an SRTM void
  EXPECT_TRUE(b.at_local(0.0, 0.0).valid());
  int compared = 0;
  for (int j = 0; j < a.info().rows; ++j) {
    for (int i = 0; i < a.info().cols; ++i) {
      const float va = a.node(i, j), vb = b.node(i, j);
      if (std::isnan(va)) continue;
      ASSERT_FLOAT_EQ(va, vb);  // filling touches voids only
      ASSERT_GE(va, 349.0f);
      ASSERT_LE(va, 3100.0f);
      ++compared;
    }
  }
  EXPECT_GT(compared, 5000);
}

TEST(DemTools, SrtmNodeValueSurvivesTiling) {
  // The tile origin 42.55 N 1.55 E is an SRTM 3" grid node: the tile must carry its value.
  const auto dir = test::scratch_dir("terrain_dem_tools_node");
  const std::string out = (dir / "t.pdem").string(), val = (dir / "v.txt").string();
  ASSERT_EQ(run("/usr/bin/python3 " + tool() + " tile " + andorra() + " -o " + out + " --center 42.55 1.55 --radius 600"), 0);
  ASSERT_EQ(std::system(("/usr/bin/python3 -c \"from osgeo import gdal; a=gdal.Open('" + andorra() +
                         "').ReadAsArray(); print(a[540, 660])\" > " + val).c_str()), 0);
  std::ifstream f(val);
  double srtm = 0.0;
  f >> srtm;
  const Dem dem = Dem::load(out);
  EXPECT_NEAR(dem.at(geo::Geodetic::from_deg(42.55, 1.55, 0.0)).elevation_m, srtm, 0.01);
}

TEST(DemTools, GeoTiffPlaneIsReproducedAtGeodeticPoints) {
  const auto dir = test::scratch_dir("terrain_dem_tools_geotiff");
  const std::string tif = (dir / "plane.tif").string(), csv = (dir / "plane.csv").string();
  const std::string out = (dir / "plane.pdem").string();
  ASSERT_EQ(run("/usr/bin/python3 " + std::string(PDNAV_SOURCE_DIR) + "/tests/dem-tools/make_test_geotiff.py " + tif +
                " " + csv),
            0);
  ASSERT_EQ(run("/usr/bin/python3 " + tool() + " tile " + tif + " -o " + out +
                " --center 42.5 1.5 --radius 2900 --cell 20"),
            0);
  const Dem dem = Dem::load(out);
  EXPECT_GE(dem.info().voids, 1);  // the nodata hole at the centre
  EXPECT_LE(dem.info().voids, 9);
  std::ifstream f(csv);
  std::string line;
  std::getline(f, line);  // header
  int points = 0;
  while (std::getline(f, line)) {
    double lat = 0, lon = 0, z = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf", &lat, &lon, &z), 3) << line;
    const DemSample s = dem.at(geo::Geodetic::from_deg(lat, lon, 0.0));
    ASSERT_TRUE(s.valid()) << line;
    EXPECT_NEAR(s.elevation_m, z, 0.05) << line;  // plane: reprojection + 2x bilinear keep it
    ++points;
  }
  EXPECT_EQ(points, 6);
}

}  // namespace
}  // namespace pdnav::terrain
