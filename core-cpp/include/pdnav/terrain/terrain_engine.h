// Terrain engine: the SIR particle filter of Broyles, Kauffman, Raquet, Smagowski,
// "Non-GNSS Smartphone Pedestrian Navigation Using Barometric Elevation and Digital Map-Matching",
// Sensors 2018, 18, 2232 (Eq. 1-10), with residual monitoring and a structure-of-arrays layout.
// State per particle: [east, north, heading bias, baro bias] in the DEM tile's ENU frame.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/baro.h"
#include "pdnav/geo/estimate.h"
#include "pdnav/geo/events.h"
#include "pdnav/geo/samples.h"
#include "pdnav/terrain/dem.h"

namespace pdnav::terrain {

enum class Resampling {
  kMultinomial,  // paper default (Eq. 10), O(N) through sorted uniforms from exponential spacings
  kSystematic,   // one uniform offset, N evenly spaced pointers (Kitagawa 1996)
  kStratified,   // one uniform per stratum
};
const char* to_string(Resampling r);
Resampling resampling_from_string(const std::string& s);  // throws std::invalid_argument

struct TerrainOptions {
  int particles = 500;                          // Broyles 2018 Sec. 4: 500 particles on the phone
  double step_length_sigma_m = 0.15;            // sigma_l, Eq. 1-2: dl ~ U(-sigma_l, sigma_l)
  double heading_bias_sigma_rad = 15.0 * kDegToRad;  // sigma_theta, Eq. 3 (FOGM heading bias)
  double heading_bias_tau_s = 60.0;             // tau_theta, Eq. 3
  double baro_bias_sigma_m = 5.0;               // sigma_b, Eq. 4 (FOGM baro bias)
  double baro_bias_tau_s = 3600.0;              // tau_b, Eq. 4
  double measurement_var_m2 = 16.0;             // R, Eq. 5-7 (lidar-class DEM)
  double initial_sigma_m = 5.0;                 // initial position 1-sigma per axis, Sec. 3
  double resample_threshold = 0.5;              // resample when Neff < 0.5 N, Eq. 10
  Resampling resampling = Resampling::kMultinomial;  // paper default
  /// Beyond the paper: update only after this horizontal distance walked since the last
  /// update (baro averaged meanwhile); 0 = every step (paper). Limits over-confidence from
  /// DEM errors that are correlated over a cell.
  double update_distance_m = 0.0;
  /// Beyond the paper: a per-particle constant step-length scale error ~ N(0, sigma), a fifth
  /// state; 0 = the paper's four-state filter.
  double step_scale_sigma = 0.0;
  /// Beyond the paper: the barometer is averaged over the walk since the last update, so compare
  /// it with the mean DEM elevation of that segment (trapezoid of the particle's DEM elevation at
  /// the last update and now) instead of the end point's, which lags on slopes; false = paper.
  bool segment_mean_elevation = false;
  /// Beyond the paper: Rao-Blackwellised baro bias. Given a particle's path the bias (Eq. 4) and
  /// the measurement (Eq. 5) are linear-Gaussian, so each particle carries the bias mean of a
  /// scalar Kalman filter (the variance is common to all particles) and is weighted by the
  /// marginal likelihood N(z; h + b, P + R) instead of sampling the bias. false = paper.
  bool rao_blackwell_baro_bias = false;
  /// Beyond the paper (issue 17): SRTM's error is spatially correlated (Rodriguez et al. 2006:
  /// ~6 m 90 % absolute height error, correlated over hundreds of metres; larger on slopes and
  /// under canopy). With the Rao-Blackwellised bias, that error is a state the bias holds: its
  /// variance grows by dem_error_sigma_m^2 (1 - exp(-2 l / dem_error_corr_m)) per step of l m
  /// instead of being counted as white, independent evidence at every update. 0 = off.
  double dem_error_sigma_m = 0.0;
  double dem_error_corr_m = 150.0;
  /// Beyond the paper (issue 17): relative barometric height-scale error from the day's
  /// temperature vs ISA (5 K / 288 K ~ 1.7 %); adds (sigma x climb since the last update)^2 to
  /// the bias variance. 0 = off. Both need rao_blackwell_baro_bias.
  double baro_scale_sigma = 0.0;
  /// Beyond the paper (issue 17): step length varies with grade (shorter on climbs and steep
  /// descents), correlated over a climb: the step-scale state also follows a FOGM in distance
  /// with this sigma and correlation length. Needs step_scale_sigma > 0 and the RB bias. 0 = off.
  double stride_grade_sigma = 0.0;
  double stride_grade_corr_m = 300.0;
  /// Beyond the paper (issue 28): the part of the grade effect that is constant over a walk. A
  /// route's mean steepness shortens the stride for the whole walk (the gait data behind
  /// stride_grade_sigma: several % per 10 % grade; mountain routes average 20-30 % grade, so
  /// 10-20 %: 15 %), which a level-ground step model (APT) does not know and the 300 m FOGM
  /// above cannot hold for a whole walk. Added in quadrature to step_scale_sigma for the per-walk scale draw, as a
  /// zero-mean prior (the filter is not told the direction). Used only with stride_grade_sigma.
  double stride_walk_grade_sigma = 0.0;
  /// Beyond the paper: roughening after resampling (Gordon et al. 1993), K; 0 = off.
  double roughening_k = 0.0;
  // --- residual monitoring (the paper mentions it without detail; docs/terrain.md) ---
  bool residual_monitor = true;
  int monitor_window = 15;                      // updates in the normalised-innovation average
  double monitor_nis_threshold = 2.0;           // mean NIS above this = divergence / false lock
  double monitor_outlier_sigmas = 6.0;          // every particle beyond this = immediate alarm
  double respread_sigma_m = 60.0;               // position noise added on recovery (per axis)
  double recovery_noise_gain = 2.0;             // process noise multiplier while recovering
  double recovery_duration_s = 60.0;
  // --- barometer integrity (beyond the paper; docs/terrain.md) ---
  /// A change between consecutive pressure samples of more than baro_jump_m + the altitude a
  /// pedestrian (lifts included) can change at baro_max_vertical_speed_mps is a sensor step:
  /// it is measured and subtracted from later samples, so the filter keeps using elevation
  /// *changes*. 0 = off.
  double baro_jump_m = 5.0;
  double baro_max_vertical_speed_mps = 10.0;
  /// A barometer repeating one exact value for this long is stuck (real sensors are never
  /// that quiet): terrain updates pause until the value changes. 0 = off.
  double baro_stuck_s = 20.0;
  /// Void / off-map particles: likelihood of a residual of this many sigmas (no information,
  /// a mild penalty), so voids neither kill nor attract particles.
  double no_info_sigmas = 2.0;
  // --- honest status (beyond the paper; docs/terrain.md "Honest status") ---
  /// A cloud whose weighted positions, projected on their major axis, split into several
  /// groups separated by an empty-ish gap is reported as ambiguous with its modes. A gap is a
  /// smoothed histogram valley below mode_valley_fraction of the smaller neighbouring peak;
  /// each mode must hold at least mode_min_weight of the weight and the mode centres must be
  /// mode_min_separation_m apart (closer modes are inside one honest ellipse anyway).
  double mode_min_weight = 0.1;
  double mode_valley_fraction = 0.25;
  double mode_min_separation_m = 60.0;
  /// Terrain is uninformative when the DEM relief (1-sigma of elevations sampled on two rings
  /// around the cloud, radius max(informative_radius_m, 2 sigma of the cloud)) is below
  /// uninformative_relief_sigmas x the measurement noise sqrt(R): a barometer then cannot tell
  /// one particle from another, so the update is skipped (the cloud keeps growing with the
  /// dead-reckoning noise, never locks on DEM noise) and the status says so. 0 = off.
  double informative_radius_m = 150.0;
  double uninformative_relief_sigmas = 1.0;
  /// The start area (3 sigma around the declared start, per axis) must lie on the tile;
  /// a wider start is refused (start_error()).
  double start_coverage_sigmas = 3.0;
  /// Start anchoring: each particle's baro bias starts at DEM(declared start) - DEM(its own
  /// start), a constant of its hypothesis, instead of 0 for all (the paper). false = paper.
  bool anchor_start_bias = true;

  /// Paper defaults (a 1-3 m lidar DEM).
  static TerrainOptions paper() { return {}; }
  /// The paper's 30 m / SRTM tuning: sigma_b 20 m, tau_b 1200 s, R 160 m^2, update every step.
  static TerrainOptions srtm_preset();
  /// Beyond the paper, for 30-90 m DEMs (SRTM), tuned on simulated walks over six areas of an
  /// SRTM tile (docs/terrain.md): sigma_b 5 m, tau_b 600 s, R 20 m^2, an update every 10 m
  /// walked, a step-scale state (sigma 3 %), roughening K = 0.2, the segment-mean elevation and
  /// the Rao-Blackwellised baro bias; since issue 17 also the correlated DEM-error term (5 m,
  /// 150 m), the baro scale term (1.7 %) and the grade-varying stride (10 %, 300 m), for the
  /// simulator's world error models; since issue 28 the per-walk grade stride term (15 %).
  /// The eval-terrain default.
  static TerrainOptions srtm_tuned();
  /// "paper", "srtm" or "srtm-tuned"; throws std::invalid_argument.
  static TerrainOptions preset(const std::string& name);
};

/// One mode of a multimodal particle cloud (DEM frame).
struct TerrainMode {
  Eigen::Vector2d en_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d cov_en_m2 = Eigen::Matrix2d::Zero();
  double weight = 0.0;  // fraction of the total weight, 0..1
  geo::Geodetic position;
};

/// Counters for diagnostics and tests.
struct TerrainStats {
  std::int64_t steps = 0;
  std::int64_t updates = 0;              // measurement updates applied
  std::int64_t skipped_updates = 0;      // no valid DEM under any particle / no baro yet
  std::int64_t resamples = 0;
  std::int64_t weight_underflows = 0;    // all weights vanished: reset to uniform
  std::int64_t recoveries = 0;           // residual monitor re-spreads
  double last_nis = 0.0;                 // last normalised innovation squared
  double mean_nis = 0.0;                 // window mean of NIS
  double neff_fraction = 1.0;            // last Neff / N
  double off_dem_fraction = 0.0;         // weight on void / off-map cells at the last update
  std::int64_t baro_rejected = 0;        // pressures outside 25-115 kPa or not finite
  std::int64_t baro_jumps = 0;           // sensor steps measured and compensated
  double baro_jump_offset_m = 0.0;       // sum of the compensated steps
  std::int64_t baro_stuck_events = 0;    // times the barometer was found stuck
  bool baro_stuck = false;               // stuck now: no terrain updates
  std::int64_t uninformative_updates = 0;  // updates skipped: terrain relief below the noise
  bool uninformative = false;            // at the last update
  double relief_m = 0.0;                 // DEM relief (1-sigma) around the cloud, last update
};

class TerrainEngine {
 public:
  TerrainEngine(const TerrainOptions& options, std::shared_ptr<const Dem> dem, std::uint64_t seed);
  ~TerrainEngine();
  TerrainEngine(TerrainEngine&&) noexcept;
  TerrainEngine& operator=(TerrainEngine&&) noexcept;

  /// Spread particles around the declared start (sigma per axis) and anchor the barometer
  /// at the DEM elevation there: the next pressure sample becomes the reference pressure.
  /// Each particle's baro bias starts at the DEM difference between the declared start and
  /// its own start position (docs/terrain.md "Start anchoring"). A start whose
  /// start_coverage_sigmas area reaches beyond the tile is refused: the engine stays without
  /// a start, estimate() is invalid and says why, start_error() holds the message (never
  /// throws: the Navigator feeds it from logs). check_start() is the throwing form.
  void initialize(const geo::Geodetic& start, double sigma_m, TimeNs t_ns);
  /// Empty when initialize() would accept this start, else the reason it refuses it.
  std::string start_problem(const geo::Geodetic& start, double sigma_m) const;
  /// Throws std::invalid_argument with start_problem() when not empty.
  void check_start(const geo::Geodetic& start, double sigma_m) const;
  /// The reason the last initialize() was refused; empty when it was accepted.
  const std::string& start_error() const;
  /// Propagation (Eq. 1-4), then a measurement update (Eq. 5-7) when baro is available,
  /// then resampling when Neff < threshold (Eq. 10).
  void feed(const PdrStep& step);
  /// Barometer: converted to altitude (geo::baro_altitude_m) and averaged until the next update.
  void feed(const PressureSample& p);

  /// Weighted mean and covariance (Eq. 8-9), status and reason: kAmbiguous with the modes
  /// in the reason when the cloud is multimodal (the mean and covariance then span them);
  /// kDegraded "terrain uninformative" on featureless terrain. Cached until the next feed (the
  /// cache makes concurrent calls on one engine unsafe; one engine belongs to one thread).
  Estimate estimate() const;
  /// The modes of the cloud (one when unimodal; heaviest first; empty before the start).
  std::vector<TerrainMode> modes() const;
  /// Up to max particles (evenly thinned), east/north in the DEM frame.
  std::vector<Eigen::Vector2d> particles_en(std::size_t max) const;
  /// The weights of the same particles as particles_en(max), normalised by the whole cloud's
  /// total weight (sum to 1 when max >= the particle count).
  std::vector<double> particle_weights(std::size_t max) const;
  /// Weighted means of the bias states (heading bias rad, baro bias m incl. the start anchor offset).
  Eigen::Vector2d bias_estimate() const;
  const TerrainStats& stats() const;
  const TerrainOptions& options() const;
  const Dem& dem() const;
  /// Heap bytes held per particle (state, weights, resampling buffers).
  static std::size_t bytes_per_particle();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pdnav::terrain
