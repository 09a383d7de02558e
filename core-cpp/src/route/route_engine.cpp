#include "pdnav/route/route_engine.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace pdnav::route {
namespace {

constexpr double kStuckSigma_m = 5.0;       // ranking: overshoot past a segment end
constexpr double kSnapSigmaFloor_m = 2.0;   // ranking: snap distance at a matched turn
constexpr double kStepScaleSigma = 0.05;    // ranking: step length error grows snap sigma
constexpr double kTurnAngleSigma_rad = 10.0 * kDegToRad;  // ranking: turn angle residual
constexpr int kAheadDepth = 8;              // shallow continuations searched for a turn node
constexpr std::size_t kMaxClusters = 64;
constexpr TimeNs kStepMemory_ns = 30 * kNsPerS;

}  // namespace

RouteEngine::RouteEngine(const RouteOptions& options, std::shared_ptr<const WalkGraph> graph,
                         std::uint64_t seed)
    : opt_(options), graph_(std::move(graph)) {
  (void)seed;
  if (!graph_) throw std::invalid_argument("RouteEngine: null walkway graph");
  if (!(opt_.distance_tolerance_m > 0) || !(opt_.angle_tolerance_rad > 0) ||
      !(opt_.init_spacing_m > 0) || !(opt_.merge_spacing_m > 0) || opt_.max_routes == 0) {
    throw std::invalid_argument("RouteEngine: tolerances, spacings and max_routes must be > 0");
  }
  const std::size_t n = graph_->segment_count();
  tail_bend_.resize(n);
  for (std::size_t s = 0; s < n; ++s) tail_bend_[s] = tail_bend(static_cast<std::int32_t>(s));
}

double RouteEngine::bend_rad(std::int32_t in_seg, std::int32_t out_seg) const {
  return wrap_pi(graph_->segment(in_seg).heading_rad - graph_->segment(out_seg).heading_rad);
}

// Heading change (left positive) at the shape points of the same edge within turn_window_m
// after the start of `seg`: what a windowed gyro detector adds to the bend at its start.
double RouteEngine::tail_bend(std::int32_t seg) const {
  const WalkGraph& g = *graph_;
  double dist = g.segment(seg).length_m;
  double sum = 0.0;
  std::int32_t cur = seg;
  for (int guard = 0; dist <= opt_.turn_window_m && guard < 64; ++guard) {
    const std::int32_t nxt = g.segment(cur).next_in_edge;
    if (nxt < 0) break;
    sum += bend_rad(cur, nxt);
    dist += g.segment(nxt).length_m;
    cur = nxt;
  }
  return sum;
}

// The turn a windowed detector reports when the walker goes in_seg -> out_seg: the bend at
// the node plus the bends that follow within the window (not wrapped: hairpins exceed pi).
double RouteEngine::map_turn_rad(std::int32_t in_seg, std::int32_t out_seg) const {
  if (out_seg == WalkGraph::reverse(in_seg)) return kPi;
  return bend_rad(in_seg, out_seg) + tail_bend_[out_seg];
}

bool RouteEngine::is_shallow(std::int32_t in_seg, std::int32_t out_seg) const {
  if (out_seg == WalkGraph::reverse(in_seg)) return false;
  return std::abs(bend_rad(in_seg, out_seg)) <= opt_.shallow_turn_max_rad ||
         std::abs(map_turn_rad(in_seg, out_seg)) <= opt_.shallow_turn_max_rad;
}

Eigen::Vector2d RouteEngine::position(const Route& r) const {
  const auto& s = graph_->segment(r.seg);
  return s.a_en_m + std::min(r.offset_m, s.length_m) * s.dir;
}

double RouteEngine::rank(const Route& r) {
  return r.log_w - 0.5 * (r.stuck_m / kStuckSigma_m) * (r.stuck_m / kStuckSigma_m);
}

void RouteEngine::remember(Route& r, std::int32_t node, std::int32_t in_seg, double odo_m) {
  if (r.n_passed == r.passed.size()) {
    std::rotate(r.passed.begin(), r.passed.begin() + 1, r.passed.end());
    r.n_passed = static_cast<std::uint8_t>(r.passed.size() - 1);
  }
  r.passed[r.n_passed++] = Passed{node, in_seg, odo_m};
}

// APT Sec. VI, initial routes: every point of every segment within the fix radius, both
// walking directions, spaced init_spacing_m.
void RouteEngine::initialise(const Eigen::Vector2d& p, double sigma_m, double radius_m) {
  routes_.clear();
  truncated_ = false;
  const WalkGraph& g = *graph_;
  for (const auto s : g.segments_near(p, radius_m)) {
    const auto& seg = g.segment(s);
    const auto n = static_cast<int>(std::floor(seg.length_m / opt_.init_spacing_m));
    for (int i = 0; i <= n; ++i) {
      const double off = std::min(seg.length_m, (i + 0.5) * opt_.init_spacing_m);
      const Eigen::Vector2d q = seg.a_en_m + off * seg.dir;
      const double d = (q - p).norm();
      if (d > radius_m) continue;
      Route r;
      r.seg = s;
      r.offset_m = off;
      r.log_w = -0.5 * (d / sigma_m) * (d / sigma_m);
      routes_.push_back(r);
    }
  }
  initialised_ = true;
  last_en_m_ = p;
  last_cov_ = Eigen::Matrix2d::Identity() * radius_m * radius_m;
  merge_and_bound();
  update_clusters();
}

// APT Sec. VI, new step: advance towards the segment end; at the end branch into every
// continuation within shallow_turn_max_rad; with none, the overshoot eats the tolerance.
void RouteEngine::advance(Route r, double d_m, std::vector<Route>& out) const {
  const WalkGraph& g = *graph_;
  r.offset_m += d_m;
  r.odo_m += d_m;
  r.since_snap_m += d_m;
  std::vector<Route> work{r};
  while (!work.empty()) {
    Route cur = work.back();
    work.pop_back();
    for (;;) {
      const auto& seg = g.segment(cur.seg);
      if (cur.offset_m <= seg.length_m) {
        out.push_back(cur);
        break;
      }
      const double excess = cur.offset_m - seg.length_m;
      std::int32_t first = -1;
      // Bends of the same edge inside the window of a just-matched turn are part of it.
      const bool in_turn = seg.next_in_edge >= 0 && cur.odo_m - excess <= cur.turn_free_until_m;
      for (const auto o : g.out_segments(seg.to)) {
        if (!is_shallow(cur.seg, o) && !(in_turn && o == seg.next_in_edge)) continue;
        if (first < 0) {
          first = o;
          continue;
        }
        Route b = cur;
        remember(b, seg.to, cur.seg, cur.odo_m - excess);
        b.seg = o;
        b.offset_m = excess;
        work.push_back(b);
      }
      if (first < 0) {  // dead end or only sharp turns: wait for the turn, lose tolerance
        cur.stuck_m += excess;
        cur.offset_m = seg.length_m;
        if (cur.stuck_m <= opt_.distance_tolerance_m) out.push_back(cur);
        break;
      }
      remember(cur, seg.to, cur.seg, cur.odo_m - excess);
      cur.seg = first;
      cur.offset_m = excess;
    }
  }
}

void RouteEngine::feed(const PdrStep& step) {
  if (!std::isfinite(step.length_m) || step.length_m <= 0.0 || step.length_m > 5.0 ||
      !std::isfinite(step.heading_rad)) {
    return;  // not a usable step
  }
  last_t_ns_ = std::max(last_t_ns_, step.t_ns);
  recent_steps_.emplace_back(step.t_ns, step.length_m);
  while (!recent_steps_.empty() && recent_steps_.front().first < step.t_ns - kStepMemory_ns) {
    recent_steps_.pop_front();
  }
  if (!initialised_) return;
  if (routes_.empty()) {  // lost: dead reckoning, and a local restart every lost_retry_m walked
    last_en_m_ += step.length_m * Eigen::Vector2d(std::sin(step.heading_rad), std::cos(step.heading_rad));
    last_cov_ += Eigen::Matrix2d::Identity() * (0.1 * step.length_m) * (0.1 * step.length_m);
    lost_walked_m_ += step.length_m;
    if (opt_.lost_retry_m > 0.0 && lost_walked_m_ >= opt_.lost_retry_m) {
      lost_walked_m_ = 0.0;
      const Eigen::Matrix2d cov = last_cov_;
      if (!local_restart()) last_cov_ = cov;  // nothing within reach: keep the dead-reckoning sigma
    }
    return;
  }
  lost_walked_m_ = 0.0;
  std::vector<Route> next;
  next.reserve(routes_.size() + 16);
  for (const auto& r : routes_) advance(r, step.length_m, next);
  if (opt_.use_step_heading) {
    const double sigma = (std::isfinite(step.heading_sigma_rad) && step.heading_sigma_rad > 0)
                             ? step.heading_sigma_rad : opt_.default_heading_sigma_rad;
    for (auto& r : next) {
      const double res = wrap_pi(step.heading_rad - graph_->segment(r.seg).heading_rad) / sigma;
      r.log_w = opt_.heading_memory * r.log_w - 0.5 * std::min(res * res, 9.0);
    }
  }
  routes_.swap(next);
  if (routes_.empty()) {
    last_en_m_ += step.length_m * Eigen::Vector2d(std::sin(step.heading_rad), std::cos(step.heading_rad));
    local_restart();
    return;
  }
  merge_and_bound();
  update_clusters();
}

// Deviation from APT (which waits for the next fix): when every route has died, restart
// around the last estimate with local_restart_radius_m; GNSS fixes are minutes apart.
bool RouteEngine::local_restart() {
  if (!(opt_.local_restart_radius_m > 0.0)) return false;
  initialise(last_en_m_, opt_.local_restart_radius_m / opt_.init_radius_sigmas, opt_.local_restart_radius_m);
  if (!routes_.empty()) ++local_restarts_;  // an attempt with no way within reach is not a restart
  return !routes_.empty();
}

// APT Sec. VI, new turn: a route survives only through a node within the distance
// tolerance (ahead along shallow continuations, or already passed) whose map turn angle
// matches the reported one within the angle tolerance. It snaps to that node.
void RouteEngine::branch_at(const Route& r, std::int32_t node, std::int32_t in_seg, double turn_rad,
                            double d_after_m, double snap_m, double along_m, std::vector<Route>& out) const {
  const double snap_sigma = std::hypot(kSnapSigmaFloor_m, kStepScaleSigma * r.since_snap_m);
  // since the previous matched turn the route has moved along the graph with the steps, so the
  // path from that turn's node to this one is (odometer since) + along_m (ahead +, passed -);
  // the steps made that distance up to the middle of this turn
  double path_m = -1.0, steps_m = 0.0;
  if (r.snap_odo_m >= 0.0 && r.stuck_m <= 0.0) {
    path_m = r.odo_m - r.snap_odo_m + along_m;
    steps_m = r.odo_m - d_after_m - r.snap_odo_m;
  }
  for (const auto o : graph_->out_segments(node)) {
    const double diff = std::abs(wrap_pi(map_turn_rad(in_seg, o) - turn_rad));
    if (diff > opt_.angle_tolerance_rad) continue;
    Route n;
    n.seg = o;
    n.odo_m = r.odo_m - d_after_m;
    n.turn_free_until_m = n.odo_m + opt_.turn_window_m;
    n.snap_odo_m = n.odo_m;
    n.sample_path_m = path_m;
    n.sample_steps_m = steps_m;
    n.log_w = r.log_w - 0.5 * (diff / kTurnAngleSigma_rad) * (diff / kTurnAngleSigma_rad) -
              0.5 * (snap_m / snap_sigma) * (snap_m / snap_sigma);
    advance(n, d_after_m, out);
  }
}

void RouteEngine::turn_candidates_ahead(const Route& r, double turn_rad, double d_after_m,
                                        std::vector<Route>& out) const {
  const WalkGraph& g = *graph_;
  struct Item { std::int32_t in_seg; double dist_m; int depth; };
  const auto& s0 = g.segment(r.seg);
  const double d0 = r.stuck_m > 0.0 ? r.stuck_m : s0.length_m - r.offset_m;
  std::vector<Item> work{{r.seg, d0, 0}};
  while (!work.empty()) {
    const Item it = work.back();
    work.pop_back();
    if (it.dist_m > opt_.distance_tolerance_m) continue;
    const auto& s = g.segment(it.in_seg);
    branch_at(r, s.to, it.in_seg, turn_rad, d_after_m, it.dist_m, it.dist_m, out);
    if (it.depth >= kAheadDepth) continue;
    for (const auto o : g.out_segments(s.to)) {
      if (!is_shallow(it.in_seg, o)) continue;
      work.push_back({o, it.dist_m + g.segment(o).length_m, it.depth + 1});
    }
  }
}

void RouteEngine::feed(const PdrTurn& turn) {
  if (!std::isfinite(turn.angle_rad) || !initialised_ || routes_.empty()) return;
  if (std::abs(turn.angle_rad) < opt_.turn_threshold_rad) return;  // below the detector's threshold: not a turn
  last_t_ns_ = std::max(last_t_ns_, turn.t_ns);
  // Distance walked since the middle of the turn: the part already on the new segment.
  const TimeNs mid = turn.start_ns > 0 && turn.start_ns <= turn.t_ns ? turn.start_ns + (turn.t_ns - turn.start_ns) / 2
                                                                     : turn.t_ns;
  double d_after = 0.0;
  for (const auto& [t, len] : recent_steps_) {
    if (t > mid) d_after += len;
  }
  const double turn_rad = turn.angle_rad;
  std::vector<Route> next = apply_turn(turn_rad, d_after);
  if (next.empty() && local_restart()) {
    // Re-seeded around the last estimate: the turn just reported locates the walker.
    next = apply_turn(turn_rad, d_after);
    if (next.empty()) return;  // keep the fresh routes; the next turn or fix prunes them
  }
  routes_.swap(next);
  merge_and_bound();
  update_clusters();
  publish_scale_sample(mid);
}

// The step scale the map measured between this turn and the previous matched one: over the
// routes of the leading cluster that carry a sample, G / D with their weights; none when the
// turn left the clusters ambiguous or the sample is shorter than scale_sample_min_m.
void RouteEngine::publish_scale_sample(TimeNs t_ns) {
  if (routes_.empty() || clusters_.empty()) return;
  if (clusters_.size() > 1 && clusters_[1].weight > opt_.ambiguity_ratio * clusters_[0].weight) return;
  const double r2 = opt_.cluster_radius_m * opt_.cluster_radius_m;
  double w_all = 0.0, w_s = 0.0, wg = 0.0, wd = 0.0;
  for (const Route& r : routes_) {
    if ((position(r) - clusters_.front().mean_en_m).squaredNorm() > r2) continue;
    const double w = std::exp(rank(r));
    w_all += w;
    if (!(r.sample_path_m > 0.0) || !(r.sample_steps_m >= opt_.scale_sample_min_m)) continue;
    w_s += w;
    wg += w * r.sample_path_m;
    wd += w * r.sample_steps_m;
  }
  // most of the leading cluster must have come from a matched turn (not a fix or a restart)
  if (!(w_s > 0.5 * w_all) || !(wd > 0.0)) return;
  const double g = wg / w_s, d = wd / w_s;
  RouteScaleSample s;
  s.t_ns = t_ns;
  s.scale = g / d;
  // the two ends' along-track error and the walked path against the polyline; the steps' stated
  // length sigma is not added: it is mostly the scale error being measured, not noise of the sum
  s.sigma = std::hypot(std::sqrt(2.0) * opt_.turn_position_sigma_m / d, opt_.path_length_sigma);
  s.distance_m = d;
  scale_sample_ = s;
}

std::vector<RouteEngine::Route> RouteEngine::apply_turn(double turn_rad, double d_after) const {
  std::vector<Route> next;
  for (const auto& r : routes_) {
    for (std::uint8_t i = 0; i < r.n_passed; ++i) {
      const double back_m = r.odo_m - r.passed[i].odo_m;
      if (back_m > opt_.distance_tolerance_m) continue;
      branch_at(r, r.passed[i].node, r.passed[i].in_seg, turn_rad, d_after, back_m, -back_m, next);
    }
    turn_candidates_ahead(r, turn_rad, d_after, next);
  }
  return next;
}

// APT Sec. VI, new GNSS fix: drop routes farther than tolerance + fix radius; none left
// (or not started yet): (re)start from this fix.
void RouteEngine::feed(const PositionFix& fix) {
  if (!std::isfinite(fix.lat_deg) || !std::isfinite(fix.lon_deg) || std::abs(fix.lat_deg) > 90.0 ||
      std::abs(fix.lon_deg) > 180.0 || !std::isfinite(fix.horizontal_sigma_m) || fix.horizontal_sigma_m < 0.0) {
    return;  // unusable fix
  }
  last_t_ns_ = std::max(last_t_ns_, fix.t_ns);
  // The graph lies on the ellipsoid (h = 0); project the fix the same way.
  const geo::Enu e = graph_->frame().to_enu(geo::Geodetic::from_deg(fix.lat_deg, fix.lon_deg, 0.0));
  const Eigen::Vector2d p(e.e_m(), e.n_m());
  const double sigma = std::max(fix.horizontal_sigma_m, opt_.min_fix_sigma_m);
  const double radius = opt_.init_radius_sigmas * sigma;
  if (!routes_.empty()) {
    const double gate = opt_.distance_tolerance_m + radius;
    std::vector<Route> kept;
    for (auto r : routes_) {
      const double d = (position(r) - p).norm();
      if (d > gate) continue;
      r.log_w -= 0.5 * (d / sigma) * (d / sigma);
      kept.push_back(r);
    }
    if (!kept.empty()) {
      reseed_along_track(p, sigma, radius, kept);
      routes_.swap(kept);
      truncated_ = false;
      merge_and_bound();
      update_clusters();
      return;
    }
  }
  if (initialised_) ++restarts_;
  initialise(p, sigma, radius);
}

// Deviation from APT (which only prunes at a fix): the step length scale error lets the
// along-track position drift by ~5 % of the distance since the last snap (40 m after 800 m
// of straight road). A fix therefore also proposes the positions within its radius that
// continue a surviving route in the same direction, weighted by that route's along-track
// variance P = 1 + (0.05 d)^2 and by the fix; their along-track variance shrinks to
// P R / (P + R) as in a scalar Kalman update.
void RouteEngine::reseed_along_track(const Eigen::Vector2d& p, double sigma_m, double radius_m,
                                     std::vector<Route>& kept) const {
  const WalkGraph& g = *graph_;
  const double r_var = 0.5 * sigma_m * sigma_m;  // per-axis variance of the fix
  const std::size_t n_kept = kept.size();
  for (const auto sid : g.segments_near(p, radius_m)) {
    const auto& seg = g.segment(sid);
    const auto n = static_cast<int>(std::floor(seg.length_m / opt_.init_spacing_m));
    for (int i = 0; i <= n; ++i) {
      const double off = std::min(seg.length_m, (i + 0.5) * opt_.init_spacing_m);
      const Eigen::Vector2d q = seg.a_en_m + off * seg.dir;
      const double d_fix = (q - p).norm();
      if (d_fix > radius_m) continue;
      double best = -1e300;
      const Route* parent = nullptr;
      for (std::size_t k = 0; k < n_kept; ++k) {
        const Route& r = kept[k];
        const double p_var = 1.0 + kStepScaleSigma * kStepScaleSigma * r.since_snap_m * r.since_snap_m;
        const double d = (position(r) - q).norm();
        if (d * d > 9.0 * p_var) continue;  // beyond 3 sigma along track
        if (std::abs(wrap_pi(g.segment(r.seg).heading_rad - seg.heading_rad)) > opt_.angle_tolerance_rad) continue;
        const double lw = r.log_w - 0.5 * d * d / p_var;
        if (lw > best) {
          best = lw;
          parent = &r;
        }
      }
      if (!parent) continue;
      const double p_var = 1.0 + kStepScaleSigma * kStepScaleSigma * parent->since_snap_m * parent->since_snap_m;
      const double post_var = p_var * r_var / (p_var + r_var);
      Route c = *parent;
      c.snap_odo_m = -1.0;  // moved to the fix: its path since the last turn is not the graph's
      c.sample_path_m = -1.0;
      c.seg = sid;
      c.offset_m = off;
      c.stuck_m = 0.0;
      c.n_passed = 0;
      c.log_w = best - 0.5 * (d_fix / sigma_m) * (d_fix / sigma_m);
      c.since_snap_m = std::sqrt(std::max(0.0, post_var - 1.0)) / kStepScaleSigma;
      kept.push_back(c);
    }
  }
}

// Merge routes on the same directed segment within merge_spacing_m (keep the best), then
// bound the set to max_routes by weight.
void RouteEngine::merge_and_bound() {
  const double q = opt_.merge_spacing_m;
  auto key = [q](const Route& r) { return std::make_pair(r.seg, static_cast<std::int64_t>(std::floor(r.offset_m / q))); };
  auto better = [](const Route& a, const Route& b) {
    return rank(a) > rank(b);
  };
  std::sort(routes_.begin(), routes_.end(), [&](const Route& a, const Route& b) {
    const auto ka = key(a), kb = key(b);
    if (ka != kb) return ka < kb;
    return better(a, b);
  });
  routes_.erase(std::unique(routes_.begin(), routes_.end(),
                            [&](const Route& a, const Route& b) { return key(a) == key(b); }),
                routes_.end());
  if (routes_.size() > opt_.max_routes) {
    std::nth_element(routes_.begin(), routes_.begin() + static_cast<std::ptrdiff_t>(opt_.max_routes),
                     routes_.end(), better);
    routes_.resize(opt_.max_routes);
    truncated_ = true;
  }
  // Keep log weights bounded: shift so the best is 0.
  if (!routes_.empty()) {
    double best = -1e300;
    for (const auto& r : routes_) best = std::max(best, r.log_w);
    for (auto& r : routes_) r.log_w = std::max(r.log_w - best, -700.0);
  }
}

void RouteEngine::update_clusters() {
  clusters_.clear();
  if (routes_.empty()) return;
  std::vector<double> w(routes_.size());
  for (std::size_t i = 0; i < routes_.size(); ++i) {
    const auto& r = routes_[i];
    w[i] = std::exp(rank(r));
  }
  std::vector<std::size_t> order(routes_.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return w[a] > w[b]; });
  std::vector<Eigen::Vector2d> seeds;
  struct Acc {
    double w = 0, wxx = 0, wxy = 0, wyy = 0;
    Eigen::Vector2d wx = Eigen::Vector2d::Zero();
    Eigen::Matrix2d w_along = Eigen::Matrix2d::Zero();  // sum of w (sigma_s d)^2 u u^T
    std::size_t n = 0;
  };
  std::vector<Acc> acc;
  const double r2 = opt_.cluster_radius_m * opt_.cluster_radius_m;
  for (const auto i : order) {
    const Eigen::Vector2d p = position(routes_[i]);
    std::size_t c = 0;
    while (c < seeds.size() && (seeds[c] - p).squaredNorm() > r2) ++c;
    if (c == seeds.size()) {
      if (seeds.size() >= kMaxClusters) continue;
      seeds.push_back(p);
      acc.emplace_back();
    }
    Acc& a = acc[c];
    const Eigen::Vector2d d = p - seeds[c];  // relative to the seed for numerical stability
    a.w += w[i]; a.wx += w[i] * d; a.wxx += w[i] * d.x() * d.x(); a.wxy += w[i] * d.x() * d.y();
    a.wyy += w[i] * d.y() * d.y(); ++a.n;
    // the route's own along-track variance: a step scale error moves every route of a cluster
    // together, so their spread does not show it (with the caller's scale sigma when it gave one;
    // reseed_along_track ranks with the constant)
    const Eigen::Vector2d& u = graph_->segment(routes_[i].seg).dir;
    const double s_along = (step_scale_sigma_ > 0.0 ? step_scale_sigma_ : kStepScaleSigma) * routes_[i].since_snap_m;
    a.w_along += w[i] * s_along * s_along * u * u.transpose();
  }
  for (std::size_t c = 0; c < seeds.size(); ++c) {
    const Acc& a = acc[c];
    Cluster cl;
    cl.weight = a.w;
    cl.size = a.n;
    const Eigen::Vector2d m = a.w > 0 ? Eigen::Vector2d(a.wx / a.w) : Eigen::Vector2d::Zero();
    cl.mean_en_m = seeds[c] + m;
    if (a.w > 0) {
      cl.cov_en_m2 << a.wxx / a.w - m.x() * m.x(), a.wxy / a.w - m.x() * m.y(),
                      a.wxy / a.w - m.x() * m.y(), a.wyy / a.w - m.y() * m.y();
      cl.cov_en_m2 += a.w_along / a.w;
    }
    clusters_.push_back(cl);
  }
  std::sort(clusters_.begin(), clusters_.end(), [](const Cluster& a, const Cluster& b) { return a.weight > b.weight; });
  last_en_m_ = clusters_.front().mean_en_m;
  last_cov_ = clusters_.front().reported_cov_en_m2();
}

Estimate RouteEngine::estimate() const {
  Estimate e;
  e.t_ns = last_t_ns_;
  e.engine = EngineKind::kRoute;
  if (!initialised_) {
    e.status = EstimateStatus::kNotInitialized;
    e.reason = "waiting for a position fix";
    return e;
  }
  e.en_m = last_en_m_;
  e.cov_en_m2 = last_cov_;
  e.position = graph_->frame().to_geodetic(geo::Enu(last_en_m_.x(), last_en_m_.y(), 0.0));
  if (routes_.empty()) {
    e.status = EstimateStatus::kLost;
    e.reason = "no route fits the steps and turns; dead reckoning until the next fix";
    return e;
  }
  const bool ambiguous = clusters_.size() > 1 && clusters_[1].weight > opt_.ambiguity_ratio * clusters_[0].weight;
  e.status = ambiguous ? EstimateStatus::kAmbiguous : EstimateStatus::kOk;
  e.reason = std::to_string(routes_.size()) + " routes in " + std::to_string(clusters_.size()) + " clusters";
  return e;
}

std::vector<std::pair<Estimate, double>> RouteEngine::cluster_estimates() const {
  std::vector<std::pair<Estimate, double>> out;
  const Estimate best = estimate();
  if (routes_.empty() || clusters_.empty() || !best.valid()) return out;
  double total = 0.0;
  for (const Cluster& c : clusters_) total += c.weight;
  for (const Cluster& c : clusters_) {
    Estimate e = best;
    e.status = EstimateStatus::kOk;
    e.en_m = c.mean_en_m;
    e.cov_en_m2 = c.reported_cov_en_m2();
    e.position = graph_->frame().to_geodetic(geo::Enu(c.mean_en_m.x(), c.mean_en_m.y(), 0.0));
    out.emplace_back(e, total > 0.0 ? c.weight / total : 0.0);
  }
  return out;
}

bool RouteEngine::needs_fix() const {
  if (!initialised_) return true;
  return routes_.empty() || truncated_ || routes_.size() > opt_.fix_request_routes ||
         clusters_.size() > opt_.fix_request_clusters;
}

std::vector<Candidate> RouteEngine::candidates(std::size_t max) const {
  std::vector<Candidate> out;
  out.reserve(routes_.size());
  double total = 0.0;
  for (const auto& r : routes_) {
    Candidate c;
    c.en_m = position(r);
    const auto& s = graph_->segment(r.seg);
    c.heading_rad = s.heading_rad;
    c.edge = s.edge;
    c.distance_error_m = r.stuck_m;
    c.weight = std::exp(rank(r));
    total += c.weight;
    out.push_back(c);
  }
  for (auto& c : out) c.weight = total > 0 ? c.weight / total : 0.0;
  std::sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) { return a.weight > b.weight; });
  if (out.size() > max) out.resize(max);
  return out;
}

}  // namespace pdnav::route
