// The walkway graph of the route engine (APT Sec. VI map model: vertices, edges, straight
// segments). Made by dem-tools/pdnav_graph.py from OpenStreetMap; format in
// docs/graph-format.md. This is the one reader of that format in the core.
#pragma once
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/frames.h"

namespace pdnav::route {

/// Walkway graph in the local ENU tangent plane of its geodetic origin (metres, east/north).
/// Internally every polyline point is a node and every straight piece gives two directed
/// segments, ids 2k and 2k+1 (reverse(s) == s ^ 1). Nodes [0, vertex_count()) are the
/// graph vertices (junctions and way ends); the rest are shape points of curved edges.
class WalkGraph {
 public:
  struct Edge {
    std::int32_t from = 0;                       // vertex index
    std::int32_t to = 0;                         // vertex index
    std::string highway;                         // OSM highway class, e.g. "footway"
    std::int64_t way_id = 0;                     // OSM way id (0 when unknown)
    std::vector<Eigen::Vector2d> shape_en_m;     // interior points, from -> to order
  };
  struct Segment {
    std::int32_t from = 0, to = 0;               // node indices
    std::int32_t edge = 0;                       // edge index
    Eigen::Vector2d a_en_m = Eigen::Vector2d::Zero(), b_en_m = Eigen::Vector2d::Zero();
    Eigen::Vector2d dir = Eigen::Vector2d::Zero();  // unit vector a -> b (east, north)
    double length_m = 0.0;
    double heading_rad = 0.0;                    // clockwise from north, [0, 2pi)
    std::int32_t next_in_edge = -1;              // continuation through a shape point, else -1
    std::int32_t prev_in_edge = -1;              // predecessor through a shape point, else -1
  };

  WalkGraph() = default;
  /// Read a graph file; throws std::runtime_error "path:line: reason" on any defect.
  static WalkGraph load(const std::string& path);
  /// Same from a stream; `name` is used in error messages.
  static WalkGraph parse(std::istream& in, const std::string& name);
  /// Build from memory (tests, simulations). Validates like the reader.
  static WalkGraph build(const geo::Geodetic& origin, std::vector<Eigen::Vector2d> vertices_en_m,
                         std::vector<Edge> edges);

  const geo::LocalFrame& frame() const { return frame_; }
  std::size_t vertex_count() const { return vertex_count_; }
  std::size_t node_count() const { return nodes_.size(); }
  std::size_t edge_count() const { return edges_.size(); }
  std::size_t segment_count() const { return segments_.size(); }
  std::size_t skipped_segments() const { return skipped_; }  // zero-length pieces dropped
  double total_length_m() const { return total_length_m_; }

  const Eigen::Vector2d& node_en_m(std::int32_t n) const { return nodes_[n]; }
  bool is_vertex(std::int32_t n) const { return n < static_cast<std::int32_t>(vertex_count_); }
  const Edge& edge(std::int32_t e) const { return edges_[e]; }
  const Segment& segment(std::int32_t s) const { return segments_[s]; }
  static std::int32_t reverse(std::int32_t s) { return s ^ 1; }
  /// Directed segments leaving a node.
  const std::vector<std::int32_t>& out_segments(std::int32_t node) const { return out_[node]; }

  /// Directed segments (both directions) within radius_m of p (distance to the segment).
  std::vector<std::int32_t> segments_near(const Eigen::Vector2d& p_en_m, double radius_m) const;
  /// Closest point of a segment to p and its distance along the segment from `a`.
  static double project(const Segment& s, const Eigen::Vector2d& p_en_m, Eigen::Vector2d* closest);

 private:
  void finish();  // segments, adjacency, spatial grid
  std::int64_t cell_key(std::int64_t cx, std::int64_t cy) const;

  geo::LocalFrame frame_;
  std::size_t vertex_count_ = 0;
  std::size_t skipped_ = 0;
  double total_length_m_ = 0.0;
  std::vector<Eigen::Vector2d> nodes_;
  std::vector<Edge> edges_;
  std::vector<Segment> segments_;
  std::vector<std::vector<std::int32_t>> out_;
  // Uniform grid of undirected pieces (segment id / 2), sorted by cell key.
  double cell_m_ = 50.0;
  std::vector<std::pair<std::int64_t, std::int32_t>> grid_;
};

}  // namespace pdnav::route
