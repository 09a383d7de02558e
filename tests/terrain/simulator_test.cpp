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
  // World errors: the cadence (1.8 Hz on the flat) drops on grades (sim::Stride).
  EXPECT_GT(static_cast<double>(a.steps.size()) / duration_s, 1.5);
  EXPECT_LT(static_cast<double>(a.steps.size()) / duration_s, 1.85);
  EXPECT_NEAR(static_cast<double>(a.pressure.size()) / duration_s, 5.0, 0.1);
  // Truth stays on the tile, inside the margin.
  for (const Eigen::Vector2d& p : a.truth_en) {
    ASSERT_GT(p.x(), dem.min_e_m() + o.edge_margin_m - 1.0);
    ASSERT_LT(p.y(), dem.max_n_m() - o.edge_margin_m + 1.0);
  }
  // Barometric altitude differences follow the truth heights within the error budget
  // (weather trend <= 3 hPa / 3 h, tide, gusts, noise, temperature scale): first vs last sample.
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

// The default errors are the world's, not the filter's: the PDR reports the model step while
// the true stride varies (slope, fatigue, walker); world_errors = false gives the old models.
TEST(Simulator, DefaultErrorsAreTheWorldModels) {
  const Dem dem = test::synthetic_dem(301, 301, 30.0, test::hills);
  WalkSimOptions o;
  ASSERT_TRUE(o.world_errors);
  const SimulatedWalk w = simulate_walk(dem, o, 5);
  double min_true = 1e9, max_true = 0;
  for (std::size_t k = 1; k < w.truth_en.size(); ++k) {
    EXPECT_EQ(w.steps[k].length_m, o.step_length_mean_m);
    const double l = (w.truth_en[k] - w.truth_en[k - 1]).norm();
    if (l > 0.3) min_true = std::min(min_true, l), max_true = std::max(max_true, l);
  }
  EXPECT_GT(max_true - min_true, 0.1);  // slope, fatigue and step-to-step variability
  for (const PressureSample& p : w.pressure) EXPECT_EQ(p.pressure_pa, std::round(p.pressure_pa));  // 1 Pa steps
  o.world_errors = false;
  const SimulatedWalk f = simulate_walk(dem, o, 5);
  const double duration_s = ns_to_s(f.steps.back().t_ns - f.t0_ns);
  EXPECT_NEAR(static_cast<double>(f.steps.size()) / duration_s, 1.8, 0.1);
  bool varies = false;
  for (const PdrStep& s : f.steps) varies = varies || s.length_m != o.step_length_mean_m;
  EXPECT_TRUE(varies);
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
