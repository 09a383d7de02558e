// Route engine updates per second with ~10, ~100 and ~1000 live candidate routes (issue 6).
// A 10 m street grid (2 km square) keeps the route count steady: every route goes straight
// through the crossings (the 90 deg branches exceed the shallow limit) and merging keeps
// the set from growing. Items/s = PdrStep updates per second; `routes` = mean live routes.
#include <cmath>
#include <memory>

#include <benchmark/benchmark.h>

#include "pdnav/route/route_engine.h"
#include "pdnav/route/router.h"
#include "pdnav/route/walk_graph.h"

namespace {

using pdnav::route::RouteEngine;
using pdnav::route::RouteOptions;
using pdnav::route::WalkGraph;

std::shared_ptr<const WalkGraph> grid_graph() {
  static const auto g = [] {
    const int n = 201;
    std::vector<Eigen::Vector2d> v;
    std::vector<WalkGraph::Edge> e;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) v.emplace_back(10.0 * i, 10.0 * j);
    auto add = [&](int a, int b) {
      WalkGraph::Edge x;
      x.from = a;
      x.to = b;
      x.highway = "residential";
      e.push_back(x);
    };
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        if (i + 1 < n) add(i * n + j, (i + 1) * n + j);
        if (j + 1 < n) add(i * n + j, i * n + j + 1);
      }
    return std::make_shared<const WalkGraph>(
        WalkGraph::build(pdnav::geo::Geodetic::from_deg(42.5, 1.5, 0.0), v, e));
  }();
  return g;
}

pdnav::PositionFix centre_fix(const WalkGraph& g, double sigma_m) {
  const auto geod = g.frame().to_geodetic(pdnav::geo::Enu(1003.0, 1001.0, 0.0));
  pdnav::PositionFix f;
  f.lat_deg = geod.lat_deg();
  f.lon_deg = geod.lon_deg();
  f.horizontal_sigma_m = sigma_m;
  return f;
}

/// The fix whose initial route set is closest to `target` routes (bisection on sigma).
pdnav::PositionFix fix_for(const std::shared_ptr<const WalkGraph>& g, const RouteOptions& opt, double target) {
  double lo = 0.5, hi = 100.0;
  for (int i = 0; i < 30; ++i) {
    const double mid = 0.5 * (lo + hi);
    RouteEngine e(opt, g, 1);
    e.feed(centre_fix(*g, mid));
    (static_cast<double>(e.route_count()) < target ? lo : hi) = mid;
  }
  return centre_fix(*g, 0.5 * (lo + hi));
}

/// Each benchmark's engine: the grid, room for 100 000 routes, and the fix whose initial route
/// set holds about state.range(0) routes.
struct Setup {
  std::shared_ptr<const WalkGraph> graph;
  RouteOptions options;
  pdnav::PositionFix fix;
};

Setup setup(const benchmark::State& state) {
  Setup b;
  b.graph = grid_graph();
  b.options.max_routes = 100000;
  b.options.min_fix_sigma_m = 0.1;
  b.fix = fix_for(b.graph, b.options, static_cast<double>(state.range(0)));
  return b;
}

/// Items/s = updates fed; `routes` = mean live routes over them.
void report(benchmark::State& state, std::int64_t n, double routes_sum) {
  state.SetItemsProcessed(n);
  state.counters["routes"] = n > 0 ? routes_sum / static_cast<double>(n) : 0.0;
}

void BM_RouteStep(benchmark::State& state) {
  const Setup b = setup(state);
  const auto& g = b.graph;
  const RouteOptions& opt = b.options;
  const pdnav::PositionFix& fix = b.fix;
  RouteEngine engine(opt, g, 1);
  engine.feed(fix);
  const std::size_t initial = engine.route_count();
  pdnav::PdrStep step;
  step.length_m = 0.7;
  step.heading_sigma_rad = 0.3;
  double routes_sum = 0.0;
  std::int64_t n = 0, k = 0;
  for (auto _ : state) {
    step.t_ns += pdnav::kNsPerS / 2;
    step.heading_rad = static_cast<double>(k++ % 4) * 0.5 * pdnav::kPi;
    engine.feed(step);
    routes_sum += static_cast<double>(engine.route_count());
    ++n;
    if (engine.route_count() < initial * 8 / 10 || k > 600) {  // re-seed before the grid edge
      state.PauseTiming();
      RouteEngine fresh(opt, g, 1);
      fresh.feed(fix);
      engine = std::move(fresh);
      k = 0;
      state.ResumeTiming();
    }
  }
  report(state, n, routes_sum);
}
BENCHMARK(BM_RouteStep)->Arg(10)->Arg(100)->Arg(1000);

void BM_RouteTurn(benchmark::State& state) {
  const Setup b = setup(state);
  const auto& g = b.graph;
  const RouteOptions& opt = b.options;
  const pdnav::PositionFix& fix = b.fix;
  double routes_sum = 0.0;
  std::int64_t n = 0;
  RouteEngine base(opt, g, 1);
  base.feed(fix);
  for (auto _ : state) {
    state.PauseTiming();
    RouteEngine engine = base;
    routes_sum += static_cast<double>(engine.route_count());
    pdnav::PdrTurn turn;
    turn.angle_rad = 0.5 * pdnav::kPi;
    state.ResumeTiming();
    engine.feed(turn);
    benchmark::DoNotOptimize(engine.route_count());
    ++n;
  }
  report(state, n, routes_sum);
}
BENCHMARK(BM_RouteTurn)->Arg(10)->Arg(100)->Arg(1000);

// Shortest path ("Go to", route::Router) on the same 2 km grid (40 401 vertices, 80 400 edges):
// one query per iteration from near the centre to a point `arg` metres away diagonally
// (both snapped from 3 m off a street); `settled` = nodes A* settled per query.
void BM_RouterShortest(benchmark::State& state) {
  const auto g = grid_graph();
  const pdnav::route::Router router(pdnav::route::RouterOptions{}, g);
  const double d = static_cast<double>(state.range(0)) / std::sqrt(2.0);
  const Eigen::Vector2d from(1003.0, 1001.5), to(1003.0 - d, 1001.5 - d);
  double settled = 0.0;
  std::int64_t n = 0;
  for (auto _ : state) {
    const pdnav::route::RoutePath p = router.shortest(from, to);
    benchmark::DoNotOptimize(p.length_m);
    settled += static_cast<double>(p.settled);
    ++n;
  }
  state.SetItemsProcessed(n);
  state.counters["settled"] = n ? settled / static_cast<double>(n) : 0.0;
}
BENCHMARK(BM_RouterShortest)->Arg(100)->Arg(500)->Arg(1400)->Unit(benchmark::kMicrosecond);

// Building the router (connected components) on the grid.
void BM_RouterBuild(benchmark::State& state) {
  const auto g = grid_graph();
  for (auto _ : state) {
    const pdnav::route::Router router(pdnav::route::RouterOptions{}, g);
    benchmark::DoNotOptimize(router.component_count());
  }
}
BENCHMARK(BM_RouterBuild)->Unit(benchmark::kMillisecond);

}  // namespace
