// fusion::Navigator: the single entry point of the core for the app (JNI), the replay CLI
// and the tests. Feed it the time-ordered sample stream; ask it for the estimate.
// It runs PDR on the inertial samples and hands steps/turns/pressure/GNSS to the engines,
// In the default mode (kAuto) the estimate shown is the fused one (FusionFilter: calibrated PDR
// prediction, gated GNSS / TDCP, terrain and route as measurements in outages, blended so it
// never jumps; docs/fusion.md); an explicit engine mode shows that engine alone.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pdnav/fusion/fusion_filter.h"
#include "pdnav/fusion/pdr_calibrator.h"
#include "pdnav/geo/estimate.h"
#include "pdnav/geo/samples.h"
#include "pdnav/pdr/heading.h"
#include "pdnav/pdr/pdr.h"
#include "pdnav/geo/wmm.h"

namespace pdnav::terrain { class Dem; struct TerrainOptions; }
namespace pdnav::route { class WalkGraph; }
namespace pdnav::gnss { class EphemerisStore; }

namespace pdnav::fusion {

enum class EngineMode { kAuto, kDeadReckoning, kTerrain, kRoute, kGnss };
EngineMode engine_mode_from_string(const std::string& s);  // "auto", "dr", "terrain", "route", "gnss"; throws std::invalid_argument
const char* to_string(EngineMode m);

inline constexpr double kDefaultUserHeightM = 1.75;

/// Hand-over rules and measurement models of the fused estimate (kAuto); docs/fusion.md.
struct FusionOptions {
  FusionFilterOptions filter;
  PdrCalibrationOptions calibration;
  // GNSS measurement models
  double spp_uere_m = 4.0;            // phone pseudorange 1-sigma (Walker 2019 Sec. 2: 3-5 m class)
  double min_spp_sigma_m = 2.0;       // floor of an SPP position 1-sigma per axis
  double default_hdop = 2.0;          // when an epoch reports none
  int min_sats_ok = 6;                // fewer used satellites: degraded (sigma scaled below)
  double degraded_sigma_scale = 1.5;
  /// The shown mode stays "gnss-degraded" until no degraded epoch was accepted for this long
  /// (hysteresis of the label only; each epoch's own weight is its own): a satellite count
  /// hovering at the threshold flipped it every 1-3 s (the demo's simulated session: 42 of its
  /// 45 mode changes).
  double degraded_hold_s = 10.0;
  double tdcp_sigma_m = 0.10;         // per axis, TDCP displacement (cm-level + phase-centre motion)
  double doppler_sigma_mps = 0.30;    // per axis, Doppler-derived velocity
  /// While the fused filter is locked to GNSS and the GNSS engine's own KF (SPP smoothed by
  /// TDCP/Doppler) accepted this epoch's fix, its position and covariance are the measurement
  /// instead of the raw SPP fix. Cascaded-filter rule (Carlson 1990, "Federated square root
  /// filter", Sec. II): the KF output is time-correlated and already holds the carrier, so after
  /// the update the fused position covariance is kept >= the KF's (floor fraction 1), never
  /// averaging successive KF outputs as if independent. docs/fusion.md (issue 14).
  bool use_gnss_kf = true;
  double kf_min_sigma_m = 1.0;        // floor of the KF position 1-sigma per axis (phone code + carrier class)
  double kf_sigma_scale = 1.0;        // KF covariance scale (1 = taken as reported)
  double kf_floor_fraction = 1.0;     // fused P_pos >= this x R_kf after a KF update
  double kf_locked_within_s = 3.0;    // KF used only after the fused filter accepted a position this recently
  bool kf_skip_displacement = false;  // drop TDCP/Doppler while the KF position is used (see docs/fusion.md)
  /// Chipset Fix rows: Android accuracy is a 68 % horizontal radius, sigma = accuracy / 1.51;
  /// scaled for their time correlation (the chipset's own filter). Used only when no Raw
  /// epoch has given a position for fix_fallback_after_s.
  double fix_sigma_scale = 1.5;
  double fix_default_accuracy_m = 15.0;
  double fix_fallback_after_s = 3.0;
  /// A Fix's speed as a step-scale sample (PdrCalibrator::add_speed). Off: a Fix is the
  /// chipset's or the fused location provider's filtered output (Android's FLP also uses the
  /// phone's motion sensors), and on the shared ETH walk its speed runs below the fixes' own
  /// displacement (20 s windows: median ratio 1.04, up to 1.3; docs/fusion.md). The speed of
  /// the GNSS engine's own TDCP/Doppler displacement is always used.
  bool fix_speed_scale = false;
  /// Flush a pending GNSS epoch when another sensor's sample is this much later (an epoch is
  /// used when it is complete, not when the next one starts).
  double gnss_flush_after_s = 0.5;
  // hand-over
  double gnss_fresh_s = 3.0;          // GNSS mode while a GNSS position was accepted this recently
                                      // (or 1.5 x the epoch interval + 1 s when duty-cycled)
  double anchor_interval_s = 5.0;     // while GNSS is good: terrain/route re-anchored this often
  double aid_after_s = 5.0;           // no GNSS this long: terrain/route become measurements
  double aid_interval_s = 10.0;       // ... at most this often (they share the PDR steps)
  /// ... fused by covariance intersection (Julier & Uhlmann 1997): the engines are driven by
  /// the same PDR steps as the filter and re-anchored to it, so their errors are correlated with
  /// the filter's by an unknown amount (docs/fusion.md "Aiding in outages"). false: a plain
  /// Kalman update with the covariance times aid_var_scale (the model before issue 28).
  bool aid_covariance_intersection = true;
  double aid_var_scale = 1.0;         // ... their covariance times this
  double aid_min_sigma_m = 5.0;       // ... plus this 1-sigma (map/model error the engines do not state)
  bool aid_with_route = true;
  /// In an outage the route engine's position clusters are weighed by the fused prediction
  /// (probabilistic data association, Bar-Shalom & Tse 1975: weight x N(cluster; fused, P + R))
  /// and the most probable one is the measurement, used when the next one weighs less than the
  /// route engine's ambiguity ratio of it. false: the route engine's leading cluster when it is
  /// unambiguous on its own weights.
  bool route_cluster_association = true;
  /// The route engine's along-track covariance grows with the filter's residual scale sigma
  /// (the steps it is fed are calibrated by the same calibration), not APT's fixed 5 %: on
  /// eval-fusion walks whose calibration was learnt on a steeper grade the route claimed a few
  /// metres while its along-track error reached 100 m (docs/fusion.md). Its steps then carry the
  /// filter's residual scale too (x (1 + ds)), so that their error is the one that sigma states.
  /// false = 5 % and the calibrated steps alone.
  bool route_scale_from_filter = true;
  bool aid_with_terrain = true;
  /// In an outage the route engine's step-scale samples (the path between two matched turns
  /// over the steps' distance, RouteScaleSample) update the filter's residual scale `ds`: the
  /// step length learned where the map constrains it (issue 27).
  bool route_scale_samples = true;
  int wrong_lock_after = 3;           // engine rejected this many times in a row: re-anchored
  // blending of the shown position
  double blend_above_sigma = 1.0;     // corrections larger than this (sigma) are blended in
  double blend_tau_s = 2.0;           // exponential blend time constant
  double max_shown_jump_sigma = 2.5;  // hard bound of one shown move, sigma of the shown covariance
};

/// The fused estimate's model before issue 28 (plain Kalman aiding with the covariance x4, the
/// PDR's heading sigma as white per-step noise, bias/scale learnt from every position fix, the
/// calibrator's N_eff from the span only, 3 % / 4 deg publication): for before/after figures
/// (`pdnav eval-fusion --fusion-model issue14`, `eval-outage` the same).
FusionOptions fusion_options_before_issue28();

/// What drives the fused estimate.
enum class FusionMode { kNotStarted, kGnss, kGnssDegraded, kRoute, kTerrain, kPdr };
const char* to_string(FusionMode m);

/// One hand-over (or start) of the fused estimate, with its reason.
struct ModeChange {
  TimeNs t_ns = 0;
  FusionMode from = FusionMode::kNotStarted;
  FusionMode to = FusionMode::kNotStarted;
  std::string reason;
};

/// Plain configuration (what the app's settings screen and the CLI flags set).
struct NavigatorConfig {
  EngineMode mode = EngineMode::kAuto;
  // Start position (declared by the user or the last fix); NaN = take it from the log's
  // Meta lines or the first GNSS fix.
  double start_lat_deg = kNaN;
  double start_lon_deg = kNaN;
  double start_sigma_m = 5.0;             // Broyles et al. 2018: 5 m initial uncertainty
  /// User height for the APT step length; NaN = the log's Meta UserHeightMeters when it comes
  /// before the first step, else (mount kAuto) the unknown-walker model
  /// (pdr::StepLengthModel::unknown_walker) or (declared mount) kDefaultUserHeightM.
  double user_height_m = kNaN;
  bool user_female = false;
  /// Phone placement: kAuto estimates placement and walking direction from the motion and,
  /// with the height unknown, uses the unknown-walker step length (docs/pdr.md); a declared
  /// mount overrides both (the default is a chest mount, which the reliability tests' simulated
  /// walkers encode; `pdnav replay` and the app's JNI bridge use auto).
  pdr::Mount mount = pdr::Mount::kChestCameraOut;
  std::string dem_path;                   // project DEM tile (dem-tools), empty = no terrain engine
  std::string graph_path;                 // project walkway graph (dem-tools), empty = no route engine
  std::vector<std::string> nav_paths;     // RINEX navigation files for the GNSS engine
  int particles = 500;                    // terrain engine (paper: 500 on a phone)
  std::string terrain_preset = "srtm-tuned";  // "paper" (lidar DEM), "srtm" (paper's 30 m tuning),
                                              // "srtm-tuned" (docs/terrain.md; the eval default)
  /// Already-loaded data, shared read-only between Navigators (a session restarted on a mode
  /// change, the fuzzer's millions of inputs); each one set is used instead of loading its
  /// path above (dem_path, graph_path, nav_paths).
  std::shared_ptr<const terrain::Dem> dem;
  std::shared_ptr<const route::WalkGraph> graph;
  std::shared_ptr<const gnss::EphemerisStore> ephemeris;
  FusionOptions fusion;                   // the fused estimate (mode kAuto)
  /// Errors here are thrown from the constructor (std::runtime_error with file and reason).
};

/// Everything a UI or replay wants after each update.
struct NavigatorOutput {
  Estimate estimate;                       // the one shown
  std::vector<Estimate> engines;           // every running engine's own estimate
  std::int64_t steps = 0;                  // steps detected so far
  std::vector<Eigen::Vector2d> particles_en_m;  // a thinned particle cloud (terrain), may be empty
  FusionMode mode = FusionMode::kNotStarted;    // what drives the fused estimate now (kAuto)
  std::vector<ModeChange> mode_changes;         // the most recent ones (up to 32), oldest first
  std::int64_t mode_change_count = 0;           // all since the start
  PdrCalibration calibration;                   // the PDR calibration in use (valid once published)
  PdrCalibration calibration_fit;               // the latest window fit, published or not (why not: its sigmas)
  /// The magnetic declination applied to the PDR headings: its WMM model and any warning
  /// (date outside every model's span, no UTC time). declination_known is false while the
  /// headings are still magnetic (no location yet).
  bool declination_known = false;
  geo::Declination declination;
};

/// One step as a walker's screen shows it (the app's per-step estimates, JNI navTakeSteps).
struct StepEstimate {
  Estimate estimate;            // after the step, at its time (status kNotInitialized before a start)
  double heading_rad = 0.0;     // the step's walking direction (calibrated), clockwise from true north
  double distance_m = 0.0;      // walked since the session start: sum of the (calibrated) step lengths
  double heading_sigma_rad = 0.0;  // the PDR's stated 1-sigma of that direction (PdrStep::heading_sigma_rad)
};

class Navigator {
 public:
  Navigator(const NavigatorConfig& config, std::uint64_t seed);
  ~Navigator();
  Navigator(Navigator&&) noexcept;
  Navigator& operator=(Navigator&&) noexcept;

  /// Feed one sample. Samples should arrive in time order per sensor; out-of-order ones
  /// are counted and ignored. Never throws on bad sample values (they are counted).
  void feed(const Sample& s);
  /// End of the input (end of a log, end of a session): PDR releases a walk shorter than its
  /// bout gate if it qualifies, and those steps reach the engines. Feed nothing afterwards.
  void finish();
  /// The estimate after each step since the last call, each at its step's own time (several
  /// steps can be released by one sample); the replay writes one track row per step. The
  /// newest 256 are held for a caller that never takes them.
  std::vector<Estimate> take_step_estimates();
  /// Every step since the last call (of this or take_step_estimates(): one queue), with its
  /// heading and the distance walked; steps before a start position carry an invalid estimate.
  std::vector<StepEstimate> take_steps();
  /// Declare or reset the start position (e.g. user long-press on the map).
  void set_start(double lat_deg, double lon_deg, double sigma_m, TimeNs t_ns);

  Estimate estimate() const;
  NavigatorOutput output(std::size_t max_particles = 200) const;
  /// Samples ignored so far, by reason.
  std::vector<std::pair<std::string, std::int64_t>> ignored() const;
  /// Fused-estimate hand-overs with reasons (the last 1000), oldest first.
  std::vector<ModeChange> mode_changes() const;
  /// The terrain engine's options as configured here (the preset, particles, and the walker-scale
  /// prior shared with the fused filter); nullptr without a terrain engine.
  const terrain::TerrainOptions* terrain_options() const;
  /// The PDR as this Navigator runs it (its location, the log's height, its placement bouts,
  /// heading sources and hard-iron calibration), for reports; its steps are taken here.
  const pdr::Pdr& pdr() const;
  /// Fusion counters (GNSS rejected by the gate, forced corrections, re-anchors, ...).
  std::vector<std::pair<std::string, std::int64_t>> fusion_counts() const;
  /// Names of two of them: the route engine's step-scale samples used / refused by the gate.
  static constexpr const char* kRouteScaleUsed = "route: step scale from two matched turns used";
  static constexpr const char* kRouteScaleRejected = "route: step scale from two matched turns rejected (gate)";

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pdnav::fusion
