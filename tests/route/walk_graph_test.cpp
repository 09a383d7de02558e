// WalkGraph reader: structure from a small file, and clear errors on defects.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pdnav/geo/units.h"
#include "pdnav/route/walk_graph.h"
#include "test_data.h"

namespace pdnav::route {
namespace {

using ::testing::HasSubstr;

// An L: vertex 0 (0,0) -- vertex 1 (100,0) along the east axis with a shape point at (50,0)
// and another edge 1 -> 2 going north with a bend through (100,30) -> (110,60).
const char* kSmallGraph =
    "pdnav-graph 1\n"
    "# comment\n"
    "origin 42.5 1.5 0\n"
    "vertices 3\n"
    "v 0 0 0\n"
    "v 1 100 0\n"
    "v 2 110 100\n"
    "edges 2\n"
    "e 0 0 1 residential 101 1 50 0\n"
    "e 1 1 2 footway 102 2 100 30 110 60\n"
    "end\n";

WalkGraph parse(const std::string& text) {
  std::istringstream in(text);
  return WalkGraph::parse(in, "mem.graph");
}

std::string parse_error(const std::string& text) {
  try {
    parse(text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return {};
}

TEST(WalkGraph, ParsesVerticesEdgesAndSegments) {
  const WalkGraph g = parse(kSmallGraph);
  EXPECT_EQ(g.vertex_count(), 3u);
  EXPECT_EQ(g.edge_count(), 2u);
  EXPECT_EQ(g.node_count(), 6u);      // 3 vertices + 3 shape points
  EXPECT_EQ(g.segment_count(), 10u);  // 5 straight pieces, two directions each
  EXPECT_NEAR(g.total_length_m(), 100.0 + 30.0 + std::hypot(10.0, 30.0) + std::hypot(0.0, 40.0), 1e-9);
  EXPECT_NEAR(g.frame().origin().lat_deg(), 42.5, 1e-12);
  EXPECT_EQ(g.edge(1).highway, "footway");
  EXPECT_EQ(g.edge(1).way_id, 102);
  // Directed ids: reverse pairs, headings clockwise from north.
  const auto& s0 = g.segment(0);
  const auto& r0 = g.segment(WalkGraph::reverse(0));
  EXPECT_EQ(s0.from, r0.to);
  EXPECT_NEAR(s0.heading_rad, kPi / 2, 1e-12);   // east
  EXPECT_NEAR(r0.heading_rad, 3 * kPi / 2, 1e-12);  // west
  // Chaining through the shape point of edge 0, but not through vertex 1.
  EXPECT_EQ(s0.next_in_edge, 2);
  EXPECT_EQ(g.segment(2).prev_in_edge, 0);
  EXPECT_EQ(g.segment(2).next_in_edge, -1);
  // Vertex 1 joins the two edges: two segments leave it (west along edge 0, north on edge 1).
  EXPECT_EQ(g.out_segments(1).size(), 2u);
}

TEST(WalkGraph, SegmentsNearFindsBothDirectionsWithinRadius) {
  const WalkGraph g = parse(kSmallGraph);
  const auto near = g.segments_near(Eigen::Vector2d(25, 5), 6.0);
  ASSERT_EQ(near.size(), 2u);
  EXPECT_EQ(near[0], 0);
  EXPECT_EQ(near[1], 1);
  EXPECT_TRUE(g.segments_near(Eigen::Vector2d(25, 50), 6.0).empty());
  EXPECT_EQ(g.segments_near(Eigen::Vector2d(100, 0), 1.0).size(), 4u);  // both edges at vertex 1
}

TEST(WalkGraph, ErrorsNameFileAndLine) {
  EXPECT_THAT(parse_error(""), HasSubstr("mem.graph:0: empty file"));
  EXPECT_THAT(parse_error("pdnav-graph 2\n"), HasSubstr("mem.graph:1: unsupported format version"));
  EXPECT_THAT(parse_error("pdnav-graph 1\norigin 95 1 0\n"), HasSubstr("mem.graph:2: bad origin latitude"));
  EXPECT_THAT(parse_error("pdnav-graph 1\norigin 42 1 0\nvertices 1\nv 1 0 0\n"),
              HasSubstr("mem.graph:4: vertex ids must be 0, 1, 2"));
  EXPECT_THAT(parse_error("pdnav-graph 1\norigin 42 1 0\nvertices 1\nv 0 nan 0\n"),
              HasSubstr("mem.graph:4: bad east_m 'nan'"));
  EXPECT_THAT(parse_error("pdnav-graph 1\norigin 42 1 0\nvertices 1\nv 0 1,5 0\n"),
              HasSubstr("mem.graph:4: bad east_m '1,5'"));
  EXPECT_THAT(parse_error("pdnav-graph 1\norigin 42 1 0\nvertices 2\nv 0 0 0\nv 1 1 0\nedges 1\ne 0 0 2 path 1 0\nend\n"),
              HasSubstr("mem.graph:7: bad to vertex '2'"));
  EXPECT_THAT(parse_error("pdnav-graph 1\norigin 42 1 0\nvertices 2\nv 0 0 0\nv 1 1 0\nedges 1\ne 0 0 1 path 1 1 5\nend\n"),
              HasSubstr("mem.graph:7: missing north_m"));
  EXPECT_THAT(parse_error("pdnav-graph 1\norigin 42 1 0\nvertices 1\nv 0 0 0 7\n"),
              HasSubstr("mem.graph:4: unexpected trailing text '7'"));
  EXPECT_THAT(parse_error("pdnav-graph 1\norigin 42 1 0\nvertices 1\nv 0 0 0\nedges 0\n"),
              HasSubstr("unexpected end of file"));
  EXPECT_THAT(parse_error("pdnav-graph 1\norigin 42 1 0\nvertices 0\nedges 0\nend\nv 0 0 0\n"),
              HasSubstr("mem.graph:6: text after the 'end' line"));
  EXPECT_THAT(parse_error("pdnav-graph 1\norigin 42 1 0\nvertices 99999999999\n"),
              HasSubstr("mem.graph:3: bad vertex count"));
}

TEST(WalkGraph, LoadMissingFileNamesIt) {
  try {
    WalkGraph::load("/nonexistent/x.graph");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/x.graph"));
  }
}

TEST(WalkGraph, DuplicatePointsAndZeroLengthEdgesAreSkipped) {
  const WalkGraph g = parse(
      "pdnav-graph 1\norigin 42 1 0\nvertices 2\nv 0 0 0\nv 1 10 0\nedges 2\n"
      "e 0 0 1 path 1 3 5 0 5 0 10 0\ne 1 0 0 path 2 0\nend\n");
  EXPECT_EQ(g.segment_count(), 4u);  // (0,0)-(5,0)-(10,0)
  EXPECT_EQ(g.skipped_segments(), 3u);
  EXPECT_NEAR(g.total_length_m(), 10.0, 1e-12);
}

// End to end with the extractor: a tiny OSM file through dem-tools/pdnav_graph.py, read
// back by the core reader.
TEST(WalkGraph, ReadsWhatTheExtractorWrites) {
  const auto dir = test::scratch_dir("route_graph_e2e");
  const auto osm = dir / "tiny.osm";
  {
    std::ofstream f(osm);
    f << "<?xml version=\"1.0\"?>\n<osm version=\"0.6\">\n"
         "<node id=\"1\" version=\"1\" lat=\"42.5\" lon=\"1.5\"/>\n"
         "<node id=\"2\" version=\"1\" lat=\"42.5\" lon=\"1.501\"/>\n"
         "<node id=\"3\" version=\"1\" lat=\"42.501\" lon=\"1.501\"/>\n"
         "<node id=\"4\" version=\"1\" lat=\"42.5\" lon=\"1.502\"/>\n"
         "<way id=\"10\" version=\"1\"><nd ref=\"1\"/><nd ref=\"2\"/><nd ref=\"4\"/>"
         "<tag k=\"highway\" v=\"residential\"/></way>\n"
         "<way id=\"11\" version=\"1\"><nd ref=\"2\"/><nd ref=\"3\"/><tag k=\"highway\" v=\"steps\"/></way>\n"
         "</osm>\n";
  }
  const auto out = dir / "tiny.graph";
  const std::string tool = std::string(PDNAV_SOURCE_DIR) + "/dem-tools/pdnav_graph.py";
  const std::string cmd = "/usr/bin/python3 '" + tool + "' '" + osm.string() + "' '" + out.string() +
                          "' --origin 42.5 1.5 > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const WalkGraph g = WalkGraph::load(out.string());
  EXPECT_EQ(g.vertex_count(), 4u);
  EXPECT_EQ(g.edge_count(), 3u);  // residential split at node 2, plus the steps
  // 0.002 deg of longitude at 42.5 deg = 164.1 m; 0.001 deg of latitude = 111.1 m.
  EXPECT_NEAR(g.total_length_m(), 164.1 + 111.1, 0.5);
  // The reader's frame reproduces the extractor's projection: node 3 back to lat/lon.
  for (std::size_t v = 0; v < g.vertex_count(); ++v) {
    const auto p = g.node_en_m(static_cast<std::int32_t>(v));
    const auto geo = g.frame().to_geodetic(geo::Enu(p.x(), p.y(), 0.0));
    if (geo.lat_deg() > 42.5005) {
      EXPECT_NEAR(geo.lat_deg(), 42.501, 1e-7);
      EXPECT_NEAR(geo.lon_deg(), 1.501, 1e-7);
    }
  }
}

}  // namespace
}  // namespace pdnav::route
