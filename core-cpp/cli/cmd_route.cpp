// pdnav route: the shortest walkway path between two WGS84 points on a walkway graph
// (route::Router; docs/route.md "Shortest path"). Prints the length, the snaps and the path;
// --json prints the same as one JSON object; --geojson writes the path as a LineString.
// Exit status 0 with a path, 3 when there is none (reason printed), 1 on bad input.
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "pdnav/route/router.h"
#include "pdnav/route/walk_graph.h"
#include "support/eval_support.h"

namespace pdnav::cli {
namespace {

struct RouteArgs {
  std::string graph_path;
  std::string from;
  std::string to;
  std::string geojson_path;
  bool json = false;
  route::RouterOptions options;
};

/// "LAT,LON" in degrees; anything else is an error naming the option.
std::pair<double, double> parse_lat_lon(const std::string& text, const char* what) {
  const auto v = parse_number_list(text);
  if (!v || v->size() != 2) {
    throw std::runtime_error(std::string(what) + ": expected LAT,LON in degrees, got '" + text + "'");
  }
  const double lat = (*v)[0], lon = (*v)[1];
  if (std::fabs(lat) > 90.0 || std::fabs(lon) > 180.0) {
    throw std::runtime_error(std::string(what) + ": latitude must be within +-90 and longitude +-180, got '" + text + "'");
  }
  return {lat, lon};
}

std::string fmt(double v, int prec) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(prec) << v;
  return s.str();
}

int run_route(const RouteArgs& a) {
  const auto [lat0, lon0] = parse_lat_lon(a.from, "--from");
  const auto [lat1, lon1] = parse_lat_lon(a.to, "--to");
  auto graph = std::make_shared<const route::WalkGraph>(route::WalkGraph::load(a.graph_path));
  const route::Router router(a.options, graph);
  const route::RoutePath p = router.shortest_geodetic(lat0, lon0, lat1, lon1);
  auto geodetic = [&](const Eigen::Vector2d& en) {
    return graph->frame().to_geodetic(geo::Enu(en.x(), en.y(), 0.0));
  };
  nlohmann::json poly = nlohmann::json::array();
  for (const auto& q : p.polyline_en_m) {
    const geo::Geodetic g = geodetic(q);
    poly.push_back({g.lon_deg(), g.lat_deg()});
  }
  std::vector<std::int32_t> vertices;
  for (const std::int32_t n : p.nodes)
    if (graph->is_vertex(n)) vertices.push_back(n);

  if (!a.geojson_path.empty()) {
    nlohmann::json fc = {{"type", "FeatureCollection"}, {"features", nlohmann::json::array()}};
    if (p.found) {
      fc["features"].push_back({{"type", "Feature"},
                                {"geometry", {{"type", "LineString"}, {"coordinates", poly}}},
                                {"properties", {{"length_m", p.length_m}, {"from_snap_m", p.from_snap_m},
                                                {"to_snap_m", p.to_snap_m}, {"edges", p.edges}}}});
    }
    std::ofstream f(a.geojson_path);
    if (!f) throw std::runtime_error(a.geojson_path + ": cannot open for writing");
    f << fc.dump(1) << "\n";
    if (!f) throw std::runtime_error(a.geojson_path + ": write failed");
  }

  if (a.json) {
    nlohmann::json j;
    j["found"] = p.found;
    j["reason"] = p.reason;
    j["components"] = router.component_count();
    if (p.found) {
      const geo::Geodetic gf = geodetic(p.from.en_m), gt = geodetic(p.to.en_m);
      j["length_m"] = p.length_m;
      j["from_snap_m"] = p.from_snap_m;
      j["to_snap_m"] = p.to_snap_m;
      j["from"] = {{"lat", gf.lat_deg()}, {"lon", gf.lon_deg()}, {"edge", graph->segment(p.from.segment).edge},
                   {"east_m", p.from.en_m.x()}, {"north_m", p.from.en_m.y()}};
      j["to"] = {{"lat", gt.lat_deg()}, {"lon", gt.lon_deg()}, {"edge", graph->segment(p.to.segment).edge},
                 {"east_m", p.to.en_m.x()}, {"north_m", p.to.en_m.y()}};
      j["vertices"] = vertices;
      j["edges"] = p.edges;
      j["settled"] = p.settled;
      j["polyline_lon_lat"] = poly;
    }
    std::cout << j.dump() << std::endl;
    return p.found ? 0 : 3;
  }

  std::cout << "graph: " << a.graph_path << "  vertices " << graph->vertex_count() << "  edges "
            << graph->edge_count() << "  connected components " << router.component_count() << "\n";
  if (!p.found) {
    std::cout << "no path: " << p.reason << std::endl;
    return 3;
  }
  const geo::Geodetic gf = geodetic(p.from.en_m), gt = geodetic(p.to.en_m);
  std::cout << "from " << fmt(lat0, 7) << "," << fmt(lon0, 7) << " snapped to " << fmt(gf.lat_deg(), 7) << ","
            << fmt(gf.lon_deg(), 7) << " on edge " << graph->segment(p.from.segment).edge << "\n";
  std::cout << "to   " << fmt(lat1, 7) << "," << fmt(lon1, 7) << " snapped to " << fmt(gt.lat_deg(), 7) << ","
            << fmt(gt.lon_deg(), 7) << " on edge " << graph->segment(p.to.segment).edge << "\n";
  std::cout << "vertices:";
  for (const auto v : vertices) std::cout << " " << v;
  std::cout << "\nedges:";
  for (const auto e : p.edges) std::cout << " " << e;
  std::cout << "\nlength_m: " << fmt(p.length_m, 2) << " from_snap_m: " << fmt(p.from_snap_m, 2)
            << " to_snap_m: " << fmt(p.to_snap_m, 2) << " nodes_settled: " << p.settled << std::endl;
  return 0;
}

}  // namespace

void register_route(CLI::App& app) {
  auto args = std::make_shared<RouteArgs>();
  CLI::App* cmd = app.add_subcommand("route", "Shortest walkway path between two points on a walkway graph");
  cmd->add_option("--graph", args->graph_path, "pdnav walkway graph (dem-tools/pdnav_graph.py)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--from", args->from, "start, LAT,LON in degrees (WGS84)")->required();
  cmd->add_option("--to", args->to, "destination, LAT,LON in degrees (WGS84)")->required();
  cmd->add_option("--geojson", args->geojson_path, "write the path as a GeoJSON LineString");
  cmd->add_flag("--json", args->json, "print the result as one JSON object");
  cmd->add_option("--max-snap", args->options.max_snap_m, "farthest a query point snaps onto a walkway, m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->callback([args]() {
    const int rc = run_route(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace pdnav::cli
