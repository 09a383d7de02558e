// Walk simulator: reproducible, realistic cadence/lengths, pressure consistent with the truth.
#include <cmath>

#include <gtest/gtest.h>

#include "pdnav/geo/baro.h"
#include "pdnav/terrain/simulator.h"
#include "synthetic_dem.h"

namespace pdnav::terrain {
namespace {

TEST(Simulator, ReproducibleAndRealistic) {
  const Dem dem = test::synthetic_dem(301, 301, 30.0, test::hills);
  WalkSimOptions o;
  const SimulatedWalk a = simulate_walk(dem, o, 77);
  const SimulatedWalk b = simulate_walk(dem, o, 77);
  const SimulatedWalk c = simulate_walk(dem, o, 78);
  ASSERT_EQ(a.steps.size(), b.steps.size());
  EXPECT_EQ(a.steps.back().heading_rad, b.steps.back().heading_rad);
  EXPECT_EQ(a.pressure.back().pressure_pa, b.pressure.back().pressure_pa);
  EXPECT_NE(a.length_m, c.length_m);
  EXPECT_GE(a.length_m, 1000.0);
  EXPECT_LE(a.length_m, 5000.0 + 5.0);
  ASSERT_EQ(a.truth.size(), a.steps.size());
  const double duration_s = ns_to_s(a.steps.back().t_ns - a.t0_ns);
  EXPECT_NEAR(static_cast<double>(a.steps.size()) / duration_s, 1.8, 0.1);
  EXPECT_NEAR(static_cast<double>(a.pressure.size()) / duration_s, 5.0, 0.1);
  // Truth stays on the tile, inside the margin.
  for (const Eigen::Vector2d& p : a.truth_en) {
    ASSERT_GT(p.x(), dem.min_e_m() + o.edge_margin_m - 1.0);
    ASSERT_LT(p.y(), dem.max_n_m() - o.edge_margin_m + 1.0);
  }
  // Barometric altitude differences follow the truth heights within the error budget
  // (FOGM bias 3 m, gusts, noise, temperature scale): first vs last sample.
  const double dh_baro = geo::baro_altitude_m(a.pressure.back().pressure_pa, a.pressure.front().pressure_pa, 0.0) -
                         geo::baro_altitude_m(a.pressure.front().pressure_pa, a.pressure.front().pressure_pa, 0.0);
  const double dh_true = a.truth.back().h_m - a.truth.front().h_m;
  EXPECT_NEAR(dh_baro, dh_true, 15.0 + 0.05 * std::abs(dh_true));
  // Measured headings differ from the truth by the simulated bias: not identical, bounded.
  double max_err = 0.0;
  for (std::size_t k = 0; k < a.steps.size(); ++k)
    max_err = std::max(max_err, std::abs(wrap_pi(a.steps[k].heading_rad - a.truth[k].heading_deg * kDegToRad)));
  EXPECT_GT(max_err, 5.0 * kDegToRad);
  EXPECT_LT(max_err, 120.0 * kDegToRad);
}

TEST(Simulator, TooSmallTileIsAClearError) {
  const Dem dem = test::synthetic_dem(11, 11, 30.0, test::hills);
  EXPECT_THROW(simulate_walk(dem, WalkSimOptions{}, 1), std::runtime_error);
}

TEST(Simulator, MahalanobisOfTheOneSigmaEllipse) {
  const Eigen::Matrix2d cov = (Eigen::Matrix2d() << 4.0, 0.0, 0.0, 1.0).finished();
  EXPECT_NEAR(mahalanobis2(cov, Eigen::Vector2d(2.0, 0.0)), 1.0, 1e-12);
  EXPECT_NEAR(mahalanobis2(cov, Eigen::Vector2d(0.0, 1.0)), 1.0, 1e-12);
  EXPECT_TRUE(std::isinf(mahalanobis2(Eigen::Matrix2d::Zero(), Eigen::Vector2d(1.0, 0.0))));
  EXPECT_NEAR(std::sqrt(kOneSigmaM2), ErrorEllipse::scale_for_probability(0.682689492137), 1e-9);
}

}  // namespace
}  // namespace pdnav::terrain
