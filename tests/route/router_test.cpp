// route::Router: shortest walkway paths on small handmade graphs (one edge, from == to, curved
// edges, disconnected pieces, points far off the graph, bad input) and against an independent
// Floyd-Warshall on seeded random graphs. The real-graph check against scipy is the ctest
// route_shortest_vs_scipy (tests/route/check_shortest_path.py).
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/geo/frames.h"
#include "pdnav/route/router.h"
#include "pdnav/route/walk_graph.h"

namespace pdnav::route {
namespace {

using V = Eigen::Vector2d;
const geo::Geodetic kOrigin = geo::Geodetic::from_deg(42.5, 1.5, 0.0);

WalkGraph::Edge edge(std::int32_t a, std::int32_t b, std::vector<V> shape = {}) {
  WalkGraph::Edge e;
  e.from = a;
  e.to = b;
  e.highway = "footway";
  e.shape_en_m = std::move(shape);
  return e;
}

std::shared_ptr<const WalkGraph> make(std::vector<V> vertices, std::vector<WalkGraph::Edge> edges) {
  return std::make_shared<const WalkGraph>(WalkGraph::build(kOrigin, std::move(vertices), std::move(edges)));
}

double polyline_length(const RoutePath& p) {
  double s = 0.0;
  for (std::size_t i = 1; i < p.polyline_en_m.size(); ++i) s += (p.polyline_en_m[i] - p.polyline_en_m[i - 1]).norm();
  return s;
}

TEST(Router, OneEdgeAlongItBetweenTheProjections) {
  auto g = make({V(0, 0), V(100, 0)}, {edge(0, 1)});
  const Router r(RouterOptions{}, g);
  const RoutePath p = r.shortest(V(20, 5), V(70, -3));
  ASSERT_TRUE(p.found) << p.reason;
  EXPECT_NEAR(p.length_m, 50.0, 1e-9);
  EXPECT_NEAR(p.from_snap_m, 5.0, 1e-9);
  EXPECT_NEAR(p.to_snap_m, 3.0, 1e-9);
  EXPECT_TRUE(p.nodes.empty());  // along the one segment, no node passed
  ASSERT_EQ(p.polyline_en_m.size(), 2u);
  EXPECT_NEAR((p.polyline_en_m.front() - V(20, 0)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((p.polyline_en_m.back() - V(70, 0)).norm(), 0.0, 1e-9);
  EXPECT_EQ(p.edges, std::vector<std::int32_t>{0});
}

TEST(Router, FromEqualsToIsAZeroLengthPath) {
  auto g = make({V(0, 0), V(100, 0), V(100, 80)}, {edge(0, 1), edge(1, 2)});
  const Router r(RouterOptions{}, g);
  const RoutePath p = r.shortest(V(100, 30), V(100, 30));
  ASSERT_TRUE(p.found);
  EXPECT_EQ(p.length_m, 0.0);
  EXPECT_EQ(p.from_snap_m, 0.0);
  EXPECT_EQ(p.to_snap_m, 0.0);
  EXPECT_EQ(p.polyline_en_m.size(), 2u);
  // on a vertex too
  const RoutePath q = r.shortest(V(100, 0), V(100, 0));
  ASSERT_TRUE(q.found);
  EXPECT_NEAR(q.length_m, 0.0, 1e-12);
}

TEST(Router, FollowsCurvedEdgesThroughShapePoints) {
  // 0 -> 1 as a detour through (50, 40) (2 x 64.03 m) and 1 -> 2 straight.
  auto g = make({V(0, 0), V(100, 0), V(100, 50)}, {edge(0, 1, {V(50, 40)}), edge(1, 2)});
  const Router r(RouterOptions{}, g);
  const RoutePath p = r.shortest(V(0, 0), V(100, 50));
  ASSERT_TRUE(p.found);
  const double expect = 2.0 * std::hypot(50.0, 40.0) + 50.0;
  EXPECT_NEAR(p.length_m, expect, 1e-9);
  EXPECT_NEAR(polyline_length(p), expect, 1e-9);
  EXPECT_EQ(p.edges, (std::vector<std::int32_t>{0, 1}));
}

TEST(Router, TakesTheShorterOfTwoWaysRoundALoop) {
  // square 100 x 100 with the start on the south side near the west corner and the end on
  // the east side near the north: west+north (30 + 100 + 100 + 10 = ...) vs east (70 + 90).
  auto g = make({V(0, 0), V(100, 0), V(100, 100), V(0, 100)},
                {edge(0, 1), edge(1, 2), edge(2, 3), edge(3, 0)});
  const Router r(RouterOptions{}, g);
  const RoutePath p = r.shortest(V(30, -1), V(101, 90));
  ASSERT_TRUE(p.found);
  EXPECT_NEAR(p.length_m, 70.0 + 90.0, 1e-9);
  ASSERT_EQ(p.nodes.size(), 1u);
  EXPECT_EQ(p.nodes[0], 1);
  const RoutePath q = r.shortest(V(10, -1), V(101, 90));  // now west/north: 10 + 100 + 100 + 10 = 220 > 90 + 90
  ASSERT_TRUE(q.found);
  EXPECT_NEAR(q.length_m, 180.0, 1e-9);
}

TEST(Router, DisconnectedPiecesUseTheComponentThatHoldsBothEnds) {
  // A: a long street y = 0; B: a short isolated path near the start only (y = 20).
  auto g = make({V(0, 0), V(1000, 0), V(0, 20), V(40, 20)}, {edge(0, 1), edge(2, 3)});
  const Router r(RouterOptions{}, g);
  EXPECT_EQ(r.component_count(), 2u);
  // start at (10, 18): 2 m from B, 18 m from A; end at (900, 1): only A is near (B is 860 m away)
  const RoutePath p = r.shortest(V(10, 18), V(900, 1));
  ASSERT_TRUE(p.found);
  EXPECT_EQ(p.from.component, r.component_of_node(0));
  EXPECT_NEAR(p.from_snap_m, 18.0, 1e-9);
  EXPECT_NEAR(p.length_m, 890.0, 1e-9);
  // both ends near B: B is used
  const RoutePath q = r.shortest(V(5, 21), V(35, 21));
  ASSERT_TRUE(q.found);
  EXPECT_EQ(q.from.component, r.component_of_node(2));
  EXPECT_NEAR(q.length_m, 30.0, 1e-9);
}

TEST(Router, NoPathWhenNoCommonComponentIsWithinReach) {
  // two streets 5 km apart, not connected
  auto g = make({V(0, 0), V(100, 0), V(5000, 0), V(5100, 0)}, {edge(0, 1), edge(2, 3)});
  const Router r(RouterOptions{}, g);
  const RoutePath p = r.shortest(V(50, 1), V(5050, 1));
  EXPECT_FALSE(p.found);
  EXPECT_NE(p.reason.find("not connected"), std::string::npos) << p.reason;
  EXPECT_TRUE(p.polyline_en_m.empty());
  // far off the graph: nothing within 1 km of the start
  const RoutePath far = r.shortest(V(50, 3000), V(50, 1));
  EXPECT_FALSE(far.found);
  EXPECT_NE(far.reason.find("of the start"), std::string::npos) << far.reason;
  const RoutePath far_to = r.shortest(V(50, 1), V(50, -3000));
  EXPECT_FALSE(far_to.found);
  EXPECT_NE(far_to.reason.find("of the destination"), std::string::npos) << far_to.reason;
  // a larger reach snaps the far point (linear scan above the grid's 10 km search)
  RouterOptions wide;
  wide.max_snap_m = 20000.0;
  const Router rw(wide, g);
  const RoutePath w = rw.shortest(V(50, 3000), V(60, 1));
  ASSERT_TRUE(w.found);
  EXPECT_NEAR(w.from_snap_m, 3000.0, 1e-9);
  EXPECT_NEAR(w.length_m, 10.0, 1e-9);
}

TEST(Router, RejectsNonFiniteInput) {
  auto g = make({V(0, 0), V(100, 0)}, {edge(0, 1)});
  const Router r(RouterOptions{}, g);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(r.shortest(V(nan, 0), V(1, 0)), std::invalid_argument);
  EXPECT_THROW(r.shortest(V(0, 0), V(std::numeric_limits<double>::infinity(), 0)), std::invalid_argument);
  EXPECT_THROW(r.shortest_geodetic(nan, 1.5, 42.5, 1.5), std::invalid_argument);
  EXPECT_THROW(r.shortest_geodetic(91.0, 1.5, 42.5, 1.5), std::invalid_argument);
  RouterOptions bad;
  bad.max_snap_m = 0.0;
  EXPECT_THROW(Router(bad, g), std::invalid_argument);
}

TEST(Router, GeodeticQueriesUseTheGraphFrame) {
  auto g = make({V(0, 0), V(0, 1000)}, {edge(0, 1)});
  const Router r(RouterOptions{}, g);
  const geo::Geodetic a = g->frame().to_geodetic(geo::Enu(3, 100, 0));
  const geo::Geodetic b = g->frame().to_geodetic(geo::Enu(-4, 900, 0));
  const RoutePath p = r.shortest_geodetic(a.lat_deg(), a.lon_deg(), b.lat_deg(), b.lon_deg());
  ASSERT_TRUE(p.found);
  EXPECT_NEAR(p.length_m, 800.0, 0.01);
  EXPECT_NEAR(p.from_snap_m, 3.0, 0.01);
  EXPECT_NEAR(p.to_snap_m, 4.0, 0.01);
}

// Independent check: on seeded random graphs (jittered grid with missing streets and shape
// points), the path length equals min over the four end-node combinations of the
// Floyd-Warshall node distances plus the along-segment legs (or the direct leg on one segment).
TEST(Router, EqualsFloydWarshallOnRandomGraphs) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> jit(-15.0, 15.0), u01(0.0, 1.0);
    const int n = 7;
    std::vector<V> verts;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) verts.emplace_back(100.0 * i + jit(rng), 100.0 * j + jit(rng));
    std::vector<WalkGraph::Edge> edges;
    auto id = [&](int i, int j) { return i * n + j; };
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        for (auto [di, dj] : {std::pair{1, 0}, std::pair{0, 1}}) {
          if (i + di >= n || j + dj >= n || u01(rng) < 0.25) continue;  // missing streets
          const V a = verts[id(i, j)], b = verts[id(i + di, j + dj)];
          std::vector<V> shape;
          if (u01(rng) < 0.4) shape.push_back(0.5 * (a + b) + V(jit(rng), jit(rng)));  // a bend
          edges.push_back(edge(id(i, j), id(i + di, j + dj), shape));
        }
      }
    }
    auto g = make(verts, edges);
    const Router r(RouterOptions{}, g);
    // all-pairs over internal nodes
    const auto N = static_cast<int>(g->node_count());
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<double> d(static_cast<std::size_t>(N) * N, inf);
    for (int k = 0; k < N; ++k) d[k * N + k] = 0.0;
    for (std::size_t s = 0; s < g->segment_count(); ++s) {
      const auto& seg = g->segment(static_cast<std::int32_t>(s));
      double& x = d[seg.from * N + seg.to];
      x = std::min(x, seg.length_m);
    }
    for (int k = 0; k < N; ++k)
      for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j) d[i * N + j] = std::min(d[i * N + j], d[i * N + k] + d[k * N + j]);

    std::uniform_real_distribution<double> pos(-50.0, 650.0);
    int checked = 0;
    for (int q = 0; q < 60; ++q) {
      const V from(pos(rng), pos(rng)), to(pos(rng), pos(rng));
      const RoutePath p = r.shortest(from, to);
      ASSERT_TRUE(p.found) << p.reason;
      const auto& sa = g->segment(p.from.segment);
      const auto& sb = g->segment(p.to.segment);
      double expect = inf;
      if (p.from.segment == p.to.segment) expect = std::fabs(p.from.offset_m - p.to.offset_m);
      for (auto [na, la] : {std::pair{sa.from, p.from.offset_m}, std::pair{sa.to, sa.length_m - p.from.offset_m}})
        for (auto [nb, lb] : {std::pair{sb.from, p.to.offset_m}, std::pair{sb.to, sb.length_m - p.to.offset_m}})
          expect = std::min(expect, la + d[na * N + nb] + lb);
      EXPECT_NEAR(p.length_m, expect, 1e-6) << "seed " << seed << " query " << q;
      EXPECT_NEAR(polyline_length(p), p.length_m, 1e-6);
      // the snaps are the nearest graph points of that component (brute force)
      double best_from = inf, best_to = inf;
      for (std::size_t s = 0; s < g->segment_count(); s += 2) {
        const auto& seg = g->segment(static_cast<std::int32_t>(s));
        if (r.component_of_node(seg.from) != p.from.component) continue;
        V c;
        WalkGraph::project(seg, from, &c);
        best_from = std::min(best_from, (c - from).norm());
        WalkGraph::project(seg, to, &c);
        best_to = std::min(best_to, (c - to).norm());
      }
      EXPECT_NEAR(p.from_snap_m, best_from, 1e-9);
      EXPECT_NEAR(p.to_snap_m, best_to, 1e-9);
      ++checked;
    }
    EXPECT_EQ(checked, 60);
  }
}

TEST(Router, IsDeterministic) {
  auto g = make({V(0, 0), V(100, 0), V(100, 100), V(0, 100)},
                {edge(0, 1), edge(1, 2), edge(2, 3), edge(3, 0)});
  const Router r(RouterOptions{}, g);
  // symmetric query: both ways round are 200 m; the answer must not change between calls
  const RoutePath a = r.shortest(V(0, 0), V(100, 100));
  const RoutePath b = r.shortest(V(0, 0), V(100, 100));
  ASSERT_TRUE(a.found);
  EXPECT_NEAR(a.length_m, 200.0, 1e-9);
  EXPECT_EQ(a.nodes, b.nodes);
}

}  // namespace
}  // namespace pdnav::route
