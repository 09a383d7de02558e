// Simulated pedestrian walks on a walkway graph, for the route engine's evaluation,
// tests and benchmarks: the PdrStep / PdrTurn / PositionFix stream a phone would give,
// with truth. Error model in docs/route.md (step length scale error, heading bias and
// noise, a windowed gyro turn detector with a 30 deg threshold, rare noisy GNSS fixes).
#pragma once
#include <cstdint>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/events.h"
#include "pdnav/route/route_engine.h"
#include "pdnav/route/walk_graph.h"

namespace pdnav::route {

struct WalkSimOptions {
  double min_length_m = 800.0;            // walk length drawn uniformly in [min, max]
  double max_length_m = 2000.0;
  int min_turns = 6;                      // reported turns; walks with fewer are redrawn
  int max_attempts = 2000;
  double lateral_offset_sd_m = 1.5;       // walker beside the centreline, per edge
  double step_length_min_m = 0.62;        // walker's mean step length ~ U(min, max)
  double step_length_max_m = 0.80;
  double step_length_sd_m = 0.04;         // step-to-step variation of the true length
  double step_period_s = 0.55;            // ~1.8 Hz cadence, +-5 % jitter
  double step_scale_error = 0.05;         // PDR length scale error ~ U(-e, +e) per walk
  double step_noise = 0.03;               // PDR per-step relative length noise (1-sigma)
  double heading_bias_sd_rad = 8.0 * kDegToRad;    // per walk (magnetic disturbance, mounting)
  double heading_noise_sd_rad = 12.0 * kDegToRad;  // per step
  double turn_threshold_rad = 30.0 * kDegToRad;    // detector: heading change over the window
  double turn_window_m = 4.0;             // ~3 s of walking; reported half a window late
  double turn_angle_sd_rad = 6.0 * kDegToRad;      // error of the reported turn angle
  double gnss_error_m = 15.0;             // RMS horizontal error; reported as the fix sigma
  double gnss_min_interval_s = 120.0;
  double gnss_max_interval_s = 300.0;
};

using SimEvent = std::variant<PdrStep, PdrTurn, PositionFix>;

struct SimWalk {
  std::vector<SimEvent> events;                 // time-ordered; starts with a fix
  std::vector<Eigen::Vector2d> truth_en_m;      // true position at each event
  std::vector<std::int32_t> path;               // directed segments walked
  double length_m = 0.0;
  int turns = 0;                                // PdrTurn events
  int bends_missed = 0;                         // path bends >= threshold not reported
};

/// One random walk on the graph (>= min_turns reported turns). Throws std::runtime_error
/// if no such walk is found in max_attempts (graph too small or without turns).
SimWalk simulate_walk(const WalkGraph& graph, const WalkSimOptions& options, std::uint64_t seed);

struct WalkScore {
  std::vector<double> turn_errors_m;   // estimate error right after each PdrTurn
  std::vector<double> step_errors_m;   // estimate error after every step
  std::vector<double> gnss_errors_m;   // error of each GNSS fix itself
  std::size_t restarts = 0;            // from a GNSS fix
  std::size_t local_restarts = 0;      // around the last estimate
  std::size_t lost_steps = 0;          // steps with status kLost
  std::size_t ambiguous_steps = 0;
  std::size_t fix_request_steps = 0;   // steps where needs_fix() was true
  std::size_t max_routes = 0;
};

/// Feed a simulated walk to a fresh engine and score it against truth.
WalkScore score_walk(std::shared_ptr<const WalkGraph> graph, const RouteOptions& options,
                     const SimWalk& walk);

/// p-quantile (0..1) by linear interpolation; NaN for an empty sample.
double quantile(std::vector<double> v, double p);

}  // namespace pdnav::route
