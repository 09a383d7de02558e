// libFuzzer target: the walkway graph reader (docs/graph-format.md), a route engine and the
// shortest-path router on whatever it accepts. Any input must give a graph or a
// std::runtime_error/invalid_argument, never a crash, hang or NaN estimate; a path the router
// finds has a finite length equal to its polyline's. Seeds: tests/fuzz-corpus/graph_reader/.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pdnav/route/route_engine.h"
#include "pdnav/route/router.h"
#include "pdnav/route/walk_graph.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > (1u << 16)) return 0;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  std::shared_ptr<const pdnav::route::WalkGraph> g;
  try {
    g = std::make_shared<const pdnav::route::WalkGraph>(pdnav::route::WalkGraph::parse(in, "fuzz"));
  } catch (const std::runtime_error&) {
    return 0;
  } catch (const std::invalid_argument&) {
    return 0;
  }
  if (g->node_count() > 4096 || g->segment_count() > 8192) return 0;  // keep runs fast
  pdnav::route::RouteOptions opt;
  opt.max_routes = 256;
  pdnav::route::RouteEngine engine(opt, g, 1);
  const auto origin = g->frame().origin();
  pdnav::PositionFix fix;
  fix.lat_deg = origin.lat_deg();
  fix.lon_deg = origin.lon_deg();
  fix.horizontal_sigma_m = 20.0;
  engine.feed(fix);
  pdnav::PdrStep step;
  for (int i = 0; i < 20; ++i) {
    step.t_ns += 500'000'000;
    step.length_m = 0.7;
    step.heading_rad = 0.3 * i;
    engine.feed(step);
  }
  pdnav::PdrTurn turn;
  turn.t_ns = step.t_ns;
  turn.start_ns = step.t_ns - 1'000'000'000;
  turn.angle_rad = 1.5;
  engine.feed(turn);
  const auto e = engine.estimate();
  if (!e.en_m.allFinite()) std::abort();

  // shortest paths between points derived from the input (near nodes, the origin, far away)
  const pdnav::route::Router router(pdnav::route::RouterOptions{}, g);
  const auto n = static_cast<std::int32_t>(g->node_count());
  auto node = [&](std::size_t k) {
    return n > 0 ? g->node_en_m(static_cast<std::int32_t>(data[k % size] % static_cast<std::uint32_t>(n)))
                 : Eigen::Vector2d(0.0, 0.0);
  };
  const Eigen::Vector2d queries[][2] = {
      {node(0) + Eigen::Vector2d(3.0, -2.0), node(size / 2) + Eigen::Vector2d(-1.0, 4.0)},
      {Eigen::Vector2d(0.0, 0.0), node(size - 1)},
      {node(1), node(1)},
      {Eigen::Vector2d(5000.0, 5000.0), node(2)},
  };
  for (const auto& q : queries) {
    const pdnav::route::RoutePath p = router.shortest(q[0], q[1]);
    if (!p.found) continue;
    double poly = 0.0;
    for (std::size_t i = 1; i < p.polyline_en_m.size(); ++i) poly += (p.polyline_en_m[i] - p.polyline_en_m[i - 1]).norm();
    if (!std::isfinite(p.length_m) || p.length_m < 0.0 || p.polyline_en_m.size() < 2 ||
        std::fabs(poly - p.length_m) > 1e-6 * (1.0 + p.length_m) ||
        p.from_snap_m > router.options().max_snap_m || p.to_snap_m > router.options().max_snap_m) {
      std::abort();
    }
  }
  return 0;
}
