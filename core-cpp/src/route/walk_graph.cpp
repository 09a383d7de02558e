#include "pdnav/route/walk_graph.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <locale>
#include <sstream>
#include <stdexcept>

#include "pdnav/geo/units.h"

namespace pdnav::route {
namespace {

constexpr std::int64_t kMaxCount = 50'000'000;  // vertices / edges / shape points per edge
constexpr double kMaxCoord_m = 1.0e6;           // a local tangent frame never spans more

/// Line-oriented tokenizer that reports "name:line: reason".
class LineReader {
 public:
  LineReader(std::istream& in, std::string name) : in_(in), name_(std::move(name)) {}

  /// Next non-empty, non-comment line split into a token stream; false at end of file.
  bool next() {
    std::string line;
    while (std::getline(in_, line)) {
      ++line_no_;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const auto first = line.find_first_not_of(" \t");
      if (first == std::string::npos || line[first] == '#') continue;
      tokens_.clear();
      tokens_.str(line);
      tokens_.imbue(std::locale::classic());
      return true;
    }
    return false;
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error(name_ + ":" + std::to_string(line_no_) + ": " + why);
  }
  void expect_more() {
    if (!next()) fail("unexpected end of file (missing 'end' line?)");
  }
  std::string word(const char* what) {
    std::string w;
    if (!(tokens_ >> w)) fail(std::string("missing ") + what);
    return w;
  }
  void keyword(const char* kw) {
    const std::string w = word(kw);
    if (w != kw) fail(std::string("expected '") + kw + "', found '" + w + "'");
  }
  double number(const char* what, double lo, double hi) {
    const std::string w = word(what);
    std::istringstream s(w);
    s.imbue(std::locale::classic());
    double v = 0.0;
    s >> v;
    if (s.fail() || !s.eof() || !std::isfinite(v) || v < lo || v > hi) {
      fail(std::string("bad ") + what + " '" + w + "' (expected a number in [" + fmt(lo) + ", " +
           fmt(hi) + "])");
    }
    return v;
  }
  std::int64_t integer(const char* what, std::int64_t lo, std::int64_t hi) {
    const std::string w = word(what);
    std::size_t used = 0;
    long long v = 0;
    try {
      v = std::stoll(w, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != w.size() || v < lo || v > hi) {
      fail(std::string("bad ") + what + " '" + w + "' (expected an integer in [" +
           std::to_string(lo) + ", " + std::to_string(hi) + "])");
    }
    return v;
  }
  void end_of_line() {
    std::string extra;
    if (tokens_ >> extra) fail("unexpected trailing text '" + extra + "'");
  }

 private:
  static std::string fmt(double v) {
    std::ostringstream s;
    s.imbue(std::locale::classic());
    s << v;
    return s.str();
  }
  std::istream& in_;
  std::string name_;
  std::istringstream tokens_;
  std::int64_t line_no_ = 0;
};

Eigen::Vector2d read_point(LineReader& r) {
  const double e = r.number("east_m", -kMaxCoord_m, kMaxCoord_m);
  const double n = r.number("north_m", -kMaxCoord_m, kMaxCoord_m);
  return {e, n};
}

}  // namespace

WalkGraph WalkGraph::load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open walkway graph");
  return parse(in, path);
}

WalkGraph WalkGraph::parse(std::istream& in, const std::string& name) {
  LineReader r(in, name);
  if (!r.next()) r.fail("empty file, expected 'pdnav-graph 1'");
  r.keyword("pdnav-graph");
  if (r.integer("format version", 0, 1000) != 1) r.fail("unsupported format version (this reader knows 1)");
  r.end_of_line();

  r.expect_more();
  r.keyword("origin");
  const double lat = r.number("origin latitude", -90.0, 90.0);
  const double lon = r.number("origin longitude", -180.0, 180.0);
  const double h = r.number("origin height", -1.0e4, 1.0e5);
  r.end_of_line();

  r.expect_more();
  r.keyword("vertices");
  const auto nv = r.integer("vertex count", 0, kMaxCount);
  r.end_of_line();
  std::vector<Eigen::Vector2d> vertices;
  vertices.reserve(static_cast<std::size_t>(std::min<std::int64_t>(nv, 1 << 20)));
  for (std::int64_t i = 0; i < nv; ++i) {
    r.expect_more();
    r.keyword("v");
    if (r.integer("vertex id", 0, kMaxCount) != i) r.fail("vertex ids must be 0, 1, 2, ... in order");
    vertices.push_back(read_point(r));
    r.end_of_line();
  }

  r.expect_more();
  r.keyword("edges");
  const auto ne = r.integer("edge count", 0, kMaxCount);
  r.end_of_line();
  std::vector<Edge> edges;
  edges.reserve(static_cast<std::size_t>(std::min<std::int64_t>(ne, 1 << 20)));
  for (std::int64_t i = 0; i < ne; ++i) {
    r.expect_more();
    r.keyword("e");
    if (r.integer("edge id", 0, kMaxCount) != i) r.fail("edge ids must be 0, 1, 2, ... in order");
    Edge e;
    e.from = static_cast<std::int32_t>(r.integer("from vertex", 0, nv - 1));
    e.to = static_cast<std::int32_t>(r.integer("to vertex", 0, nv - 1));
    e.highway = r.word("highway class");
    e.way_id = r.integer("way id", 0, std::numeric_limits<std::int64_t>::max());
    const auto k = r.integer("shape point count", 0, kMaxCount);
    for (std::int64_t j = 0; j < k; ++j) e.shape_en_m.push_back(read_point(r));
    r.end_of_line();
    edges.push_back(std::move(e));
  }
  r.expect_more();
  r.keyword("end");
  r.end_of_line();
  if (r.next()) r.fail("text after the 'end' line");
  return build(geo::Geodetic::from_deg(lat, lon, h), std::move(vertices), std::move(edges));
}

WalkGraph WalkGraph::build(const geo::Geodetic& origin, std::vector<Eigen::Vector2d> vertices,
                           std::vector<Edge> edges) {
  WalkGraph g;
  g.frame_ = geo::LocalFrame(origin);
  g.vertex_count_ = vertices.size();
  g.nodes_ = std::move(vertices);
  for (const auto& p : g.nodes_) {
    if (!p.allFinite() || p.cwiseAbs().maxCoeff() > kMaxCoord_m) {
      throw std::invalid_argument("walkway graph: vertex not finite or beyond 1000 km of the origin");
    }
  }
  for (const auto& e : edges) {
    const auto nv = static_cast<std::int32_t>(g.vertex_count_);
    if (e.from < 0 || e.to < 0 || e.from >= nv || e.to >= nv) {
      throw std::invalid_argument("walkway graph: edge vertex index out of range");
    }
  }
  g.edges_ = std::move(edges);
  g.finish();
  return g;
}

void WalkGraph::finish() {
  out_.assign(nodes_.size(), {});
  for (std::size_t ei = 0; ei < edges_.size(); ++ei) {
    const Edge& e = edges_[ei];
    std::int32_t prev_node = e.from;
    std::int32_t prev_fwd = -1;  // forward segment of the previous piece of this edge
    auto add_piece = [&](std::int32_t a, std::int32_t b) {
      const Eigen::Vector2d d = nodes_[b] - nodes_[a];
      const double len = d.norm();
      if (!(len > 1e-3)) {
        ++skipped_;
        return;
      }
      const auto id = static_cast<std::int32_t>(segments_.size());
      Segment f;
      f.from = a; f.to = b; f.edge = static_cast<std::int32_t>(ei);
      f.a_en_m = nodes_[a]; f.b_en_m = nodes_[b];
      f.dir = d / len; f.length_m = len;
      f.heading_rad = wrap_two_pi(std::atan2(d.x(), d.y()));
      Segment r = f;
      std::swap(r.from, r.to);
      std::swap(r.a_en_m, r.b_en_m);
      r.dir = -f.dir;
      r.heading_rad = wrap_two_pi(f.heading_rad + kPi);
      segments_.push_back(f);
      segments_.push_back(r);
      out_[a].push_back(id);
      out_[b].push_back(id + 1);
      if (prev_fwd >= 0 && !is_vertex(a)) {  // chain through a shape point
        segments_[prev_fwd].next_in_edge = id;
        segments_[id].prev_in_edge = prev_fwd;
        segments_[id + 1].next_in_edge = prev_fwd + 1;
        segments_[prev_fwd + 1].prev_in_edge = id + 1;
      }
      prev_fwd = id;
      total_length_m_ += len;
    };
    // Interior points that duplicate their predecessor or the end vertex add nothing.
    std::vector<Eigen::Vector2d> shape;
    for (const auto& p : e.shape_en_m) {
      if (!p.allFinite() || p.cwiseAbs().maxCoeff() > kMaxCoord_m) {
        throw std::invalid_argument("walkway graph: shape point not finite or beyond 1000 km of the origin");
      }
      const Eigen::Vector2d& last = shape.empty() ? nodes_[e.from] : shape.back();
      if ((p - last).norm() <= 1e-3) {
        ++skipped_;
        continue;
      }
      shape.push_back(p);
    }
    while (!shape.empty() && (shape.back() - nodes_[e.to]).norm() <= 1e-3) {
      shape.pop_back();
      ++skipped_;
    }
    for (const auto& p : shape) {
      nodes_.push_back(p);
      out_.emplace_back();
      const auto n = static_cast<std::int32_t>(nodes_.size() - 1);
      add_piece(prev_node, n);
      prev_node = n;
    }
    add_piece(prev_node, e.to);
  }
  // Spatial grid over undirected pieces: cells of sample points every cell/4 along each
  // piece (a long diagonal piece costs its length, not its bounding box). Queries widen
  // their box by cell/8, the farthest a piece point lies from its nearest sample.
  grid_.clear();
  const double step = 0.25 * cell_m_;
  for (std::size_t s = 0; s < segments_.size(); s += 2) {
    const Segment& sg = segments_[s];
    const auto n = static_cast<std::int64_t>(std::ceil(sg.length_m / step));
    for (std::int64_t i = 0; i <= n; ++i) {
      const Eigen::Vector2d q = sg.a_en_m + std::min(sg.length_m, static_cast<double>(i) * step) * sg.dir;
      grid_.emplace_back(cell_key(static_cast<std::int64_t>(std::floor(q.x() / cell_m_)),
                                  static_cast<std::int64_t>(std::floor(q.y() / cell_m_))),
                         static_cast<std::int32_t>(s / 2));
    }
  }
  std::sort(grid_.begin(), grid_.end());
  grid_.erase(std::unique(grid_.begin(), grid_.end()), grid_.end());
}

std::int64_t WalkGraph::cell_key(std::int64_t cx, std::int64_t cy) const {
  return (cx + (1 << 20)) * (std::int64_t{1} << 22) + (cy + (1 << 20));
}

double WalkGraph::project(const Segment& s, const Eigen::Vector2d& p, Eigen::Vector2d* closest) {
  const double t = std::clamp((p - s.a_en_m).dot(s.dir), 0.0, s.length_m);
  if (closest) *closest = s.a_en_m + t * s.dir;
  return t;
}

std::vector<std::int32_t> WalkGraph::segments_near(const Eigen::Vector2d& p, double radius_m) const {
  std::vector<std::int32_t> pieces;
  if (!p.allFinite() || !(radius_m >= 0.0)) return pieces;
  if (p.cwiseAbs().maxCoeff() > 2.0 * kMaxCoord_m) return pieces;
  const double r = std::min(radius_m, 1.0e4);
  const double box = r + 0.125 * cell_m_;
  const auto x0 = static_cast<std::int64_t>(std::floor((p.x() - box) / cell_m_));
  const auto x1 = static_cast<std::int64_t>(std::floor((p.x() + box) / cell_m_));
  const auto y0 = static_cast<std::int64_t>(std::floor((p.y() - box) / cell_m_));
  const auto y1 = static_cast<std::int64_t>(std::floor((p.y() + box) / cell_m_));
  for (auto cx = x0; cx <= x1; ++cx) {
    auto lo = std::lower_bound(grid_.begin(), grid_.end(), std::make_pair(cell_key(cx, y0), std::int32_t{-1}));
    const auto hi_key = cell_key(cx, y1);
    for (; lo != grid_.end() && lo->first <= hi_key; ++lo) pieces.push_back(lo->second);
  }
  std::sort(pieces.begin(), pieces.end());
  pieces.erase(std::unique(pieces.begin(), pieces.end()), pieces.end());
  std::vector<std::int32_t> out;
  for (const auto piece : pieces) {
    const Segment& s = segments_[2 * piece];
    Eigen::Vector2d c;
    project(s, p, &c);
    if ((c - p).norm() <= r) {
      out.push_back(2 * piece);
      out.push_back(2 * piece + 1);
    }
  }
  return out;
}

}  // namespace pdnav::route
