// Issue 19.2: WMM2015 (v2) and WMM2020 embedded beside WMM2025 and picked by the log's date.
// Reference values: tests/data/wmm/WMM2015_2020_reference_values.csv (pygeomag 1.1.0, an
// independent implementation, on the same NOAA .COF files; SOURCE.md).
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/geo/wmm.h"
#include "test_data.h"

using namespace pdnav;
using namespace pdnav::geo;

namespace {

struct Ref {
  std::string model;
  double year, alt_km, lat_deg, lon_deg, d_deg, i_deg, h_nt;
};

std::vector<Ref> load_refs() {
  std::ifstream in(test::test_data("wmm/WMM2015_2020_reference_values.csv"));
  std::vector<Ref> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    for (char& c : line) if (c == ',') c = ' ';
    std::istringstream ls(line);
    Ref r;
    if (!(ls >> r.model >> r.year >> r.alt_km >> r.lat_deg >> r.lon_deg >> r.d_deg >> r.i_deg >> r.h_nt)) {
      ADD_FAILURE() << "bad reference line: " << line;
      continue;
    }
    rows.push_back(r);
  }
  return rows;
}

/// Unix ms of a decimal year (inverse of decimal_year_from_unix_ms, by bisection).
std::int64_t unix_ms_of(double year) {
  std::int64_t lo = 0, hi = 4102444800000;
  while (hi - lo > 1) {
    const std::int64_t mid = lo + (hi - lo) / 2;
    (decimal_year_from_unix_ms(mid) < year ? lo : hi) = mid;
  }
  return hi;
}

const WmmModel& model_named(const std::string& name) {
  return name == "WMM-2020" ? WmmModel::wmm2020() : WmmModel::wmm2015();
}

}  // namespace

TEST(WmmModels, EmbeddedCoefficientsMatchTheCofFiles) {
  for (const auto& [file, model] : {std::pair{"wmm/WMM_2020.COF", &WmmModel::wmm2020()},
                                    std::pair{"wmm/WMM_2015v2.COF", &WmmModel::wmm2015()}}) {
    const WmmModel cof = WmmModel::load_cof(test::test_data(file));
    EXPECT_EQ(cof.name, model->name);
    EXPECT_DOUBLE_EQ(cof.epoch_year, model->epoch_year);
    ASSERT_EQ(cof.coefficients.size(), model->coefficients.size()) << file;
    for (std::size_t i = 0; i < cof.coefficients.size(); ++i) {
      EXPECT_EQ(cof.coefficients[i].n, model->coefficients[i].n);
      EXPECT_EQ(cof.coefficients[i].m, model->coefficients[i].m);
      EXPECT_DOUBLE_EQ(cof.coefficients[i].g_nt, model->coefficients[i].g_nt);
      EXPECT_DOUBLE_EQ(cof.coefficients[i].h_nt, model->coefficients[i].h_nt);
      EXPECT_DOUBLE_EQ(cof.coefficients[i].g_dot_ntpyr, model->coefficients[i].g_dot_ntpyr);
      EXPECT_DOUBLE_EQ(cof.coefficients[i].h_dot_ntpyr, model->coefficients[i].h_dot_ntpyr);
    }
  }
}

TEST(WmmModels, FieldMatchesAnIndependentImplementation) {
  const auto refs = load_refs();
  ASSERT_GE(refs.size(), 70u);
  for (const Ref& r : refs) {
    const Geodetic g = Geodetic::from_deg(r.lat_deg, r.lon_deg, r.alt_km * 1000.0);
    const MagneticField f = wmm_field(model_named(r.model), g, r.year);
    const std::string where = r.model + " " + std::to_string(r.year) + " " + std::to_string(r.lat_deg) + "," +
                              std::to_string(r.lon_deg) + "," + std::to_string(r.alt_km) + " km";
    EXPECT_NEAR(rad_to_deg(f.declination_rad), r.d_deg, 0.01) << where;
    EXPECT_NEAR(rad_to_deg(f.inclination_rad), r.i_deg, 0.01) << where;
    EXPECT_NEAR(f.h_nt, r.h_nt, 1.0) << where;
  }
}

TEST(WmmModels, TheLogDatePicksTheModel) {
  // Every reference row evaluated through the date helper: the model of its span is used.
  for (const Ref& r : load_refs()) {
    const Geodetic g = Geodetic::from_deg(r.lat_deg, r.lon_deg, r.alt_km * 1000.0);
    const Declination d = declination_at(g, unix_ms_of(r.year));
    EXPECT_EQ(d.model, r.model) << r.year;
    EXPECT_FALSE(d.extrapolated);
    EXPECT_NEAR(rad_to_deg(d.declination_rad), r.d_deg, 0.02) << r.model << " " << r.year;
  }
  // The case: Hangzhou in 2019 (an ILC walk's date) is about -5.6 deg, not 2025's -6.0.
  const Geodetic hangzhou = Geodetic::from_deg(30.27, 120.15, 0.0);
  const Declination d2019 = declination_at(hangzhou, 1560000000000);  // 2019-06-08
  EXPECT_EQ(d2019.model, "WMM-2015v2");
  EXPECT_NEAR(rad_to_deg(d2019.declination_rad), -5.62, 0.05);
  EXPECT_LT(std::abs(rad_to_deg(d2019.declination_rad - declination_at(hangzhou, 1735689600000).declination_rad)), 0.6);
  EXPECT_GT(std::abs(rad_to_deg(d2019.declination_rad - declination_at(hangzhou, 1735689600000).declination_rad)), 0.3);
  // Span edges: 2020.0 belongs to WMM2020, 2025.0 to WMM2025, 2030.0 is past every span.
  EXPECT_EQ(declination_at(hangzhou, 1577836800000).model, "WMM-2020");
  EXPECT_EQ(declination_at(hangzhou, 1735689600000).model, "WMM-2025");
  EXPECT_TRUE(declination_at(hangzhou, 1893456000000).extrapolated);
}
