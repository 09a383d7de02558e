// The Navigator's terrain particles and its fused filter share one walker model: each particle's
// walker scale is drawn with the filter's prior for an unknown walker's stride
// (FusionFilterOptions::initial_scale_sigma), not the step model's per-step 10 %.
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/fusion/navigator.h"
#include "pdnav/terrain/dem.h"
#include "pdnav/terrain/terrain_engine.h"

namespace pdnav::fusion {
namespace {

std::shared_ptr<const terrain::Dem> small_hill() {
  terrain::DemInfo info;
  info.origin_lat_deg = 42.5;
  info.origin_lon_deg = 1.5;
  info.cols = info.rows = 21;
  info.cell_m = 30.0;
  info.x0_m = info.y0_m = -300.0;
  std::vector<float> v(static_cast<std::size_t>(info.cols * info.rows));
  for (int r = 0; r < info.rows; ++r)
    for (int c = 0; c < info.cols; ++c)
      v[static_cast<std::size_t>(r * info.cols + c)] = static_cast<float>(1000.0 + 2.0 * c + 3.0 * r);
  return std::make_shared<const terrain::Dem>(terrain::Dem::from_grid(info, std::move(v)));
}

NavigatorConfig with_dem(EngineMode mode) {
  NavigatorConfig cfg;
  cfg.mode = mode;
  cfg.dem = small_hill();
  return cfg;
}

}  // namespace

TEST(NavigatorTerrainPrior, ParticlesDrawTheWalkerScaleWithTheFusedFiltersPrior) {
  for (EngineMode mode : {EngineMode::kAuto, EngineMode::kTerrain}) {
    NavigatorConfig cfg = with_dem(mode);
    const Navigator nav(cfg, 1);
    ASSERT_NE(nav.terrain_options(), nullptr);
    EXPECT_DOUBLE_EQ(nav.terrain_options()->step_scale_sigma, cfg.fusion.filter.initial_scale_sigma);
    EXPECT_GT(nav.terrain_options()->step_scale_sigma, 0.15);  // an unknown walker, not the per-step 10 %
    // the one prior moves both
    cfg.fusion.filter.initial_scale_sigma = 0.25;
    const Navigator wider(cfg, 1);
    EXPECT_DOUBLE_EQ(wider.terrain_options()->step_scale_sigma, 0.25);
  }
  // the paper's four-state preset has no scale state and keeps none
  NavigatorConfig paper = with_dem(EngineMode::kTerrain);
  paper.terrain_preset = "paper";
  EXPECT_EQ(Navigator(paper, 1).terrain_options()->step_scale_sigma, 0.0);
  // without a DEM there is no terrain engine
  NavigatorConfig none;
  EXPECT_EQ(Navigator(none, 1).terrain_options(), nullptr);
}

}  // namespace pdnav::fusion
