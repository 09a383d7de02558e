// Route engine: APT's error-tolerant route matcher (Zhu, Li, Chen, "APT: Accurate Outdoor
// Pedestrian Tracking with Smartphones", Sec. VI). Keeps every position on the walkway
// graph that fits the steps and turns within tolerances, prunes with rare GNSS fixes and
// snaps to turn points. docs/route.md describes the algorithm and its deviations.
#pragma once
#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/estimate.h"
#include "pdnav/geo/events.h"
#include "pdnav/route/walk_graph.h"

namespace pdnav::route {

struct RouteOptions {
  double turn_threshold_rad = deg_to_rad(30.0);   // APT Sec. V-B/VI: turn detector threshold
  double angle_tolerance_rad = deg_to_rad(30.0);  // APT Sec. VI: reported vs map turn angle
  double distance_tolerance_m = 20.0;             // APT Sec. VI: along-track distance tolerance
  /// Largest bend a route follows without a reported turn: the detector threshold plus
  /// its angle noise margin (a 35 deg bend reported as 28 deg yields no PdrTurn).
  double shallow_turn_max_rad = deg_to_rad(45.0);
  /// Window over which the PDR turn detector sums heading change: a map turn is the bend
  /// at a node plus the bends of the same edge within this distance after it.
  double turn_window_m = 4.0;
  /// Every route died: re-seed within this radius of the last estimate instead of waiting
  /// minutes for the next fix (0 = APT behaviour: lost until the next fix).
  double local_restart_radius_m = 30.0;
  /// ... and while lost (no route near a fix or a re-anchoring position), retry that restart
  /// every this many metres walked (a third of the radius: no way is walked past unseen).
  double lost_retry_m = 10.0;
  double init_radius_sigmas = 2.5;   // initial routes within k * fix sigma (2.5 -> 99.8 % in 2D)
  double init_spacing_m = 2.0;       // spacing of initial route positions along each segment
  double min_fix_sigma_m = 3.0;      // floor on a fix's reported 1-sigma radius
  double merge_spacing_m = 1.0;      // routes on one segment closer than this are merged
  std::size_t max_routes = 4000;     // memory bound; the lowest-weight routes are dropped
  std::size_t fix_request_routes = 600;     // needs_fix() above this many live routes
  std::size_t fix_request_clusters = 6;     // ... or above this many position clusters
  double cluster_radius_m = 10.0;           // routes within this of a cluster seed join it
  double ambiguity_ratio = 0.3;             // 2nd cluster weight / best above this: ambiguous
  /// Step headings rank routes (never prune): residual 1-sigma when the step has none.
  bool use_step_heading = true;
  double default_heading_sigma_rad = deg_to_rad(25.0);
  double heading_memory = 0.95;      // per-step forgetting of the heading log-likelihood
  /// Step scale from the map (issue 27: step length learned where the map constrains it; APT's
  /// turn snapping gives it): between two matched turns the path length along the graph G and
  /// the distance the fed steps made D give a sample G / D. Published when D >= this and the
  /// turn leaves one cluster (not ambiguous).
  double scale_sample_min_m = 40.0;
  /// 1-sigma of where a matched turn puts the walker along the path, at each end of a sample
  /// (the demo's route eval, error right after a turn: median 0.83 m, p95 2.87 m: ~1 m per axis).
  double turn_position_sigma_m = 1.0;
  /// Relative 1-sigma of a walked path against its graph polyline (corners cut or widened, the
  /// walker beside the centreline, simplified ways), added to every sample. 5 %: the samples'
  /// scatter on simulated phone sessions (p10 / p90 -8.7 / +5.9 %, docs/route.md); no real walk
  /// on a graph is shared to measure it.
  double path_length_sigma = 0.05;
};

/// A step-scale sample from two matched turns (RouteOptions::scale_sample_min_m).
struct RouteScaleSample {
  TimeNs t_ns = 0;           // the middle of the second turn
  double scale = 1.0;        // path length along the graph / distance of the fed steps
  double sigma = 0.0;        // 1-sigma of `scale`
  double distance_m = 0.0;   // distance of the fed steps between the two turns
};

/// One live hypothesis, for display and for fusion.
struct Candidate {
  Eigen::Vector2d en_m = Eigen::Vector2d::Zero();  // position in the graph's local frame
  double heading_rad = 0.0;      // walking direction along the segment, clockwise from north
  double weight = 0.0;           // normalised over all candidates
  std::int32_t edge = -1;        // WalkGraph edge index
  double distance_error_m = 0.0; // overshoot past a segment end while no turn matched
};

class RouteEngine {
 public:
  /// The matcher is deterministic; `seed` is accepted for the common engine face and unused.
  RouteEngine(const RouteOptions& options, std::shared_ptr<const WalkGraph> graph, std::uint64_t seed);

  void feed(const PositionFix& fix);   // initialise / prune / restart when no route is left
  void feed(const PdrStep& step);      // advance every route by the step length
  void feed(const PdrTurn& turn);      // keep routes that can make this turn; snap them
  /// Best position (largest cluster); kAmbiguous when several clusters compete, kLost
  /// (dead reckoning from the last position) when every route died.
  Estimate estimate() const;
  /// Too many routes or clusters: the caller should obtain a GNSS fix.
  bool needs_fix() const;
  std::vector<Candidate> candidates(std::size_t max) const;
  /// Every position cluster as an estimate (its routes' weighted mean and covariance, as
  /// estimate() reports the leading one), with its share of the routes' weight; best first.
  std::vector<std::pair<Estimate, double>> cluster_estimates() const;

  /// 1-sigma of the fed steps' length scale error (fraction), for the along-track part of the
  /// covariance estimate() reports (sigma x the distance since the route's last snap). The
  /// Navigator sets it before each step to the fusion filter's residual scale sigma (the steps
  /// it feeds are calibrated and carry the filter's residual scale); <= 0 (the default) = 5 %,
  /// the constant the ranking uses too.
  void set_step_scale_sigma(double sigma) { step_scale_sigma_ = sigma; }
  /// The step-scale sample of the last turn, once (then empty until the next one).
  std::optional<RouteScaleSample> take_scale_sample() { auto s = scale_sample_; scale_sample_.reset(); return s; }
  std::size_t route_count() const { return routes_.size(); }
  std::size_t restarts() const { return restarts_; }            // from a GNSS fix
  std::size_t local_restarts() const { return local_restarts_; }  // around the last estimate
  const WalkGraph& graph() const { return *graph_; }
  const RouteOptions& options() const { return opt_; }

 private:
  struct Passed {  // a node the route went through
    std::int32_t node = -1;
    std::int32_t in_seg = -1;
    double odo_m = 0.0;  // route odometer when it reached the node
  };
  struct Route {
    std::int32_t seg = 0;
    double offset_m = 0.0;     // along seg from its start
    double stuck_m = 0.0;      // walked past the segment end with no way to continue
    double odo_m = 0.0;        // distance walked since creation
    double since_snap_m = 0.0; // distance walked since the last snap (init or turn)
    double log_w = 0.0;        // ranking log-likelihood (heading, fix distance)
    double turn_free_until_m = -1.0;  // odometer up to which a matched turn's bends are free
    double snap_odo_m = -1.0;  // odometer at the last matched turn's node (< 0: none since the route began)
    double sample_path_m = -1.0, sample_steps_m = 0.0;  // G and D at that turn (G < 0: none)
    std::array<Passed, 4> passed{};
    std::uint8_t n_passed = 0;
  };
  struct Cluster {
    Eigen::Vector2d mean_en_m = Eigen::Vector2d::Zero();
    Eigen::Matrix2d cov_en_m2 = Eigen::Matrix2d::Zero();
    double weight = 0.0;
    std::size_t size = 0;
    /// The covariance an estimate of this cluster reports: its routes' spread and along-track
    /// variance, plus (1 m)^2 per axis.
    Eigen::Matrix2d reported_cov_en_m2() const { return cov_en_m2 + Eigen::Matrix2d::Identity(); }
  };

  Eigen::Vector2d position(const Route& r) const;
  void initialise(const Eigen::Vector2d& p_en_m, double sigma_m, double radius_m);
  void advance(Route r, double d_m, std::vector<Route>& out) const;
  void branch_at(const Route& r, std::int32_t node, std::int32_t in_seg, double turn_rad,
                 double d_after_m, double snap_m, double along_m, std::vector<Route>& out) const;
  void publish_scale_sample(TimeNs t_ns);
  void turn_candidates_ahead(const Route& r, double turn_rad, double d_after_m, std::vector<Route>& out) const;
  double bend_rad(std::int32_t in_seg, std::int32_t out_seg) const;
  double tail_bend(std::int32_t seg) const;
  double map_turn_rad(std::int32_t in_seg, std::int32_t out_seg) const;
  bool is_shallow(std::int32_t in_seg, std::int32_t out_seg) const;
  std::vector<Route> apply_turn(double turn_rad, double d_after_m) const;
  bool local_restart();
  void reseed_along_track(const Eigen::Vector2d& p_en_m, double sigma_m, double radius_m,
                          std::vector<Route>& kept) const;
  void merge_and_bound();
  void update_clusters();
  static void remember(Route& r, std::int32_t node, std::int32_t in_seg, double odo_m);
  static double rank(const Route& r);  // log weight with the overshoot's penalty

  RouteOptions opt_;
  std::shared_ptr<const WalkGraph> graph_;
  std::vector<double> tail_bend_;  // per directed segment: bends within turn_window_m after its start
  std::vector<Route> routes_;
  std::vector<Cluster> clusters_;
  std::deque<std::pair<TimeNs, double>> recent_steps_;  // (t, length) for turn snapping
  bool truncated_ = false;
  double lost_walked_m_ = 0.0;     // walked while lost since the last local restart attempt
  double step_scale_sigma_ = 0.0;  // set_step_scale_sigma (<= 0: kStepScaleSigma)
  std::optional<RouteScaleSample> scale_sample_;
  bool initialised_ = false;
  std::size_t restarts_ = 0;
  std::size_t local_restarts_ = 0;
  TimeNs last_t_ns_ = 0;
  Eigen::Vector2d last_en_m_ = Eigen::Vector2d::Zero();  // last estimate, for dead reckoning
  Eigen::Matrix2d last_cov_ = Eigen::Matrix2d::Identity();
};

}  // namespace pdnav::route
