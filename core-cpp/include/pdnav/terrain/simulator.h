// Walk simulator on a real DEM: random routes with realistic PDR and barometer errors, and the
// evaluation of the terrain engine against dead reckoning on such walks (pdnav simulate /
// pdnav eval-terrain). Seeded and reproducible; no file I/O (the CLI writes the logs).
// Errors: by default the world models of pdnav/sim/world.h (issue 17, docs/simulator.md),
// which are not the filter's; world_errors = false restores the earlier filter-like models
// (FOGM heading and baro bias, white DEM error) documented in docs/terrain.md.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/events.h"
#include "pdnav/geo/samples.h"
#include "pdnav/sim/world.h"
#include "pdnav/terrain/dem.h"
#include "pdnav/terrain/terrain_engine.h"

namespace pdnav::terrain {

struct WalkSimOptions {
  double min_length_m = 1000.0;               // route length drawn uniformly in [min, max]
  double max_length_m = 5000.0;
  double step_rate_hz = 1.8;                  // walking cadence
  double step_period_jitter = 0.05;           // relative 1-sigma of each step period
  double step_length_mean_m = 0.72;           // per-walk true step length ~ N(mean, sd)
  double step_length_walk_sd_m = 0.05;
  double step_length_jitter_m = 0.04;         // step-to-step true length 1-sigma
  double length_scale_error_sd = 0.02;        // PDR step-length model error (per walk, relative)
  double length_noise_m = 0.03;               // PDR per-step length noise 1-sigma
  double heading_bias_sigma_rad = 15.0 * kDegToRad;  // FOGM heading bias (Broyles 2018)
  double heading_bias_tau_s = 60.0;
  double heading_noise_rad = 2.0 * kDegToRad;  // white heading noise per step
  double disturbance_rate_per_s = 1.0 / 300.0; // magnetic disturbances (paper's Route 8)
  double disturbance_max_rad = 30.0 * kDegToRad;
  double disturbance_min_s = 10.0;
  double disturbance_max_s = 60.0;
  double baro_rate_hz = 5.0;
  double baro_noise_pa = 3.0;                 // white pressure noise (~0.25 m)
  double baro_bias_sigma_m = 3.0;             // FOGM baro altitude bias
  double baro_bias_tau_s = 1200.0;
  double weather_drift_sd_pa_per_h = 30.0;    // per-walk linear synoptic pressure trend
  double gust_rate_per_s = 1.0 / 120.0;       // wind gusts: pressure bumps
  double gust_max_pa = 30.0;
  double gust_min_s = 2.0;
  double gust_max_s = 10.0;
  double dem_error_sigma_m = 5.0;             // truth terrain = DEM + correlated error field
  double dem_error_corr_m = 300.0;
  double start_sigma_m = 5.0;                 // declared start error 1-sigma per axis
  double edge_margin_m = 800.0;               // routes stay this far inside the tile
  double max_slope = 0.6;                     // route legs steeper than this are rejected
  double sea_level_pressure_pa = 101325.0;
  double temperature_offset_sd_k = 5.0;       // day's deviation from the ISA temperature
  /// World error models (default): heading = random walk + phone shifts + magnetic anomalies
  /// around structures; true stride varies with slope and fatigue while the PDR reports the
  /// model's step_length_mean_m; barometer = weather trend + tide + gusts + offset + 1 Pa
  /// quantisation; DEM error correlated, slope-dependent, canopy-biased. The fields above
  /// that describe the old models (heading_bias_*, disturbance_*, baro_*, weather_*, gust_*,
  /// dem_error_*, length_scale_error_sd, length_noise_m, step_length_jitter_m) are then unused.
  bool world_errors = true;
  sim::HeadingErrorOptions heading_world;
  sim::StrideOptions stride_world;
  sim::BaroWorldOptions baro_world;
  sim::DemErrorOptions dem_world;
  double anomalies_per_km = 3.0;              // magnetic structures along a mountain route
  double phone_height_m = 1.3;                // barometer above the ground (chest)
};

/// A simulated walk: what a phone would log, plus the truth.
struct SimulatedWalk {
  std::uint64_t seed = 0;
  TimeNs t0_ns = 0;
  geo::Geodetic declared_start;          // what the user declares (truth + error)
  double declared_sigma_m = 5.0;
  Eigen::Vector2d declared_start_en = Eigen::Vector2d::Zero();
  std::vector<PdrStep> steps;            // measured steps (biased heading, length error)
  std::vector<PressureSample> pressure;  // time ordered
  std::vector<TruthSample> truth;        // one per step, at the step time
  std::vector<Eigen::Vector2d> truth_en; // one per step, DEM frame
  double length_m = 0.0;                 // true path length
};

/// Simulates one walk on the DEM; throws std::runtime_error if no walkable route fits.
SimulatedWalk simulate_walk(const Dem& dem, const WalkSimOptions& opt, std::uint64_t seed);

/// Per-walk accuracy of dead reckoning and of the terrain engine against the truth.
struct WalkEvaluation {
  double length_m = 0.0;
  std::size_t epochs = 0;          // steps evaluated
  double dr_drms_m = 0.0;          // sqrt(mean horizontal error^2), dead reckoning
  double pf_drms_m = 0.0;          // same, particle filter
  double coverage_1sigma = 0.0;    // fraction of epochs with the truth inside the 1-sigma ellipse
  std::size_t inside_1sigma = 0;   //   (68.27 % probability content, Mahalanobis^2 <= kOneSigmaM2)
  double coverage_unit = 0.0;      // same for the unit-covariance ellipse (39.35 % content)
  std::size_t inside_unit = 0;
  /// The median epoch's squared Mahalanobis distance as a chi^2(2) percentile (geo
  /// chi2_2dof_percent; 50 when the covariance is honest): a walk's error is correlated along it,
  /// so its coverage is a few draws. NaN without an evaluated epoch.
  double median_percentile = kNaN;
  bool all_finite = true;          // no NaN / inf in any estimate
  double final_dr_error_m = 0.0;
  double final_pf_error_m = 0.0;
  TerrainStats stats;
};

/// Runs dead reckoning and a TerrainEngine (seeded) over the walk, step by step.
WalkEvaluation evaluate_walk(const SimulatedWalk& walk, std::shared_ptr<const Dem> dem,
                             const TerrainOptions& options, std::uint64_t seed);

/// Seed of walk k of an evaluation with base seed s (SplitMix64 of s and k).
std::uint64_t walk_seed(std::uint64_t base_seed, std::uint64_t k);

}  // namespace pdnav::terrain
