// libFuzzer target: the walkway graph reader (docs/graph-format.md) and a route engine on
// whatever it accepts. Any input must give a graph or a std::runtime_error/invalid_argument,
// never a crash, hang or NaN estimate. Seeds: tests/fuzz-corpus/graph_reader/.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pdnav/route/route_engine.h"
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
  return 0;
}
