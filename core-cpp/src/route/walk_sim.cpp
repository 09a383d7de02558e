#include "pdnav/route/walk_sim.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace pdnav::route {
namespace {

/// A path on the graph with cumulative distances, for truth lookup.
struct Path {
  std::vector<std::int32_t> segs;
  std::vector<double> start_m;  // distance at the start of each segment
  std::vector<double> side_m;   // walker's offset to the left of the centreline
  double length_m = 0.0;
};

Path random_path(const WalkGraph& g, double target_m, std::mt19937_64& rng) {
  Path p;
  std::uniform_int_distribution<std::size_t> pick_seg(0, g.segment_count() - 1);
  auto seg = static_cast<std::int32_t>(pick_seg(rng));
  while (p.length_m < target_m) {
    p.segs.push_back(seg);
    p.start_m.push_back(p.length_m);
    p.length_m += g.segment(seg).length_m;
    std::vector<std::int32_t> next;
    for (const auto o : g.out_segments(g.segment(seg).to)) {
      if (o != WalkGraph::reverse(seg)) next.push_back(o);
    }
    if (next.empty()) break;  // dead end: the caller rejects short paths
    seg = next[std::uniform_int_distribution<std::size_t>(0, next.size() - 1)(rng)];
  }
  return p;
}

Eigen::Vector2d point_at(const WalkGraph& g, const Path& p, double s, double* heading) {
  const auto it = std::upper_bound(p.start_m.begin(), p.start_m.end(), s);
  const std::size_t k = it == p.start_m.begin() ? 0 : static_cast<std::size_t>(it - p.start_m.begin() - 1);
  const auto& seg = g.segment(p.segs[k]);
  if (heading) *heading = seg.heading_rad;
  const Eigen::Vector2d left(-seg.dir.y(), seg.dir.x());
  const double side = p.side_m.empty() ? 0.0 : p.side_m[k];
  return seg.a_en_m + std::clamp(s - p.start_m[k], 0.0, seg.length_m) * seg.dir + side * left;
}

struct DetectedTurn {
  double first_m = 0.0;  // distance of the first bend of the cluster
  double last_m = 0.0;   // distance of the last bend
  double angle_rad = 0.0;
};

/// Windowed gyro turn detector on the true path: bends within turn_window_m of the first
/// one add up; the measured sum (with noise) must reach the threshold.
std::vector<DetectedTurn> detect_turns(const WalkGraph& g, const Path& p, const WalkSimOptions& o,
                                       std::mt19937_64& rng, int* missed) {
  std::normal_distribution<double> noise(0.0, o.turn_angle_sd_rad);
  std::vector<double> at, bend;
  for (std::size_t k = 0; k + 1 < p.segs.size(); ++k) {
    at.push_back(p.start_m[k + 1]);
    bend.push_back(wrap_pi(g.segment(p.segs[k]).heading_rad - g.segment(p.segs[k + 1]).heading_rad));
  }
  std::vector<DetectedTurn> out;
  std::size_t i = 0;
  while (i < at.size()) {
    double sum = bend[i];
    std::size_t j = i + 1;
    while (j < at.size() && at[j] - at[i] <= o.turn_window_m) sum += bend[j++];
    const double measured = sum + noise(rng);
    if (std::abs(measured) >= o.turn_threshold_rad) {
      out.push_back({at[i], at[j - 1], measured});
      i = j;
    } else {
      if (std::abs(sum) >= o.turn_threshold_rad) ++*missed;
      ++i;
    }
  }
  return out;
}

}  // namespace

SimWalk simulate_walk(const WalkGraph& g, const WalkSimOptions& o, std::uint64_t seed) {
  if (g.segment_count() == 0) throw std::runtime_error("simulate_walk: empty walkway graph");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Path path;
  std::vector<DetectedTurn> turns;
  int missed = 0;
  for (int attempt = 0;; ++attempt) {
    if (attempt >= o.max_attempts) {
      throw std::runtime_error("simulate_walk: no walk with " + std::to_string(o.min_turns) +
                               " turns found in " + std::to_string(o.max_attempts) + " attempts");
    }
    const double target = o.min_length_m + (o.max_length_m - o.min_length_m) * unit(rng);
    path = random_path(g, target, rng);
    if (path.length_m < 0.9 * target) continue;
    // Pedestrians walk beside the mapped centreline (sidewalk side, held along an edge).
    std::normal_distribution<double> side(0.0, o.lateral_offset_sd_m);
    double edge_side = 0.0;
    for (std::size_t k = 0; k < path.segs.size(); ++k) {
      if (k == 0 || g.segment(path.segs[k]).edge != g.segment(path.segs[k - 1]).edge) edge_side = side(rng);
      path.side_m.push_back(edge_side);
    }
    missed = 0;
    turns = detect_turns(g, path, o, rng, &missed);
    // Keep turns that happen after the first few steps and before the end of the walk.
    if (static_cast<int>(turns.size()) >= o.min_turns) break;
  }

  SimWalk w;
  w.path = path.segs;
  w.length_m = path.length_m;
  w.bends_missed = missed;
  const double mean_step = o.step_length_min_m + (o.step_length_max_m - o.step_length_min_m) * unit(rng);
  const double scale = 1.0 + o.step_scale_error * (2.0 * unit(rng) - 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double heading_bias = o.heading_bias_sd_rad * gauss(rng);
  const double gnss_axis_sd = o.gnss_error_m / std::sqrt(2.0);
  const auto frame = g.frame();

  auto make_fix = [&](TimeNs t, const Eigen::Vector2d& truth) {
    const Eigen::Vector2d p = truth + gnss_axis_sd * Eigen::Vector2d(gauss(rng), gauss(rng));
    const geo::Geodetic geod = frame.to_geodetic(geo::Enu(p.x(), p.y(), 0.0));
    PositionFix f;
    f.t_ns = t;
    f.lat_deg = geod.lat_deg();
    f.lon_deg = geod.lon_deg();
    f.h_m = geod.h_m;
    f.horizontal_sigma_m = o.gnss_error_m;
    w.events.emplace_back(f);
    w.truth_en_m.push_back(truth);
  };

  TimeNs t = 1 * kNsPerS;
  double s = 0.0;
  double heading = 0.0;
  make_fix(t, point_at(g, path, 0.0, &heading));
  double next_fix_s = ns_to_s(t) + o.gnss_min_interval_s + (o.gnss_max_interval_s - o.gnss_min_interval_s) * unit(rng);
  std::vector<std::pair<TimeNs, double>> step_log;  // (t, s) after each step
  std::size_t next_turn = 0;
  for (;;) {
    const double true_len = std::max(0.2, mean_step + o.step_length_sd_m * gauss(rng));
    if (s + true_len > path.length_m) break;
    s += true_len;
    t += s_to_ns(o.step_period_s * (0.95 + 0.1 * unit(rng)));
    const Eigen::Vector2d truth = point_at(g, path, s, &heading);
    PdrStep st;
    st.t_ns = t;
    st.length_m = true_len * scale * (1.0 + o.step_noise * gauss(rng));
    st.heading_rad = wrap_two_pi(heading + heading_bias + o.heading_noise_sd_rad * gauss(rng));
    st.heading_sigma_rad = std::hypot(o.heading_bias_sd_rad, o.heading_noise_sd_rad);
    st.length_sigma_m = std::abs(st.length_m) * std::hypot(o.step_scale_error, o.step_noise);
    w.events.emplace_back(st);
    w.truth_en_m.push_back(truth);
    step_log.emplace_back(t, s);
    // The detector reports a turn once the walker is half a window past its last bend;
    // it began half a window before the first bend.
    while (next_turn < turns.size() && s >= turns[next_turn].last_m + 0.5 * o.turn_window_m) {
      const DetectedTurn& dt = turns[next_turn++];
      PdrTurn tr;
      tr.t_ns = t;
      tr.start_ns = t;
      for (const auto& [ts, ss] : step_log) {
        if (ss >= dt.first_m - 0.5 * o.turn_window_m) {
          tr.start_ns = ts;
          break;
        }
      }
      tr.angle_rad = dt.angle_rad;
      w.events.emplace_back(tr);
      w.truth_en_m.push_back(truth);
      ++w.turns;
    }
    if (ns_to_s(t) >= next_fix_s) {
      make_fix(t, truth);
      next_fix_s = ns_to_s(t) + o.gnss_min_interval_s + (o.gnss_max_interval_s - o.gnss_min_interval_s) * unit(rng);
    }
  }
  return w;
}

WalkScore score_walk(std::shared_ptr<const WalkGraph> graph, const RouteOptions& options, const SimWalk& walk) {
  RouteEngine engine(options, graph, 1);
  WalkScore sc;
  for (std::size_t i = 0; i < walk.events.size(); ++i) {
    const Eigen::Vector2d& truth = walk.truth_en_m[i];
    std::visit([&](const auto& ev) { engine.feed(ev); }, walk.events[i]);
    sc.max_routes = std::max(sc.max_routes, engine.route_count());
    const Estimate e = engine.estimate();
    const double err = (e.en_m - truth).norm();
    if (const auto* f = std::get_if<PositionFix>(&walk.events[i])) {
      const geo::Enu p = graph->frame().to_enu(geo::Geodetic::from_deg(f->lat_deg, f->lon_deg, 0.0));
      sc.gnss_errors_m.push_back((Eigen::Vector2d(p.e_m(), p.n_m()) - truth).norm());
    } else if (std::holds_alternative<PdrTurn>(walk.events[i])) {
      sc.turn_errors_m.push_back(err);
    } else {
      sc.step_errors_m.push_back(err);
      if (e.status == EstimateStatus::kLost) ++sc.lost_steps;
      if (e.status == EstimateStatus::kAmbiguous) ++sc.ambiguous_steps;
      if (engine.needs_fix()) ++sc.fix_request_steps;
    }
  }
  sc.restarts = engine.restarts();
  sc.local_restarts = engine.local_restarts();
  return sc;
}

double quantile(std::vector<double> v, double p) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const double x = std::clamp(p, 0.0, 1.0) * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(std::floor(x));
  const std::size_t j = std::min(i + 1, v.size() - 1);
  return v[i] + (x - static_cast<double>(i)) * (v[j] - v[i]);
}

}  // namespace pdnav::route
