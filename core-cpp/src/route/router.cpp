#include "pdnav/route/router.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <stdexcept>
#include <utility>

namespace pdnav::route {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kGridSearchMax_m = 1.0e4;  // WalkGraph::segments_near caps its radius here
constexpr double kFirstSearch_m = 50.0;     // first snap search radius (grows x4 up to max_snap_m)
}  // namespace

Router::Router(const RouterOptions& options, std::shared_ptr<const WalkGraph> graph)
    : opt_(options), graph_(std::move(graph)) {
  if (!graph_) throw std::invalid_argument("Router: no graph");
  if (!(opt_.max_snap_m > 0.0)) throw std::invalid_argument("Router: max_snap_m must be > 0");
  const auto n = static_cast<std::int32_t>(graph_->node_count());
  component_.assign(static_cast<std::size_t>(n), -1);
  std::vector<std::int32_t> stack;
  for (std::int32_t start = 0; start < n; ++start) {
    if (component_[start] >= 0) continue;
    const auto c = static_cast<std::int32_t>(component_size_.size());
    component_size_.push_back(0);
    component_[start] = c;
    stack.push_back(start);
    while (!stack.empty()) {
      const std::int32_t u = stack.back();
      stack.pop_back();
      ++component_size_[c];
      for (const std::int32_t s : graph_->out_segments(u)) {
        const std::int32_t v = graph_->segment(s).to;
        if (component_[v] < 0) {
          component_[v] = c;
          stack.push_back(v);
        }
      }
    }
  }
}

std::vector<GraphPoint> Router::nearest_per_component(const Eigen::Vector2d& p, double radius_m) const {
  std::vector<GraphPoint> best(component_size_.size());
  for (auto& b : best) b.snap_m = kInf;
  auto consider = [&](std::int32_t even) {
    const WalkGraph::Segment& s = graph_->segment(even);
    Eigen::Vector2d c;
    const double t = WalkGraph::project(s, p, &c);
    const double d = (c - p).norm();
    if (!(d <= radius_m)) return;
    GraphPoint& b = best[component_[s.from]];
    if (d < b.snap_m) {  // pieces come in increasing id: ties keep the lower id (deterministic)
      b.segment = even;
      b.offset_m = t;
      b.en_m = c;
      b.snap_m = d;
      b.component = component_[s.from];
    }
  };
  if (radius_m <= kGridSearchMax_m) {
    for (const std::int32_t s : graph_->segments_near(p, radius_m)) {
      if ((s & 1) == 0) consider(s);
    }
  } else {
    const auto count = static_cast<std::int32_t>(graph_->segment_count());
    for (std::int32_t s = 0; s < count; s += 2) consider(s);
  }
  return best;
}

RoutePath Router::shortest_geodetic(double from_lat_deg, double from_lon_deg, double to_lat_deg,
                                    double to_lon_deg) const {
  for (double v : {from_lat_deg, from_lon_deg, to_lat_deg, to_lon_deg}) {
    if (!std::isfinite(v)) throw std::invalid_argument("route: non-finite coordinate");
  }
  if (std::fabs(from_lat_deg) > 90.0 || std::fabs(to_lat_deg) > 90.0 || std::fabs(from_lon_deg) > 180.0 ||
      std::fabs(to_lon_deg) > 180.0) {
    throw std::invalid_argument("route: coordinates need |lat| <= 90, |lon| <= 180");
  }
  const geo::Enu a = graph_->frame().to_enu(geo::Geodetic::from_deg(from_lat_deg, from_lon_deg, 0.0));
  const geo::Enu b = graph_->frame().to_enu(geo::Geodetic::from_deg(to_lat_deg, to_lon_deg, 0.0));
  return shortest(Eigen::Vector2d(a.e_m(), a.n_m()), Eigen::Vector2d(b.e_m(), b.n_m()));
}

RoutePath Router::shortest(const Eigen::Vector2d& from_en_m, const Eigen::Vector2d& to_en_m) const {
  if (!from_en_m.allFinite() || !to_en_m.allFinite()) {
    throw std::invalid_argument("route: non-finite query point");
  }
  RoutePath out;
  // The component with the smallest snap sum, searched in growing radii: at radius r every
  // component with both snaps <= r is found exactly, and any other has a sum > r, so a best
  // sum <= r is final (the last round, r = max_snap_m, is the exhaustive one).
  std::vector<GraphPoint> fa, fb;
  std::int32_t comp = -1;
  bool any_from = false, any_to = false;
  for (double r = std::min(opt_.max_snap_m, kFirstSearch_m);; r = std::min(opt_.max_snap_m, 4.0 * r)) {
    fa = nearest_per_component(from_en_m, r);
    fb = nearest_per_component(to_en_m, r);
    comp = -1;
    double best_snaps = kInf;
    any_from = any_to = false;
    for (std::size_t c = 0; c < fa.size(); ++c) {
      any_from = any_from || std::isfinite(fa[c].snap_m);
      any_to = any_to || std::isfinite(fb[c].snap_m);
      const double sum = fa[c].snap_m + fb[c].snap_m;
      if (sum < best_snaps) {
        best_snaps = sum;
        comp = static_cast<std::int32_t>(c);
      }
    }
    if (best_snaps <= r || r >= opt_.max_snap_m) break;
  }
  const std::string within = " within " + std::to_string(static_cast<long long>(std::lround(opt_.max_snap_m))) + " m";
  if (comp < 0) {
    out.reason = !any_from ? "no walkway" + within + " of the start"
                 : !any_to ? "no walkway" + within + " of the destination"
                           : "the walkways near the start and the destination are not connected";
    return out;
  }
  const GraphPoint& a = fa[comp];
  const GraphPoint& b = fb[comp];
  out.from = a;
  out.to = b;
  out.from_snap_m = a.snap_m;
  out.to_snap_m = b.snap_m;

  const WalkGraph& g = *graph_;
  const WalkGraph::Segment& sa = g.segment(a.segment);
  const WalkGraph::Segment& sb = g.segment(b.segment);
  // Leaving the target's segment at either end node costs the rest of that segment.
  auto terminal = [&](std::int32_t node) {
    double t = kInf;
    if (node == sb.from) t = std::min(t, b.offset_m);
    if (node == sb.to) t = std::min(t, sb.length_m - b.offset_m);
    return t;
  };
  double best = kInf;
  std::int32_t best_node = -1;  // -1 with a finite best: along the shared segment directly
  if (a.segment == b.segment) best = std::fabs(a.offset_m - b.offset_m);

  const std::size_t n = g.node_count();
  std::vector<double> dist(n, kInf);
  std::vector<std::int32_t> prev(n, -1);
  std::vector<char> settled(n, 0);
  using Item = std::pair<double, std::int32_t>;  // (f = g + h, node); ties by node id
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  auto h = [&](std::int32_t node) { return (g.node_en_m(node) - b.en_m).norm(); };
  auto push = [&](std::int32_t node, double d, std::int32_t from) {
    if (d < dist[node]) {
      dist[node] = d;
      prev[node] = from;
      open.emplace(d + h(node), node);
    }
  };
  push(sa.from, a.offset_m, -1);
  push(sa.to, sa.length_m - a.offset_m, -1);
  while (!open.empty()) {
    const auto [f, u] = open.top();
    open.pop();
    if (settled[u]) continue;
    // consistent heuristic: every path through u or later nodes costs >= f
    if (f >= best) break;
    settled[u] = 1;
    ++out.settled;
    const double via = dist[u] + terminal(u);
    if (via < best) {
      best = via;
      best_node = u;
    }
    for (const std::int32_t s : g.out_segments(u)) {
      const WalkGraph::Segment& seg = g.segment(s);
      if (!settled[seg.to]) push(seg.to, dist[u] + seg.length_m, u);
    }
  }
  if (!std::isfinite(best)) {  // cannot happen inside one component; kept as a clear failure
    out.reason = "no path inside the connected walkways (internal error)";
    return out;
  }
  out.found = true;
  out.length_m = best;
  for (std::int32_t v = best_node; v >= 0; v = prev[v]) out.nodes.push_back(v);
  std::reverse(out.nodes.begin(), out.nodes.end());
  auto add_edge = [&](std::int32_t e) {
    if (out.edges.empty() || out.edges.back() != e) out.edges.push_back(e);
  };
  add_edge(sa.edge);
  for (std::size_t i = 1; i < out.nodes.size(); ++i) {
    for (const std::int32_t s : g.out_segments(out.nodes[i - 1])) {
      if (g.segment(s).to == out.nodes[i]) {
        add_edge(g.segment(s).edge);
        break;
      }
    }
  }
  add_edge(sb.edge);
  auto add = [&](const Eigen::Vector2d& q) {  // a snap onto a node repeats it: drop the repeat
    if (out.polyline_en_m.empty() || (out.polyline_en_m.back() - q).norm() > 1e-9) out.polyline_en_m.push_back(q);
  };
  add(a.en_m);
  for (const std::int32_t v : out.nodes) add(g.node_en_m(v));
  add(b.en_m);
  if (out.polyline_en_m.size() == 1) out.polyline_en_m.push_back(b.en_m);  // from == to: still a line
  return out;
}

}  // namespace pdnav::route
