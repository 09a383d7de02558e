// Shortest walkway path on the WalkGraph ("Go to" in the app, `pdnav route`): A* (Hart,
// Nilsson, Raphael 1968) over the graph's straight segments with the straight-line distance
// as the heuristic (admissible and consistent in the plane, so the first settled target is
// optimal, as Dijkstra's would be). Both ends are snapped to the nearest point of the
// connected component that holds both (the one with the smallest sum of the two snap
// distances). docs/route.md ("Shortest path").
#pragma once
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/frames.h"
#include "pdnav/route/walk_graph.h"

namespace pdnav::route {

struct RouterOptions {
  /// A query point farther than this from every walkway of a component does not snap to it;
  /// with no component within reach of both ends there is no path (the caller shows the
  /// straight bearing only). 1 km: beyond it the off-path leg dominates any walkway route.
  double max_snap_m = 1000.0;
};

/// A point on the graph: a directed segment (always the even one, 2k) and the distance
/// along it from its start.
struct GraphPoint {
  std::int32_t segment = -1;
  double offset_m = 0.0;
  Eigen::Vector2d en_m = Eigen::Vector2d::Zero();
  double snap_m = 0.0;           // straight distance from the query point
  std::int32_t component = -1;
};

struct RoutePath {
  bool found = false;
  std::string reason;            // why not found (empty when found)
  double length_m = 0.0;         // along the graph, from the from-snap to the to-snap
  double from_snap_m = 0.0;      // query point -> start of the path (straight)
  double to_snap_m = 0.0;        // end of the path -> query point (straight)
  GraphPoint from, to;
  std::vector<std::int32_t> nodes;          // graph nodes passed, in order (vertices and shape points)
  std::vector<std::int32_t> edges;          // WalkGraph edges walked, in order (no repeats in a row)
  std::vector<Eigen::Vector2d> polyline_en_m;  // from-snap, nodes..., to-snap (graph frame)
  std::size_t settled = 0;       // nodes settled by the search (cost)
};

class Router {
 public:
  /// Labels the connected components once (linear in the graph size).
  Router(const RouterOptions& options, std::shared_ptr<const WalkGraph> graph);

  /// Shortest path between two points of the graph's local frame. Never throws for
  /// finite input; non-finite input -> std::invalid_argument.
  RoutePath shortest(const Eigen::Vector2d& from_en_m, const Eigen::Vector2d& to_en_m) const;
  /// Same from WGS84 degrees (projected with h = 0 like the graph's vertices).
  RoutePath shortest_geodetic(double from_lat_deg, double from_lon_deg, double to_lat_deg,
                              double to_lon_deg) const;

  std::size_t component_count() const { return component_size_.size(); }
  std::int32_t component_of_node(std::int32_t node) const { return component_[node]; }
  const WalkGraph& graph() const { return *graph_; }
  const RouterOptions& options() const { return opt_; }

 private:
  /// Nearest point of each component within radius_m of p (index = component; snap_m =
  /// +inf where none).
  std::vector<GraphPoint> nearest_per_component(const Eigen::Vector2d& p, double radius_m) const;

  RouterOptions opt_;
  std::shared_ptr<const WalkGraph> graph_;
  std::vector<std::int32_t> component_;       // per node
  std::vector<std::int32_t> component_size_;  // nodes per component
};

}  // namespace pdnav::route
