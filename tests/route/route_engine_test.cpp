// RouteEngine (APT Sec. VI) on hand-made graphs with known answers, and on simulated walks
// through a seeded synthetic town (not the Andorra data: that is the eval-route ctest).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include "pdnav/route/route_engine.h"
#include "pdnav/route/walk_graph.h"
#include "pdnav/route/walk_sim.h"

namespace pdnav::route {
namespace {

const geo::Geodetic kOrigin = geo::Geodetic::from_deg(42.5, 1.5, 0.0);

WalkGraph::Edge edge(std::int32_t a, std::int32_t b, std::vector<Eigen::Vector2d> shape = {}) {
  WalkGraph::Edge e;
  e.from = a;
  e.to = b;
  e.highway = "footway";
  e.shape_en_m = std::move(shape);
  return e;
}

/// A plus-shaped crossing at (0,0) with arms 200 m long, plus a lone street far away.
std::shared_ptr<const WalkGraph> crossing() {
  std::vector<Eigen::Vector2d> v{{0, 0}, {200, 0}, {0, 200}, {-200, 0}, {0, -200}, {1000, 1000}, {1000, 1200}};
  std::vector<WalkGraph::Edge> e{edge(0, 1), edge(0, 2), edge(0, 3), edge(0, 4), edge(5, 6)};
  return std::make_shared<const WalkGraph>(WalkGraph::build(kOrigin, v, e));
}

PositionFix fix_at(const WalkGraph& g, Eigen::Vector2d p, double sigma_m, TimeNs t) {
  const auto geod = g.frame().to_geodetic(geo::Enu(p.x(), p.y(), 0.0));
  PositionFix f;
  f.t_ns = t;
  f.lat_deg = geod.lat_deg();
  f.lon_deg = geod.lon_deg();
  f.horizontal_sigma_m = sigma_m;
  return f;
}

PdrStep step(TimeNs t, double len, double heading_deg) {
  PdrStep s;
  s.t_ns = t;
  s.length_m = len;
  s.heading_rad = wrap_two_pi(deg_to_rad(heading_deg));
  s.heading_sigma_rad = deg_to_rad(15.0);
  return s;
}

/// Walk `n` steps of `len` metres with a heading; returns the time after the last one.
TimeNs walk(RouteEngine& e, TimeNs t, int n, double len, double heading_deg) {
  for (int i = 0; i < n; ++i) {
    t += kNsPerS / 2;
    e.feed(step(t, len, heading_deg));
  }
  return t;
}

TEST(RouteEngine, InitialRoutesCoverEveryEdgePointInRadiusBothWays) {
  auto g = crossing();
  RouteEngine e(RouteOptions{}, g, 1);
  EXPECT_EQ(e.estimate().status, EstimateStatus::kNotInitialized);
  EXPECT_TRUE(e.needs_fix());
  e.feed(fix_at(*g, {100, 0}, 4.0, kNsPerS));  // radius 2.5 * 4 = 10 m on the east arm
  // 20 m of edge, 2 m spacing, two directions.
  EXPECT_EQ(e.route_count(), 20u);
  const auto c = e.candidates(100);
  ASSERT_EQ(c.size(), 20u);
  for (const auto& k : c) {
    EXPECT_LE((k.en_m - Eigen::Vector2d(100, 0)).norm(), 10.0 + 1e-9);
    EXPECT_NEAR(k.en_m.y(), 0.0, 1e-9);
  }
  const Estimate est = e.estimate();
  EXPECT_TRUE(est.valid());
  EXPECT_NEAR(est.en_m.x(), 100.0, 1.5);
}

TEST(RouteEngine, TurnSnapsToTheCornerAndKeepsOnlyMatchingBranch) {
  auto g = crossing();
  RouteEngine e(RouteOptions{}, g, 1);
  // The walker starts 60 m east of the crossing, walking west; the fix is 11 m off.
  e.feed(fix_at(*g, {70, 5}, 15.0, kNsPerS));
  // 80 true steps of 0.75 m (60 m, to the crossing) reported 5 % long.
  TimeNs t = walk(e, kNsPerS, 80, 0.75 * 1.05, 270.0);
  // A right turn (negative angle) to the north from t - 1 s to t + 1 s, centred on the
  // crossing; then 4 true steps north (3 m).
  const TimeNs t_turn_start = t - kNsPerS;
  t = walk(e, t, 4, 0.75, 0.0);
  PdrTurn turn;
  turn.start_ns = t_turn_start;
  turn.t_ns = t_turn_start + 2 * kNsPerS;
  turn.angle_rad = deg_to_rad(-88.0);
  e.feed(turn);
  const Estimate est = e.estimate();
  ASSERT_EQ(est.status, EstimateStatus::kOk) << est.reason;
  // Snapped to the crossing, then the 4 steps after the turn's midpoint (3 m) north. Without
  // the snap the 5 % long steps would have carried it 3 m west past the crossing.
  EXPECT_NEAR(est.en_m.x(), 0.0, 0.5);
  EXPECT_NEAR(est.en_m.y(), 3.0, 0.5);
  for (const auto& c : e.candidates(1000)) EXPECT_NEAR(c.heading_rad, 0.0, 1e-9);  // all northbound
}

// The reported covariance carries the along-track variance of the steps' scale (5 % of the
// distance since the last snap) along the street: the routes of a cluster move together, so
// their spread alone stayed ~1 m while a scale error drifts the position along the street.
TEST(RouteEngine, ReportedCovarianceGrowsAlongTheStreetNotAcrossIt) {
  auto g = crossing();
  RouteEngine e(RouteOptions{}, g, 1);
  e.feed(fix_at(*g, {0, -190}, 3.0, kNsPerS));
  TimeNs t = walk(e, kNsPerS, 20, 0.75, 0.0);  // 15 m north on the south arm
  const Estimate a = e.estimate();
  t = walk(e, t, 160, 0.75, 0.0);              // 120 m more, no turn
  const Estimate b = e.estimate();
  ASSERT_TRUE(a.valid() && b.valid());
  const double d_a = 15.0, d_b = 135.0;  // walked since the fix (the routes' last snap)
  std::printf("along-track sigma %.1f m after %.0f m, %.1f m after %.0f m; across %.1f m\n", std::sqrt(a.cov_en_m2(1, 1)), d_a,
              std::sqrt(b.cov_en_m2(1, 1)), d_b, std::sqrt(b.cov_en_m2(0, 0)));
  EXPECT_GT(std::sqrt(b.cov_en_m2(1, 1)), 0.05 * d_b);         // north: along the street
  EXPECT_LT(std::sqrt(b.cov_en_m2(1, 1)), 0.05 * d_b + 10.0);  // (plus the routes' spread)
  EXPECT_LT(std::sqrt(b.cov_en_m2(0, 0)), 1.5);                // east: across it
  EXPECT_GT(b.cov_en_m2(1, 1), 4.0 * a.cov_en_m2(1, 1));
}

// The caller's step-scale sigma (the Navigator: the fusion filter's residual scale sigma of the
// calibrated steps it feeds) sets that along-track growth instead of the 5 % constant: the same
// walk with 20 % reports (0.20^2 - 0.05^2) d^2 more along-track variance, the across-track unchanged.
TEST(RouteEngine, CallersStepScaleSigmaSetsTheAlongTrackGrowth) {
  auto g = crossing();
  auto along_after_straight_walk = [&](double scale_sigma, double* across) {
    RouteEngine e(RouteOptions{}, g, 1);
    if (scale_sigma > 0.0) e.set_step_scale_sigma(scale_sigma);
    e.feed(fix_at(*g, {0, -190}, 3.0, kNsPerS));
    walk(e, kNsPerS, 180, 0.75, 0.0);  // 135 m north, no turn
    const Estimate b = e.estimate();
    EXPECT_TRUE(b.valid());
    *across = std::sqrt(b.cov_en_m2(0, 0));
    return std::sqrt(b.cov_en_m2(1, 1));
  };
  double across_default = 0.0, across_20 = 0.0;
  const double along_default = along_after_straight_walk(0.0, &across_default);
  const double along_20 = along_after_straight_walk(0.20, &across_20);
  std::printf("along-track sigma after 135 m: %.1f m (5 %%), %.1f m (20 %%)\n", along_default, along_20);
  EXPECT_GT(along_20, 0.20 * 135.0);
  EXPECT_LT(along_20, 0.20 * 135.0 + 10.0);
  // the routes' own spread is the same in both: the variances differ by (0.20^2 - 0.05^2) d^2
  const double d = 135.0;
  EXPECT_NEAR(along_20 * along_20 - along_default * along_default, (0.20 * 0.20 - 0.05 * 0.05) * d * d, 0.02 * 0.04 * d * d);
  EXPECT_NEAR(across_20, across_default, 1e-9);
}

TEST(RouteEngine, UnmatchableTurnLosesAllRoutesAndNextFixRestarts) {
  auto g = crossing();
  RouteOptions apt;  // the paper's behaviour: no local restart
  apt.local_restart_radius_m = 0.0;
  RouteEngine e(apt, g, 1);
  e.feed(fix_at(*g, {100, 0}, 5.0, kNsPerS));
  TimeNs t = walk(e, kNsPerS, 10, 0.7, 270.0);
  PdrTurn turn;  // a right turn in the middle of a straight street: no node within 20 m
  turn.start_ns = t - kNsPerS;
  turn.t_ns = t;
  turn.angle_rad = deg_to_rad(-90.0);
  e.feed(turn);
  EXPECT_EQ(e.route_count(), 0u);
  Estimate est = e.estimate();
  EXPECT_EQ(est.status, EstimateStatus::kLost);
  EXPECT_TRUE(e.needs_fix());
  // Dead reckoning continues west; the estimate stays finite.
  const double x_before = est.en_m.x();
  t = walk(e, t, 10, 0.7, 270.0);
  est = e.estimate();
  EXPECT_NEAR(est.en_m.x(), x_before - 7.0, 1e-6);
  EXPECT_TRUE(est.en_m.allFinite());
  e.feed(fix_at(*g, {1000, 1100}, 5.0, t + 1));
  EXPECT_EQ(e.restarts(), 1u);
  EXPECT_GT(e.route_count(), 0u);
  EXPECT_NEAR(e.estimate().en_m.y(), 1100.0, 2.0);
}

TEST(RouteEngine, LocalRestartReseedsAroundTheLastEstimate) {
  auto g = crossing();
  RouteEngine e(RouteOptions{}, g, 1);
  e.feed(fix_at(*g, {100, 0}, 5.0, kNsPerS));
  TimeNs t = walk(e, kNsPerS, 10, 0.7, 270.0);  // ~93 m east of the crossing
  PdrTurn turn;  // no node within 20 m can explain a turn here
  turn.start_ns = t - kNsPerS;
  turn.t_ns = t;
  turn.angle_rad = deg_to_rad(-90.0);
  e.feed(turn);
  EXPECT_EQ(e.local_restarts(), 1u);
  EXPECT_EQ(e.restarts(), 0u);
  ASSERT_GT(e.route_count(), 0u);
  for (const auto& c : e.candidates(1000)) EXPECT_LE((c.en_m - Eigen::Vector2d(93, 0)).norm(), 30.0 + 1.0);
  EXPECT_NE(e.estimate().status, EstimateStatus::kLost);
}

TEST(RouteEngine, ALostEngineRetriesTheLocalRestartAsItWalks) {
  // A fix (or the fused estimate it is re-anchored to) 60 m north of the east arm, with no way
  // within its radius: no route, kLost. Before, a lost engine waited for the next fix however
  // near a way it walked; now it retries the local restart every lost_retry_m walked.
  auto g = crossing();
  RouteEngine e(RouteOptions{}, g, 1);
  e.feed(fix_at(*g, {100, 60}, 4.0, kNsPerS));  // radius 2.5 x 4 = 10 m: nothing within it
  ASSERT_EQ(e.route_count(), 0u);
  EXPECT_EQ(e.estimate().status, EstimateStatus::kLost);
  TimeNs t = walk(e, kNsPerS, 20, 0.7, 90.0);  // 14 m east, still 60 m from the arm: nothing to find
  EXPECT_EQ(e.route_count(), 0u);
  EXPECT_EQ(e.local_restarts(), 0u);  // attempts without a way in reach are not restarts
  t = walk(e, t, 60, 0.7, 180.0);  // 42 m south: within 30 m of the east arm after ~30 m
  EXPECT_EQ(e.local_restarts(), 1u);
  ASSERT_GT(e.route_count(), 0u);
  EXPECT_NE(e.estimate().status, EstimateStatus::kLost);
  for (const auto& c : e.candidates(1000)) EXPECT_LE(std::abs(c.en_m.y()), 1e-6);  // on the east arm
  RouteOptions apt = RouteOptions{};
  apt.lost_retry_m = 0.0;  // off: lost until the next fix
  RouteEngine f(apt, g, 1);
  f.feed(fix_at(*g, {100, 60}, 4.0, kNsPerS));
  t = walk(f, kNsPerS, 20, 0.7, 90.0);
  walk(f, t, 60, 0.7, 180.0);
  EXPECT_EQ(f.route_count(), 0u);
}

TEST(RouteEngine, DeadEndOvershootDiesAtTheDistanceTolerance) {
  std::vector<Eigen::Vector2d> v{{0, 0}, {50, 0}};
  auto g = std::make_shared<const WalkGraph>(WalkGraph::build(kOrigin, v, {edge(0, 1)}));
  RouteEngine e(RouteOptions{}, g, 1);
  e.feed(fix_at(*g, {45, 0}, 2.0, kNsPerS));  // routes near the east end, both directions
  TimeNs t = walk(e, kNsPerS, 20, 1.0, 90.0);  // 20 m east: eastbound routes stuck at the end
  ASSERT_GT(e.route_count(), 0u);
  int stuck_eastbound = 0;
  for (const auto& c : e.candidates(100)) {
    if (c.heading_rad < kPi) {
      EXPECT_GT(c.distance_error_m, 0.0);
      EXPECT_LE(c.distance_error_m, 20.0);
      EXPECT_NEAR(c.en_m.x(), 50.0, 1e-9);  // held at the dead end
      ++stuck_eastbound;
    }
  }
  EXPECT_GT(stuck_eastbound, 0);
  walk(e, t, 12, 1.0, 90.0);  // 32 m: eastbound routes have overshot > 20 m and died
  for (const auto& c : e.candidates(100)) EXPECT_GT(c.heading_rad, kPi);  // only westbound left
}

TEST(RouteEngine, FixPrunesRoutesBeyondToleranceAndItsRadius) {
  auto g = crossing();
  RouteEngine e(RouteOptions{}, g, 1);
  e.feed(fix_at(*g, {0, 0}, 20.0, kNsPerS));  // radius 50 m on all four arms
  const auto n0 = e.route_count();
  walk(e, kNsPerS, 10, 0.7, 90.0);
  e.feed(fix_at(*g, {0, 150}, 4.0, 10 * kNsPerS));  // gate 20 + 10 m around (0,150)
  EXPECT_LT(e.route_count(), n0);
  for (const auto& c : e.candidates(1000)) EXPECT_LE((c.en_m - Eigen::Vector2d(0, 150)).norm(), 30.0 + 1e-9);
}

TEST(RouteEngine, BadInputIsIgnoredNeverNaN) {
  auto g = crossing();
  RouteEngine e(RouteOptions{}, g, 1);
  PositionFix bad = fix_at(*g, {0, 0}, 5.0, 1);
  bad.lat_deg = std::nan("");
  e.feed(bad);
  EXPECT_EQ(e.estimate().status, EstimateStatus::kNotInitialized);
  e.feed(fix_at(*g, {0, 50}, 5.0, 2));
  const auto n = e.route_count();
  e.feed(step(3, std::nan(""), 0.0));
  e.feed(step(4, -1.0, 0.0));
  e.feed(step(5, 0.7, std::nan("")));
  PdrTurn t;
  t.angle_rad = std::nan("");
  e.feed(t);
  EXPECT_EQ(e.route_count(), n);
  EXPECT_TRUE(e.estimate().en_m.allFinite());
  EXPECT_TRUE(e.estimate().cov_en_m2.allFinite());
  EXPECT_THROW(RouteEngine(RouteOptions{}, nullptr, 1), std::invalid_argument);
}

TEST(RouteEngine, MemoryIsBoundedAndTooManyRoutesAskForAFix) {
  // A dense grid (10 m spacing) and a huge fix radius: far more routes than allowed.
  std::vector<Eigen::Vector2d> v;
  std::vector<WalkGraph::Edge> edges;
  const int n = 30;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) v.emplace_back(10.0 * i, 10.0 * j);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (i + 1 < n) edges.push_back(edge(i * n + j, (i + 1) * n + j));
      if (j + 1 < n) edges.push_back(edge(i * n + j, i * n + j + 1));
    }
  auto g = std::make_shared<const WalkGraph>(WalkGraph::build(kOrigin, v, edges));
  RouteOptions opt;
  opt.max_routes = 500;
  RouteEngine e(opt, g, 1);
  e.feed(fix_at(*g, {150, 150}, 60.0, 1));
  EXPECT_LE(e.route_count(), 500u);
  EXPECT_TRUE(e.needs_fix());
  walk(e, 1, 30, 0.7, 90.0);
  EXPECT_LE(e.route_count(), 500u);
}

/// A seeded synthetic town: jittered 12 x 12 grid, 70 m blocks, some streets missing,
/// some with a bend, plus diagonal footpaths.
std::shared_ptr<const WalkGraph> synthetic_town(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(-12.0, 12.0), unit(0.0, 1.0);
  const int n = 12;
  std::vector<Eigen::Vector2d> v;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) v.emplace_back(70.0 * i + jitter(rng), 70.0 * j + jitter(rng));
  std::vector<WalkGraph::Edge> edges;
  auto add = [&](int a, int b) {
    if (unit(rng) < 0.15) return;  // missing street
    std::vector<Eigen::Vector2d> shape;
    if (unit(rng) < 0.3) {  // a bend in the middle
      const Eigen::Vector2d mid = 0.5 * (v[a] + v[b]);
      shape.push_back(mid + Eigen::Vector2d(jitter(rng), jitter(rng)));
    }
    edges.push_back(edge(a, b, shape));
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (i + 1 < n) add(i * n + j, (i + 1) * n + j);
      if (j + 1 < n) add(i * n + j, i * n + j + 1);
      if (i + 1 < n && j + 1 < n && unit(rng) < 0.1) add(i * n + j, (i + 1) * n + j + 1);
    }
  return std::make_shared<const WalkGraph>(WalkGraph::build(kOrigin, v, edges));
}

TEST(RouteEngine, SimulatedWalksInASyntheticTownMeetTheTurnPointBar) {
  auto g = synthetic_town(42);
  WalkSimOptions sim;
  std::vector<double> turn_err, step_err, gnss_err;
  for (std::uint64_t w = 0; w < 12; ++w) {
    const SimWalk walk = simulate_walk(*g, sim, 1000 + w);
    EXPECT_GE(walk.turns, sim.min_turns);
    const WalkScore s = score_walk(g, RouteOptions{}, walk);
    turn_err.insert(turn_err.end(), s.turn_errors_m.begin(), s.turn_errors_m.end());
    step_err.insert(step_err.end(), s.step_errors_m.begin(), s.step_errors_m.end());
    gnss_err.insert(gnss_err.end(), s.gnss_errors_m.begin(), s.gnss_errors_m.end());
  }
  const double gnss_med = quantile(gnss_err, 0.5);
  EXPECT_GT(gnss_med, 8.0);  // the simulated GNSS is as bad as stated (15 m RMS)
  EXPECT_LE(quantile(turn_err, 0.5), 3.0);
  EXPECT_LE(quantile(turn_err, 0.95), 10.0);
  EXPECT_LE(quantile(step_err, 0.5), 0.5 * gnss_med);
}

// Issue 27: the map measures the walker's step scale between two matched turns. Walkers whose
// PDR steps are off by up to +-15 % (the spread of the length ratio over the real sets): each
// published sample against that walk's true path / step distance, in its own sigmas.
TEST(RouteEngine, TwoMatchedTurnsMeasureTheStepScale) {
  auto g = synthetic_town(42);
  WalkSimOptions sim;
  sim.step_scale_error = 0.15;
  std::vector<double> z, rel;
  int walks_with_sample = 0;
  for (std::uint64_t w = 0; w < 12; ++w) {
    const SimWalk walk = simulate_walk(*g, sim, 2000 + w);
    double pdr_m = 0.0;
    for (const SimEvent& ev : walk.events)
      if (const auto* st = std::get_if<PdrStep>(&ev)) pdr_m += st->length_m;
    const double truth = walk.length_m / pdr_m;  // true path / the steps' distance
    RouteEngine engine(RouteOptions{}, g, 1);
    bool any = false;
    for (const SimEvent& ev : walk.events) {
      std::visit([&](const auto& e) { engine.feed(e); }, ev);
      if (const auto s = engine.take_scale_sample()) {
        ASSERT_TRUE(std::isfinite(s->scale) && s->sigma > 0.0);
        EXPECT_GE(s->distance_m, RouteOptions{}.scale_sample_min_m);
        z.push_back((s->scale - truth) / s->sigma);
        rel.push_back(s->scale / truth - 1.0);
        any = true;
      }
    }
    walks_with_sample += any;
  }
  double z2 = 0.0;
  int outside = 0;
  for (double x : z) { z2 += x * x; outside += std::abs(x) > 3.0; }
  std::sort(rel.begin(), rel.end());
  std::printf("samples %zu in %d walks, mean z^2 %.2f, beyond 3 sigma %d, relative error p10/p50/p90 %.3f %.3f %.3f\n",
              z.size(), walks_with_sample, z.empty() ? 0.0 : z2 / static_cast<double>(z.size()), outside,
              quantile(rel, 0.1), quantile(rel, 0.5), quantile(rel, 0.9));
  // (this simulator's walker keeps to the centreline within 1.5 m, so the samples are better
  // than their sigma, which carries path_length_sigma for real paths: on the phone sessions of
  // `pdnav simulate --session` they scatter -8.7 / +5.9 % (p10 / p90), docs/route.md)
  ASSERT_GE(z.size(), 20u);
  EXPECT_GE(walks_with_sample, 8);
  EXPECT_EQ(outside, 0);
  EXPECT_LT(z2 / static_cast<double>(z.size()), 1.0);
  EXPECT_LT(std::abs(quantile(rel, 0.5)), 0.01);  // the walker's up to 15 % is gone to within 1 %
  EXPECT_LT(quantile(rel, 0.9) - quantile(rel, 0.1), 0.04);
}

TEST(RouteEngine, SimulationIsReproducibleFromItsSeed) {
  auto g = synthetic_town(7);
  const SimWalk a = simulate_walk(*g, WalkSimOptions{}, 99);
  const SimWalk b = simulate_walk(*g, WalkSimOptions{}, 99);
  ASSERT_EQ(a.events.size(), b.events.size());
  EXPECT_EQ(a.path, b.path);
  const WalkScore sa = score_walk(g, RouteOptions{}, a);
  const WalkScore sb = score_walk(g, RouteOptions{}, b);
  EXPECT_EQ(sa.step_errors_m, sb.step_errors_m);
}

}  // namespace
}  // namespace pdnav::route
