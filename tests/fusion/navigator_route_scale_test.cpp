// The route engine's along-track covariance inside the Navigator (issue 28): the steps the
// Navigator feeds it are calibrated by the fusion's calibration, so their scale error is the
// fusion filter's residual scale sigma, and the route reports its along-track sigma with that
// (FusionOptions::route_scale_from_filter), not with APT's 5 %. Here no GNSS ever calibrates
// the walker: the filter's scale sigma is the unknown walker's prior (15 %), and after 150 m
// along a straight street with no turn the route says so; with the option off it claims 5 %.
#include <cmath>
#include <memory>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "../support/walk_fixtures.h"
#include "pdnav/fusion/navigator.h"
#include "pdnav/route/walk_graph.h"

namespace pdnav::fusion {
namespace {

constexpr TimeNs kStepNs = 550 * kNsPerMs;
const geo::Geodetic kOrigin = geo::Geodetic::from_deg(42.5, 1.5, 0.0);

/// One straight street 1 km north from the origin.
std::shared_ptr<const route::WalkGraph> street() {
  std::vector<Eigen::Vector2d> v{{0, 0}, {0, 1000}};
  route::WalkGraph::Edge e;
  e.from = 0;
  e.to = 1;
  e.highway = "footway";
  return std::make_shared<const route::WalkGraph>(route::WalkGraph::build(kOrigin, v, {e}));
}

/// Android step events of a chest-mounted phone, the walker facing (magnetic) north.
void walk_north(Navigator& nav, TimeNs& t, int steps) {
  const Eigen::Quaterniond q = test::chest_facing(0.0);
  for (int k = 0; k < steps; ++k) {
    t += kStepNs;
    for (const Sample& s : test::step_events(t - kNsPerMs, t, q)) nav.feed(s);
  }
}

/// The route engine's (along-track, across-track) sigma after `steps` steps north from the
/// street's south end, and the distance walked.
struct RouteSigma {
  double along_m = 0.0, across_m = 0.0, walked_m = 0.0;
};
RouteSigma route_sigma_after(bool scale_from_filter, int steps) {
  NavigatorConfig cfg;
  cfg.mode = EngineMode::kAuto;
  const geo::Geodetic start = street()->frame().to_geodetic(geo::Enu(0.0, 20.0, 0.0));
  cfg.start_lat_deg = start.lat_deg();
  cfg.start_lon_deg = start.lon_deg();
  cfg.start_sigma_m = 3.0;
  cfg.graph = street();
  cfg.fusion.route_scale_from_filter = scale_from_filter;
  Navigator nav(cfg, 1);
  TimeNs t = kNsPerS;
  walk_north(nav, t, steps);
  RouteSigma r;
  for (const StepEstimate& s : nav.take_steps()) r.walked_m = s.distance_m;
  for (const Estimate& e : nav.output(0).engines) {
    if (e.engine != EngineKind::kRoute) continue;
    EXPECT_TRUE(e.valid()) << e.reason;
    r.along_m = std::sqrt(e.cov_en_m2(1, 1));  // the street runs north
    r.across_m = std::sqrt(e.cov_en_m2(0, 0));
  }
  return r;
}

TEST(NavigatorRouteScale, TheRoutesAlongTrackSigmaIsTheFiltersScaleSigma) {
  const RouteSigma with = route_sigma_after(true, 220);
  const RouteSigma without = route_sigma_after(false, 220);
  ASSERT_GT(with.walked_m, 100.0);
  std::printf("after %.0f m: route along-track sigma %.1f m (filter's scale sigma), %.1f m (5 %%); across %.1f / %.1f m\n",
              with.walked_m, with.along_m, without.along_m, with.across_m, without.across_m);
  // uncalibrated: the filter's scale sigma is initial_scale_sigma (15 %) of the distance walked
  const double prior = FusionFilterOptions{}.initial_scale_sigma;
  EXPECT_GT(with.along_m, 0.9 * prior * with.walked_m);
  EXPECT_LT(with.along_m, prior * with.walked_m + 10.0);
  EXPECT_LT(without.along_m, 0.05 * without.walked_m + 10.0);
  EXPECT_GT(with.along_m, 2.0 * without.along_m);
  EXPECT_NEAR(with.across_m, without.across_m, 0.5);
}

}  // namespace
}  // namespace pdnav::fusion
