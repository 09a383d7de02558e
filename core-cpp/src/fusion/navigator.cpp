#include "pdnav/fusion/navigator.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <stdexcept>
#include <utility>

#include <Eigen/LU>

#include "pdnav/fusion/dead_reckoning.h"
#include "pdnav/geo/frames.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/gnss_engine.h"
#include "pdnav/pdr/pdr.h"
#include "pdnav/route/route_engine.h"
#include "pdnav/terrain/terrain_engine.h"
#include "reason_text.h"

namespace pdnav::fusion {

EngineMode engine_mode_from_string(const std::string& s) {
  if (s == "auto") return EngineMode::kAuto;
  if (s == "dr" || s == "dead-reckoning") return EngineMode::kDeadReckoning;
  if (s == "terrain") return EngineMode::kTerrain;
  if (s == "route") return EngineMode::kRoute;
  if (s == "gnss") return EngineMode::kGnss;
  throw std::invalid_argument("unknown engine '" + s + "' (auto, dr, terrain, route, gnss)");
}

const char* to_string(EngineMode m) {
  switch (m) {
    case EngineMode::kAuto: return "auto";
    case EngineMode::kDeadReckoning: return "dr";
    case EngineMode::kTerrain: return "terrain";
    case EngineMode::kRoute: return "route";
    case EngineMode::kGnss: return "gnss";
  }
  return "?";
}

const char* to_string(FusionMode m) {
  switch (m) {
    case FusionMode::kNotStarted: return "not-started";
    case FusionMode::kGnss: return "gnss";
    case FusionMode::kGnssDegraded: return "gnss-degraded";
    case FusionMode::kRoute: return "route";
    case FusionMode::kTerrain: return "terrain";
    case FusionMode::kPdr: return "pdr";
  }
  return "?";
}

FusionOptions fusion_options_before_issue28() {
  FusionOptions o;
  o.aid_covariance_intersection = false;
  o.aid_var_scale = 4.0;
  o.filter.consider_pdr_states_on_position = false;
  o.filter.heading_bias_tau_s = 0.0;
  o.filter.scale_tau_s = 0.0;
  o.calibration.max_scale_sigma = 0.03;
  o.calibration.max_heading_bias_sigma_rad = 4.0 * kDegToRad;
  o.calibration.residual_correlation = false;
  o.calibration.check_bias_drift = false;
  o.calibration.independent_heading = false;
  o.calibration.use_course = false;
  o.calibration.use_speed = false;
  o.route_scale_from_filter = false;
  o.route_scale_samples = false;
  o.filter.scale_within_walk_sigma = 0.0;
  return o;
}

namespace {
constexpr std::size_t kModeChangesKept = 1000;
constexpr double kFusedRefreshS = 0.5;  // shown estimate refreshed at least this often (s of samples)
constexpr std::size_t kModeChangesInOutput = 32;
constexpr std::size_t kStepEstimatesKept = 256;  // per-step estimates held for take_step_estimates()

using detail::fmt;

TimeNs ns(double s) { return static_cast<TimeNs>(s * 1e9); }

/// Mahalanobis length of d in covariance c (inf when c is singular).
double sigmas(const Eigen::Vector2d& d, const Eigen::Matrix2d& c) {
  const double det = c.determinant();
  if (!(det > 0.0)) return d.norm() > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
  return std::sqrt(std::max(0.0, d.dot(c.inverse() * d)));
}

double wrap_2pi(double a) {
  a = std::fmod(a, 2.0 * kPi);
  return a < 0.0 ? a + 2.0 * kPi : a;
}

constexpr TimeNs kGnssFreshNs = 3 * kNsPerS;  // a GNSS estimate older than this is "lost"

/// Typical interval between GNSS events (the engine's epochs, accepted positions): the first
/// interval, then an exponential average; a gap of 60 s or more is an outage, not the rate.
struct IntervalAverage {
  double s = 1.0;
  int n = 0;
  void add(double dt_s) {
    if (dt_s > 0.0 && dt_s < 60.0) s = n++ == 0 ? dt_s : 0.8 * s + 0.2 * dt_s;
  }
  /// Still fresh this long after the last event: base_s, or 1.5 intervals + 1 s when duty-cycled.
  double fresh_limit_s(double base_s) const { return std::max(base_s, 1.5 * s + 1.0); }
};

/// elapsedRealtimeNanos is >= 0 and far below 2^62 (146 years); outside that range a time is
/// corrupt, and admitting it would let time differences downstream overflow int64.
bool time_in_range(TimeNs t) { return t >= 0 && t <= (TimeNs{1} << 62); }

bool wants(EngineMode mode, EngineMode engine) { return mode == EngineMode::kAuto || mode == engine; }
}  // namespace

struct Navigator::Impl {
  NavigatorConfig cfg;
  std::uint64_t seed;
  pdr::Pdr pdr;
  DeadReckoning dr;
  std::unique_ptr<terrain::TerrainEngine> terrain;
  std::unique_ptr<route::RouteEngine> route;
  std::unique_ptr<gnss::GnssEngine> gnss;
  std::map<std::string, std::int64_t> ignored;
  std::map<std::size_t, TimeNs> last_t_by_type;
  bool started = false;
  bool location_set = false;
  TimeNs last_t_ns = 0;
  TimeNs last_gnss_ok_ns = -1;
  TimeNs last_gnss_epoch_ns = -1;         // time of the GNSS engine's newest epoch
  IntervalAverage gnss_epoch_interval;    // between its epochs (duty cycling)
  std::int64_t steps = 0;
  std::int64_t first_utc_ms = kMissingInt;  // wall clock of the session (WMM date)
  geo::Geodetic start_position;
  std::vector<StepEstimate> step_estimates;  // after each step, at its own time (take_steps)
  double walked_m = 0.0;                  // sum of the calibrated step lengths
  double pending_start_lat = kNaN, pending_start_lon = kNaN, pending_start_sigma = kNaN;

  // --- the fused estimate (mode kAuto) ---
  bool fused = false;
  FusionFilter ff;
  PdrCalibrator cal;
  geo::LocalFrame frame;                  // fused frame (the start position)
  PdrCalibration applied;                 // calibration applied to the steps
  FusionMode mode = FusionMode::kNotStarted;
  std::string mode_why;  // why the fused estimate is in its mode, as of the last refresh
  std::deque<ModeChange> changes;
  std::int64_t change_count = 0;
  std::map<std::string, std::int64_t> counts;
  TimeNs last_gnss_ns = -1;               // last accepted GNSS (Raw or Fix) position
  TimeNs last_raw_pos_ns = -1;            // last Raw epoch with an SPP position (accepted or not)
  IntervalAverage gnss_interval;          // between accepted GNSS positions
  TimeNs last_degraded_gnss_ns = -1;     // last accepted degraded / Fix-only GNSS position
  std::string gnss_what;                  // description of the last accepted GNSS measurement
  std::string last_event;                 // the last notable filter event (for the reason)
  TimeNs last_raw_row_ns = -1;            // t of the last Raw row fed (pending epoch)
  bool raw_pending = false;
  TimeNs last_anchor_ns = -1, last_aid_ns = -1, last_aid_ok_ns = -1;
  FusionMode aid_engine = FusionMode::kPdr;
  int route_misses = 0, terrain_misses = 0;
  double height_m = 0.0;
  // shown (blended) estimate
  bool shown_valid = false;
  Eigen::Vector2d offset_en_m = Eigen::Vector2d::Zero();  // shown - filter
  Eigen::Vector2d shown_en_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d shown_cov = Eigen::Matrix2d::Identity();
  TimeNs shown_t_ns = 0;
  Estimate shown;

  Impl(const NavigatorConfig& c, std::uint64_t s)
      : cfg(c), seed(s), pdr(pdr_options(c)), fused(c.mode == EngineMode::kAuto), ff(c.fusion.filter),
        cal(c.fusion.calibration) {
    ff.track_motion_sensing(true);  // every motion-sensor sample is reported (feed): a GNSS-only log is blind
    if ((cfg.dem || !cfg.dem_path.empty()) && wants(cfg.mode, EngineMode::kTerrain)) {
      auto dem = cfg.dem ? cfg.dem : std::make_shared<const terrain::Dem>(terrain::Dem::load(cfg.dem_path));
      terrain::TerrainOptions topt = terrain::TerrainOptions::preset(cfg.terrain_preset);
      topt.particles = std::max(1, cfg.particles);
      // A preset with a scale state draws each particle's walker scale from the step model's
      // per-walk error for an unknown walker: the fused filter's own prior for it
      // (FusionFilterOptions::initial_scale_sigma, 18 %: measured between and within the real
      // data sets), not the model's per-step 10 %. (The paper's four-state presets keep their
      // per-step sigma_l only.)
      if (topt.step_scale_sigma > 0.0)
        topt.step_scale_sigma = std::max({topt.step_scale_sigma, pdr.options().length.sigma_fraction,
                                          c.fusion.filter.initial_scale_sigma});
      terrain = std::make_unique<terrain::TerrainEngine>(topt, dem, seed);
    }
    if ((cfg.graph || !cfg.graph_path.empty()) && wants(cfg.mode, EngineMode::kRoute)) {
      auto graph = cfg.graph ? cfg.graph : std::make_shared<const route::WalkGraph>(route::WalkGraph::load(cfg.graph_path));
      route = std::make_unique<route::RouteEngine>(route::RouteOptions{}, graph, seed + 1);
    }
    if (wants(cfg.mode, EngineMode::kGnss)) {
      gnss = std::make_unique<gnss::GnssEngine>(gnss::GnssOptions{}, ephemeris(cfg), seed + 2);
    }
    if (cfg.mode == EngineMode::kTerrain && !terrain) throw std::invalid_argument("terrain engine needs a DEM (--dem)");
    if (cfg.mode == EngineMode::kRoute && !route) throw std::invalid_argument("route engine needs a walkway graph (--graph)");
    if (std::isfinite(cfg.start_lat_deg) && std::isfinite(cfg.start_lon_deg))
      pending_start_lat = cfg.start_lat_deg, pending_start_lon = cfg.start_lon_deg, pending_start_sigma = cfg.start_sigma_m;
  }

  static std::shared_ptr<const gnss::EphemerisStore> ephemeris(const NavigatorConfig& c) {
    if (c.ephemeris) return c.ephemeris;
    auto eph = std::make_shared<gnss::EphemerisStore>();
    for (const std::string& p : c.nav_paths) eph->load_rinex_nav(p);
    return eph;
  }

  static pdr::StepLengthModel length_model(double height_m, bool female) {
    return female ? pdr::StepLengthModel::apt_female(height_m) : pdr::StepLengthModel::apt_male(height_m);
  }

  static pdr::PdrOptions pdr_options(const NavigatorConfig& c) {
    pdr::PdrOptions o;
    // height known: APT's height model; unknown with nothing declared (mount auto): a model
    // that adapts to the walker (docs/pdr.md); else APT with the default height
    o.length = std::isfinite(c.user_height_m)       ? length_model(c.user_height_m, c.user_female)
               : c.mount == pdr::Mount::kAuto ? pdr::StepLengthModel::unknown_walker()
                                              : length_model(kDefaultUserHeightM, c.user_female);
    o.source = pdr::StepSource::kAuto;  // Android step events while they arrive, else APT detector
    o.heading.mount = c.mount;
    return o;
  }

  void count(const std::string& why) { ++ignored[why]; }

  void start(double lat_deg, double lon_deg, double sigma_m, TimeNs t_ns) {
    constexpr double kMaxStartSigmaM = 100e3;  // a start "somewhere in this country" is not a start
    if (!std::isfinite(lat_deg) || !std::isfinite(lon_deg) || std::abs(lat_deg) > 90.0 || std::abs(lon_deg) > 180.0 ||
        !(sigma_m > 0.0) || !(sigma_m <= kMaxStartSigmaM) || !time_in_range(t_ns)) {
      count("invalid start position");
      return;
    }
    geo::Geodetic g = geo::Geodetic::from_deg(lat_deg, lon_deg, 0.0);
    dr.initialize(g, sigma_m, t_ns);
    if (terrain) terrain->initialize(g, sigma_m, t_ns);
    if (route) route->feed(PositionFix{t_ns, lat_deg, lon_deg, 0.0, sigma_m});
    start_position = g;
    pdr.set_location(g, first_utc_ms);  // WMM declination at the session's date
    if (fused) start_fused(g, sigma_m, t_ns);
    started = true;
  }

  /// The start position is known (configured or both Meta keys) but the Navigator has not
  /// started yet: PDR gets the location now, so the first drained steps already carry the
  /// declination (issue #20.2; they are drained before the start, which happens at a step).
  void hint_location() {
    if (started || !std::isfinite(pending_start_lat) || !std::isfinite(pending_start_lon)) return;
    if (std::abs(pending_start_lat) > 90.0 || std::abs(pending_start_lon) > 180.0) return;  // start() counts it
    pdr.set_location(geo::Geodetic::from_deg(pending_start_lat, pending_start_lon, 0.0), first_utc_ms);
  }

  void maybe_start(TimeNs t_ns) {
    if (!started && std::isfinite(pending_start_lat)) start(pending_start_lat, pending_start_lon, pending_start_sigma, t_ns);
  }

  void on_meta(const MetaSample& m) {
    auto num = [&](double* out) {
      try {
        *out = std::stod(m.value);
      } catch (const std::exception&) {
        count("Meta " + m.key + ": not a number");
      }
    };
    if (m.key == "StartLatitudeDegrees" && !std::isfinite(cfg.start_lat_deg)) num(&pending_start_lat);
    else if (m.key == "StartLongitudeDegrees" && !std::isfinite(cfg.start_lon_deg)) num(&pending_start_lon);
    else if (m.key == "StartSigmaMeters" && !std::isfinite(cfg.start_lat_deg)) num(&pending_start_sigma);
    if (!std::isfinite(pending_start_sigma)) pending_start_sigma = cfg.start_sigma_m;
    if (m.key == "UserHeightMeters" && !std::isfinite(cfg.user_height_m)) height_from_log(m.value);
    hint_location();
  }

  /// The recorded user height sets the step length, unless configured or steps were taken.
  void height_from_log(const std::string& value) {
    double h = kNaN;
    try {
      h = std::stod(value);
    } catch (const std::exception&) {
    }
    if (!(h >= 0.5 && h <= 2.5)) {
      count("Meta UserHeightMeters: not a height in 0.5-2.5 m");
    } else if (steps > 0) {
      count("Meta UserHeightMeters: after the first step (ignored)");
    } else {
      pdr.set_length_model(length_model(h, cfg.user_female));
    }
  }

  void drain_pdr() {
    if (!pdr.has_location()) hint_location();
    for (const PdrStep& s : pdr.take_steps()) {
      ++steps;
      maybe_start(s.t_ns);
      dr.feed(s);
      if (fused && started) {
        fused_step(s);
      } else {
        if (terrain) terrain->feed(s);
        if (route) route->feed(s);
      }
      const PdrStep c = calibrated(s);
      walked_m += c.length_m;
      step_estimates.push_back(StepEstimate{choose(), c.heading_rad, walked_m, c.heading_sigma_rad});
      // a caller that never takes them (the app) must not grow memory: the newest are kept
      if (step_estimates.size() > kStepEstimatesKept) step_estimates.erase(step_estimates.begin());
    }
    for (const PdrTurn& t : pdr.take_turns())
      if (route) route->feed(t);
  }

  void drain_gnss() {
    if (!gnss) return;
    std::vector<gnss::EpochSolution> sols = gnss->take_solutions();
    const Estimate g = gnss->estimate();
    if (g.t_ns > last_gnss_epoch_ns) {
      if (last_gnss_epoch_ns >= 0) gnss_epoch_interval.add(static_cast<double>(g.t_ns - last_gnss_epoch_ns) * 1e-9);
      last_gnss_epoch_ns = g.t_ns;
    }
    // the fused estimate also starts from a degraded (< 6 satellites) fix, with its covariance
    if (g.status == EstimateStatus::kOk || (fused && !started && g.status == EstimateStatus::kDegraded)) {
      last_gnss_ok_ns = g.t_ns;
      if (!started) {
        pending_start_lat = g.position.lat_deg();
        pending_start_lon = g.position.lon_deg();
        pending_start_sigma = std::max(1.0, std::sqrt(std::max(0.0, g.cov_en_m2.trace())));
        start(pending_start_lat, pending_start_lon, pending_start_sigma, g.t_ns);
      }
    }
    if (fused && started)
      for (const gnss::EpochSolution& sol : sols) fused_epoch(sol);
  }

  void on_fix(const FixSample& f) {
    std::string p = f.provider;
    std::transform(p.begin(), p.end(), p.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    if (p != "GPS" || !std::isfinite(f.lat_deg) || !std::isfinite(f.lon_deg)) return;
    const double sigma = std::isfinite(f.accuracy_m) && f.accuracy_m > 0 ? f.accuracy_m : 15.0;
    if (!started && !std::isfinite(pending_start_lat) && !gnss_has_nav()) start(f.lat_deg, f.lon_deg, sigma, f.t_ns);
    if (fused) {
      if (started) fused_fix(f);
      return;
    }
    if (route && started) route->feed(PositionFix{f.t_ns, f.lat_deg, f.lon_deg, std::isfinite(f.alt_m) ? f.alt_m : 0.0, sigma});
  }

  bool gnss_has_nav() const { return gnss && (cfg.ephemeris || !cfg.nav_paths.empty()); }

  bool in_order(const Sample& s) {
    const TimeNs t = sample_time_ns(s);
    if (!time_in_range(t)) {
      count("time outside 0..2^62 ns");
      return false;
    }
    TimeNs& last = last_t_by_type[s.index()];
    if (last_t_by_type.count(s.index()) && t < last) {
      count("time went backwards");
      return false;
    }
    last = t;
    last_t_ns = std::max(last_t_ns, t);
    return true;
  }

  void note_utc(const Sample& s) {
    if (first_utc_ms != kMissingInt) return;
    std::visit(
        [&](const auto& x) {
          if constexpr (has_utc<std::decay_t<decltype(x)>>::value)
            if (x.utc_ms != kMissingInt && x.utc_ms > 0) first_utc_ms = x.utc_ms;
        },
        s);
    if (first_utc_ms == kMissingInt) return;
    if (started) pdr.set_location(start_position, first_utc_ms);
    else hint_location();
  }

  void feed(const Sample& s) {
    if (!in_order(s)) return;
    note_utc(s);
    if (gnss && raw_pending && !std::holds_alternative<GnssRawSample>(s) &&
        sample_time_ns(s) > last_raw_row_ns + ns(cfg.fusion.gnss_flush_after_s)) {
      raw_pending = false;  // the epoch is complete: use it now, not when the next one starts
      gnss->flush();
      drain_gnss();
    }
    std::visit(
        [&](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, AccelSample> || std::is_same_v<T, GyroSample> || std::is_same_v<T, MagSample> ||
                        std::is_same_v<T, RotationVectorSample> || std::is_same_v<T, StepDetectorSample> ||
                        std::is_same_v<T, SensorAccuracySample> || std::is_same_v<T, UncalAccelSample> ||
                        std::is_same_v<T, UncalGyroSample> || std::is_same_v<T, UncalMagSample>) {
            pdr.feed(x);
            ff.note_motion_sensing(x.t_ns);
            drain_pdr();
          } else if constexpr (std::is_same_v<T, PressureSample>) {
            maybe_start(x.t_ns);
            if (terrain && started) terrain->feed(x);
          } else if constexpr (std::is_same_v<T, GnssRawSample> || std::is_same_v<T, NavMessageSample>) {
            if (gnss) {
              gnss->feed(x);
              if constexpr (std::is_same_v<T, GnssRawSample>) {
                raw_pending = true;
                last_raw_row_ns = x.t_ns;
              }
              drain_gnss();
            }
          } else if constexpr (std::is_same_v<T, FixSample>) {
            on_fix(x);
          } else if constexpr (std::is_same_v<T, MetaSample>) {
            on_meta(x);
          }
        },
        s);
    // time passes without steps or GNSS (standing, an outage): the covariance grows, the mode
    // follows, at most every fused_refresh_s
    if (fused && started && ff.initialized()) {
      const TimeNs t = sample_time_ns(s);
      if (t - shown_t_ns >= ns(kFusedRefreshS)) {
        ff.advance_to(t);
        refresh_mode(t);
        update_shown(t);
      }
    }
  }

  // ------------------------------------------------------------------------------------------
  // The fused estimate (docs/fusion.md)
  const FusionOptions& fo() const { return cfg.fusion; }

  void start_fused(const geo::Geodetic& g, double sigma_m, TimeNs t_ns) {
    const bool restart = ff.initialized();
    frame = geo::LocalFrame(g);
    ff.initialize(Eigen::Vector2d::Zero(), sigma_m, t_ns);
    if (applied.valid) ff.set_residual_uncertainty(applied.heading_bias_sigma_rad * applied.heading_bias_sigma_rad,
                                                   applied.scale_sigma * applied.scale_sigma);
    cal.reset();  // the calibration track restarts in the new frame; the applied one is kept
    shown_valid = false;
    offset_en_m.setZero();
    last_gnss_ns = -1;
    height_m = g.h_m;
    set_mode(t_ns, FusionMode::kPdr,
             std::string(restart ? "start position reset" : "started") + " at " + fmt(g.lat_deg(), 6) + ", " +
                 fmt(g.lon_deg(), 6) + " (sigma " + fmt(sigma_m) + " m): dead reckoning until GNSS is accepted");
    update_shown(t_ns);
  }

  void set_mode(TimeNs t, FusionMode to, const std::string& why) {
    mode_why = why;  // the shown reason is the current one ("no GNSS for 300 s"); the log keeps the change's
    if (to == mode) return;
    ModeChange c{t, mode, to, why};
    changes.push_back(c);
    while (changes.size() > kModeChangesKept) changes.pop_front();
    ++change_count;
    mode = to;
  }

  PdrStep calibrated(const PdrStep& s) const {
    PdrStep c = s;
    if (!applied.valid) return c;
    c.length_m = s.length_m * applied.scale;
    c.length_sigma_m = s.length_sigma_m * applied.scale;
    // the heading bias expected now (a Gauss-Markov process: it fades from the calibrated value)
    c.heading_rad = wrap_2pi(s.heading_rad - ff.heading_bias_expected(applied.heading_bias_rad,
                                                                      static_cast<double>(s.t_ns - applied.t_ns) * 1e-9));
    return c;
  }

  void fused_step(const PdrStep& raw) {
    cal.add_step(raw);
    const PdrStep c = calibrated(raw);
    ff.predict(c);
    if (terrain) terrain->feed(c);
    if (route && fo().route_scale_from_filter) {
      // the route's steps carry the filter's residual scale too, so that their scale error is
      // the one whose sigma it is given (the filter learns ds from TDCP speeds and the map)
      PdrStep cr = c;
      cr.length_m *= 1.0 + ff.scale_error();
      cr.length_sigma_m *= 1.0 + ff.scale_error();
      route->set_step_scale_sigma(std::sqrt(std::max(0.0, ff.scale_error_var())));
      route->feed(cr);
    } else if (route) {
      route->feed(c);
    }
    for (const PdrTurn& t : pdr.take_turns())
      if (route) route->feed(t);
    if (route) route_scale(c.t_ns);
    engine_aid(c.t_ns);
    refresh_mode(c.t_ns);
    update_shown(c.t_ns);
  }

  /// A measurement update moved the filter by `before -> now`: blend it into the shown position
  /// when it is larger than blend_above_sigma of the shown covariance.
  void after_update(const Eigen::Vector2d& before) {
    const Eigen::Vector2d delta = ff.position_en_m() - before;
    if (shown_valid && sigmas(delta, shown_cov) > fo().blend_above_sigma) offset_en_m -= delta;
  }

  void accepted_gnss(TimeNs t, const Eigen::Vector2d& z, double sigma_m, bool degraded, const std::string& what) {
    if (last_gnss_ns >= 0) gnss_interval.add(static_cast<double>(t - last_gnss_ns) * 1e-9);
    last_gnss_ns = t;
    if (degraded) last_degraded_gnss_ns = t;
    gnss_what = what;
    cal.add_gnss(t, z, sigma_m);
    const PdrCalibration& p = cal.published();
    if (p.valid && p.t_ns != applied.t_ns) {
      if (!applied.valid) ++counts["calibration published"];
      applied = p;
      // the fit is the bias averaged over its window; what the filter carries is the bias now
      const double var_b = ff.heading_bias_var_after_window(p.heading_bias_sigma_rad * p.heading_bias_sigma_rad, p.span_s);
      applied.heading_bias_sigma_rad = std::sqrt(var_b);
      const double var_s = ff.scale_var_after_window(p.scale_sigma * p.scale_sigma, p.span_s);
      applied.scale_sigma = std::sqrt(var_s);
      ff.set_residual_uncertainty(var_b, var_s);
    }
  }

  void note_result(const PositionUpdateResult& r, const std::string& src) {
    if (r.accepted) {
      if (r.forced) {
        ++counts["GNSS: forced correction (consistent disagreement)"];
        last_event = src + ": " + r.reason;
      } else if (r.reacquired) {
        ++counts["GNSS: re-acquired after an outage"];
        last_event = src + ": " + r.reason;
      }
    } else {
      ++counts[src + ": " + (r.reason.rfind("re-acq", 0) == 0 ? "waiting for re-acquisition agreement" : "rejected by the innovation gate")];
      last_event = src + ": " + r.reason;
    }
  }

  void fused_epoch(const gnss::EpochSolution& sol) {
    const TimeNs t = sol.t_ns;
    // The GNSS engine's KF accepted this epoch's fix: its position (SPP smoothed by the carrier)
    // is the measurement instead of the raw fix, its time correlation bounded by a covariance
    // floor of 1 x R_kf; TDCP stays in (it constrains the PDR states; docs/fusion.md).
    // (Re-)acquisition stays on the raw fix's wider sigma: the KF is used only while the fused
    // filter is locked to GNSS (an accepted position within kf_locked_within_s).
    const bool locked = ff.last_accepted_ns() >= 0 && t - ff.last_accepted_ns() <= ns(fo().kf_locked_within_s);
    const bool use_kf = fo().use_gnss_kf && locked && sol.spp_ok && sol.kf_ok && sol.kf_update_accepted &&
                        sol.kf_cov_enu.allFinite() && sol.kf_cov_enu.topLeftCorner<2, 2>().determinant() > 0.0;
    if (!(use_kf && fo().kf_skip_displacement) && sol.disp_dt_s > 0.0 && !sol.disp_source.empty()) {
      const double sd = sol.disp_source == "tdcp" ? fo().tdcp_sigma_m : fo().doppler_sigma_mps * sol.disp_dt_s;
      const Eigen::Vector2d before = ff.position_en_m();
      double nis = 0.0;
      if (ff.update_displacement(t, t - ns(sol.disp_dt_s), sol.tdcp_disp_m.head<2>(), sd * sd * Eigen::Matrix2d::Identity(), &nis)) {
        ++counts["GNSS: " + sol.disp_source + " displacement used"];
        // its direction is the course over ground since the last epoch, its length the distance:
        // a heading-bias and a step-scale sample
        const Eigen::Vector2d d = sol.tdcp_disp_m.head<2>();
        if (d.norm() > 0.0) {
          cal.add_course(t, std::atan2(d.x(), d.y()), d.norm() / sol.disp_dt_s, std::atan2(sd, d.norm()));
          cal.add_speed(t, d.norm() / sol.disp_dt_s, sd / sol.disp_dt_s);
        }
      }
      else if (ff.clone_t_ns() >= 0)
        ++counts["GNSS: " + sol.disp_source + " displacement rejected or unmatched"];
      after_update(before);
    }
    if (sol.spp_ok) {
      last_raw_pos_ns = t;
      const geo::Geodetic g = geo::to_geodetic(sol.spp);
      const Eigen::Vector2d z = frame.to_enu(sol.spp).p_m.head<2>();
      const double hdop = std::isfinite(sol.hdop) && sol.hdop > 0.0 ? sol.hdop : fo().default_hdop;
      const bool degraded = sol.sats_used < fo().min_sats_ok;
      double sigma = std::max(fo().min_spp_sigma_m, fo().spp_uere_m * hdop);
      if (degraded) sigma *= fo().degraded_sigma_scale;
      const double spp_sigma = sigma;
      Eigen::Vector2d zm = z;
      Eigen::Matrix2d rm = sigma * sigma * Eigen::Matrix2d::Identity();
      double floor_fraction = -1.0;
      if (use_kf) {
        zm = frame.to_enu(sol.kf).p_m.head<2>();
        rm = fo().kf_sigma_scale * sol.kf_cov_enu.topLeftCorner<2, 2>();
        rm = 0.5 * (rm + rm.transpose()).eval();
        const double v_min = fo().kf_min_sigma_m * fo().kf_min_sigma_m;
        rm(0, 0) = std::max(rm(0, 0), v_min);
        rm(1, 1) = std::max(rm(1, 1), v_min);
        if (degraded) rm *= fo().degraded_sigma_scale * fo().degraded_sigma_scale;
        sigma = std::sqrt(0.5 * rm.trace());
        floor_fraction = fo().kf_floor_fraction;
        ++counts["GNSS: engine KF position used"];
      }
      const Eigen::Vector2d before = ff.position_en_m();
      const PositionUpdateResult r = ff.update_position(t, zm, rm, true, floor_fraction);
      note_result(r, "GNSS");
      if (r.accepted) {
        if (std::isfinite(g.h_m)) height_m = g.h_m;
        // the PDR calibrator keeps the raw fixes (its window model assumes independent epochs)
        accepted_gnss(t, z, spp_sigma, degraded,
                      std::string(use_kf ? "GNSS KF" : "SPP") + " " + std::to_string(sol.sats_used) + " sats, sigma " +
                          fmt(sigma) + " m" + (sol.disp_source.empty() ? "" : " + " + sol.disp_source));
        if (r.reacquired) refresh_mode(t, "GNSS " + r.reason);
      }
      after_update(before);
    }
    ff.clone(t);
    anchor_engines(t);
    refresh_mode(t);
    update_shown(t);
  }

  void fused_fix(const FixSample& f) {
    if (last_raw_pos_ns >= 0 && f.t_ns - last_raw_pos_ns <= ns(fo().fix_fallback_after_s)) return;  // Raw is better
    const double acc = std::isfinite(f.accuracy_m) && f.accuracy_m > 0 ? f.accuracy_m : fo().fix_default_accuracy_m;
    const double sigma = acc / FixSample::kAccuracyRadiusPerSigma * fo().fix_sigma_scale;  // 68 % radius -> 1-sigma per axis
    const geo::Geodetic g = geo::Geodetic::from_deg(f.lat_deg, f.lon_deg, std::isfinite(f.alt_m) ? f.alt_m : 0.0);
    const Eigen::Vector2d z = frame.to_enu(g).p_m.head<2>();
    const Eigen::Vector2d before = ff.position_en_m();
    const PositionUpdateResult r = ff.update_position(f.t_ns, z, sigma * sigma * Eigen::Matrix2d::Identity());
    note_result(r, "Fix");
    if (r.accepted) {
      if (std::isfinite(f.alt_m)) height_m = f.alt_m;
      // the fix's course over ground (Doppler velocity): a heading-bias sample for the calibrator.
      // Exactly 0 is Android's Location.getBearing() without hasBearing() (loggers write it so).
      // Its speed is a step-scale sample only with fix_speed_scale (see NavigatorOptions)
      if (std::isfinite(f.bearing_deg) && f.bearing_deg != 0.0 && std::isfinite(f.speed_mps))
        cal.add_course(f.t_ns, f.bearing_deg * kDegToRad, f.speed_mps, f.bearing_accuracy_deg * kDegToRad);
      if (fo().fix_speed_scale) cal.add_speed(f.t_ns, f.speed_mps, f.speed_accuracy_mps);
      accepted_gnss(f.t_ns, z, sigma, true, "chipset Fix, accuracy " + fmt(acc) + " m");
      if (r.reacquired) refresh_mode(f.t_ns, "Fix " + r.reason);
    }
    after_update(before);
    anchor_engines(f.t_ns);
    refresh_mode(f.t_ns);
    update_shown(f.t_ns);
  }

  geo::Geodetic fused_geodetic(const Eigen::Vector2d& en) const {
    geo::Geodetic g = frame.to_geodetic(geo::Enu(en.x(), en.y(), 0.0));
    g.h_m = height_m;
    return g;
  }

  bool gnss_fresh(TimeNs t) const {
    if (last_gnss_ns < 0) return false;
    return t - last_gnss_ns <= ns(gnss_interval.fresh_limit_s(fo().gnss_fresh_s));
  }

  /// While GNSS is good, terrain and route are held to the fused estimate (a wrong lock is
  /// found and corrected on the way).
  void anchor_engines(TimeNs t) {
    if (!gnss_fresh(t) || t - last_gnss_ns > ns(1.0) + ns(gnss_interval.s)) return;
    if (last_anchor_ns >= 0 && t - last_anchor_ns < ns(fo().anchor_interval_s)) return;
    last_anchor_ns = t;
    const Eigen::Vector2d m = ff.position_en_m();
    const Eigen::Matrix2d p = ff.position_cov_m2();
    const double sigma = std::sqrt(std::max(1e-4, 0.5 * (p.trace() + std::sqrt(std::pow(p(0, 0) - p(1, 1), 2) + 4 * p(0, 1) * p(0, 1)))));
    const geo::Geodetic g = fused_geodetic(m);
    auto check = [&](const Estimate& e, const char* name) {
      if (!e.valid()) return;
      const Eigen::Vector2d d = frame.to_enu(e.position).p_m.head<2>() - m;
      if (sigmas(d, e.cov_en_m2 + p) > 3.0) {
        ++counts[std::string(name) + ": wrong lock corrected while GNSS is good"];
        last_event = std::string(name) + " engine was " + fmt(d.norm()) + " m off the GNSS-fused estimate: re-anchored";
      }
    };
    if (terrain) {
      check(terrain->estimate(), "terrain");
      terrain->initialize(g, sigma, t);
    }
    if (route) {
      check(route->estimate(), "route");
      route->feed(PositionFix{t, g.lat_deg(), g.lon_deg(), g.h_m, sigma});
    }
    route_misses = terrain_misses = 0;
    ++counts["engines re-anchored to the fused estimate"];
  }

  /// In an outage, a step-scale sample of the route engine (two matched turns) is a direct
  /// measurement of the filter's residual scale (the route was fed the calibrated steps, times
  /// 1 + ds with route_scale_from_filter).
  void route_scale(TimeNs t) {
    const std::optional<route::RouteScaleSample> s = route->take_scale_sample();
    if (!s || !fo().route_scale_samples || t - s->t_ns > ns(30.0)) return;  // (a stale one: taken before the fused start)
    if (last_gnss_ns >= 0 && t - last_gnss_ns < ns(fo().aid_after_s)) return;  // GNSS calibrates the scale
    // the route was fed the filter's corrected steps (x (1 + ds)) when route_scale_from_filter
    const double fed = fo().route_scale_from_filter ? 1.0 + ff.scale_error() : 1.0;
    double nis = 0.0;
    if (ff.update_scale(t, s->scale * fed - 1.0, s->sigma * fed * s->sigma * fed, &nis)) {
      ++counts[Navigator::kRouteScaleUsed];
      last_event = "route: the map's path between two turns is " + fmt(100.0 * (s->scale - 1.0)) + " % longer than " +
                   fmt(s->distance_m) + " m of steps (+- " + fmt(100.0 * s->sigma) + " %): scale updated";
    } else {
      ++counts[Navigator::kRouteScaleRejected];
    }
  }

  /// R of an engine's estimate as an aiding measurement: its covariance times aid_var_scale plus
  /// the aid_min_sigma_m floor (what the engines do not state).
  Eigen::Matrix2d aid_covariance(const Eigen::Matrix2d& cov_en_m2) const {
    return cov_en_m2 * fo().aid_var_scale + fo().aid_min_sigma_m * fo().aid_min_sigma_m * Eigen::Matrix2d::Identity();
  }

  /// In an outage, the route and terrain engines' estimates are measurements.
  void engine_aid(TimeNs t) {
    if (last_gnss_ns >= 0 && t - last_gnss_ns < ns(fo().aid_after_s)) return;
    if (last_aid_ns >= 0 && t - last_aid_ns < ns(fo().aid_interval_s)) return;
    last_aid_ns = t;
    auto aid = [&](const Estimate& e, FusionMode which, int* misses, const char* name) {
      if (e.status != EstimateStatus::kOk) return false;
      const Eigen::Vector2d z = frame.to_enu(e.position).p_m.head<2>();
      const Eigen::Matrix2d r = aid_covariance(e.cov_en_m2);
      const Eigen::Vector2d before = ff.position_en_m();
      const PositionUpdateResult res = fo().aid_covariance_intersection ? ff.update_position_ci(t, z, r)
                                                                         : ff.update_position(t, z, r, /*use_gate_policy=*/false);
      after_update(before);
      if (res.accepted) {
        *misses = 0;
        last_aid_ok_ns = t;
        aid_engine = which;
        ++counts[std::string(name) + ": used as a measurement"];
        return true;
      }
      ++counts[std::string(name) + ": rejected by the innovation gate"];
      if (++*misses >= fo().wrong_lock_after) {
        *misses = 0;
        ++counts[std::string(name) + ": wrong lock corrected (re-anchored to the fused estimate)"];
        last_event = std::string(name) + " engine disagreed " + std::to_string(fo().wrong_lock_after) +
                     " times in a row (" + res.reason + "): re-anchored";
        const Eigen::Matrix2d p = ff.position_cov_m2();
        const double sigma = std::sqrt(std::max(1e-4, 0.5 * p.trace()));
        const geo::Geodetic g = fused_geodetic(ff.position_en_m());
        if (which == FusionMode::kTerrain && terrain) terrain->initialize(g, sigma, t);
        if (which == FusionMode::kRoute && route) route->feed(PositionFix{t, g.lat_deg(), g.lon_deg(), g.h_m, sigma});
      }
      return false;
    };
    bool used = false;
    if (route && fo().aid_with_route) used = aid(associated_route(), FusionMode::kRoute, &route_misses, "route");
    if (!used && terrain && fo().aid_with_terrain) aid(terrain->estimate(), FusionMode::kTerrain, &terrain_misses, "terrain");
  }

  /// The route engine's estimate for the fused filter: its leading cluster, or with
  /// route_cluster_association the cluster the fused prediction makes most probable.
  Estimate associated_route() {
    Estimate lead = route->estimate();
    if (!fo().route_cluster_association || !(lead.status == EstimateStatus::kOk || lead.status == EstimateStatus::kAmbiguous))
      return lead;
    const auto clusters = route->cluster_estimates();
    if (clusters.size() < 2) return lead;
    std::vector<AidHypothesis> h;
    for (const auto& [e, w] : clusters)
      h.push_back({frame.to_enu(e.position).p_m.head<2>(), aid_covariance(e.cov_en_m2), w});
    const AidAssociation a = associate(ff.position_en_m(), ff.position_cov_m2(), h);
    if (a.index < 0) return lead;
    Estimate best = clusters[static_cast<std::size_t>(a.index)].first;
    if (a.runner_up > route->options().ambiguity_ratio) {
      best.status = EstimateStatus::kAmbiguous;
      ++counts["route: clusters ambiguous under the fused prediction"];
    } else if (a.index != 0) {
      ++counts["route: a cluster other than the leading one chosen by the fused prediction"];
    }
    return best;
  }

  void refresh_mode(TimeNs t, const std::string& why_in = "") {
    FusionMode to = FusionMode::kPdr;
    std::string why = why_in;
    if (gnss_fresh(t)) {
      // the label holds degraded_hold_s after the last degraded position accepted
      const bool degraded = last_degraded_gnss_ns >= 0 && last_gnss_ns - last_degraded_gnss_ns <= ns(fo().degraded_hold_s);
      to = degraded ? FusionMode::kGnssDegraded : FusionMode::kGnss;
      if (why.empty()) why = "GNSS accepted: " + gnss_what;
    } else if (last_aid_ok_ns >= 0 && t - last_aid_ok_ns <= ns(2.0 * fo().aid_interval_s)) {
      to = aid_engine;
      if (why.empty())
        why = std::string("no GNSS for ") + fmt(static_cast<double>(t - std::max<TimeNs>(0, last_gnss_ns)) * 1e-9) +
              " s: " + to_string(aid_engine) + " engine used as a measurement";
    } else if (why.empty()) {
      why = last_gnss_ns >= 0 ? "no usable GNSS for " + fmt(static_cast<double>(t - last_gnss_ns) * 1e-9) +
                                    " s: dead reckoning on the " + (applied.valid ? "calibrated" : "uncalibrated") + " PDR"
                              : "no GNSS accepted yet: dead reckoning";
      if (!last_event.empty()) why += " (last: " + last_event + ")";
    }
    set_mode(t, to, why);
  }

  void update_shown(TimeNs t) {
    if (shown_valid) t = std::max(t, shown_t_ns);  // a late epoch never moves the shown time back
    const Eigen::Vector2d m = ff.position_en_m();
    const Eigen::Matrix2d p = ff.position_cov_m2();
    if (!shown_valid) {
      offset_en_m.setZero();
    } else {
      // the blend: the offset decays with blend_tau_s, one move bounded by max_shown_jump_sigma
      const double dt = std::max(0.0, static_cast<double>(t - shown_t_ns) * 1e-9);
      const Eigen::Vector2d decayed = offset_en_m * std::exp(-dt / fo().blend_tau_s);
      Eigen::Vector2d target = m + decayed;
      const Eigen::Vector2d move = target - shown_en_m;
      const double k = sigmas(move, shown_cov);
      if (k > fo().max_shown_jump_sigma && std::isfinite(k)) target = shown_en_m + move * (fo().max_shown_jump_sigma / k);
      offset_en_m = target - m;
      if (offset_en_m.norm() < 1e-3) offset_en_m.setZero();
    }
    shown_en_m = m + offset_en_m;
    shown_cov = p + offset_en_m * offset_en_m.transpose();
    shown_t_ns = t;
    shown_valid = true;
    Estimate e;
    e.t_ns = t;
    e.position = fused_geodetic(shown_en_m);
    e.en_m = shown_en_m;
    e.cov_en_m2 = shown_cov;
    e.vertical_sigma_m = 0.0;
    switch (mode) {
      case FusionMode::kGnss: e.engine = EngineKind::kGnss; e.status = EstimateStatus::kOk; break;
      case FusionMode::kGnssDegraded: e.engine = EngineKind::kGnss; e.status = EstimateStatus::kDegraded; break;
      case FusionMode::kRoute: e.engine = EngineKind::kRoute; e.status = EstimateStatus::kDegraded; break;
      case FusionMode::kTerrain: e.engine = EngineKind::kTerrain; e.status = EstimateStatus::kDegraded; break;
      default: e.engine = EngineKind::kDeadReckoning; e.status = EstimateStatus::kDegraded; break;
    }
    e.reason = std::string("fused (") + to_string(mode) + "): " + mode_why;
    if (applied.valid)
      e.reason += "; PDR scale " + fmt(applied.scale, 3) + " heading bias " + fmt(rad_to_deg(applied.heading_bias_rad)) + " deg";
    if (offset_en_m.norm() > 0.0) e.reason += "; blending " + fmt(offset_en_m.norm()) + " m";
    if (!dr.has_absolute_heading() && steps > 0) e.reason += "; relative heading only";
    shown = std::move(e);
  }

  /// The GNSS engine's estimate as of now. It is its newest epoch's: while epochs come the
  /// engine itself says degraded / lost (coasting, few satellites), but when they stop altogether
  /// (a tunnel, a jammer, the receiver off) it would go on saying "ok" with that epoch's
  /// covariance at a position the walker has long left. Past the freshness limit (kGnssFreshNs,
  /// or 1.5 epoch intervals + 1 s when duty-cycled) it is lost; the position stays, as of then.
  Estimate gnss_now() const {
    Estimate g = gnss->estimate();
    if (!g.valid()) return g;
    const double age_s = static_cast<double>(last_t_ns - g.t_ns) * 1e-9;
    if (age_s > gnss_epoch_interval.fresh_limit_s(static_cast<double>(kGnssFreshNs) * 1e-9)) {
      g.status = EstimateStatus::kLost;
      g.reason = "GNSS: no epoch for " + fmt(age_s) + " s (the position is the last epoch's)";
    }
    return g;
  }

  Estimate choose() const {
    if (fused) {
      if (shown_valid) return shown;
      Estimate d = dr.estimate();
      return d;
    }
    if (gnss && wants(cfg.mode, EngineMode::kGnss)) {
      Estimate g = gnss_now();
      const bool fresh = last_gnss_ok_ns >= 0 && last_t_ns - last_gnss_ok_ns <= kGnssFreshNs;
      if (cfg.mode == EngineMode::kGnss) return g;
      if (g.valid() && fresh) return g;
    }
    const char* why = gnss && last_gnss_ok_ns >= 0 ? "GNSS lost, " : "";
    if (route) {
      Estimate r = route->estimate();
      if (r.valid() || cfg.mode == EngineMode::kRoute) {
        r.reason = std::string(why) + "route engine: " + r.reason;
        return r;
      }
    }
    if (terrain) {
      Estimate t = terrain->estimate();
      if (t.valid() || cfg.mode == EngineMode::kTerrain) {
        t.reason = std::string(why) + "terrain engine: " + t.reason;
        return t;
      }
    }
    Estimate d = dr.estimate();  // its reason says "relative heading only" while it is (issue #19.1)
    if (d.valid()) d.reason = std::string(why) + d.reason;
    return d;
  }
};

Navigator::Navigator(const NavigatorConfig& config, std::uint64_t seed) : impl_(std::make_unique<Impl>(config, seed)) {}
Navigator::~Navigator() = default;
Navigator::Navigator(Navigator&&) noexcept = default;
Navigator& Navigator::operator=(Navigator&&) noexcept = default;

void Navigator::feed(const Sample& s) { impl_->feed(s); }

void Navigator::finish() {
  impl_->pdr.finish();
  impl_->drain_pdr();
}

std::vector<Estimate> Navigator::take_step_estimates() {
  std::vector<Estimate> out;
  for (StepEstimate& s : std::exchange(impl_->step_estimates, {}))
    if (s.estimate.valid()) out.push_back(std::move(s.estimate));
  return out;
}

std::vector<StepEstimate> Navigator::take_steps() { return std::exchange(impl_->step_estimates, {}); }

void Navigator::set_start(double lat_deg, double lon_deg, double sigma_m, TimeNs t_ns) {
  impl_->start(lat_deg, lon_deg, sigma_m, t_ns);
}

Estimate Navigator::estimate() const { return impl_->choose(); }

NavigatorOutput Navigator::output(std::size_t max_particles) const {
  NavigatorOutput o;
  o.estimate = impl_->choose();
  o.steps = impl_->steps;
  o.engines.push_back(impl_->dr.estimate());
  if (impl_->terrain) {
    o.engines.push_back(impl_->terrain->estimate());
    o.particles_en_m = impl_->terrain->particles_en(max_particles);
  }
  if (impl_->route) o.engines.push_back(impl_->route->estimate());
  if (impl_->gnss) o.engines.push_back(impl_->gnss_now());
  o.mode = impl_->mode;
  o.mode_change_count = impl_->change_count;
  const std::size_t n = std::min(kModeChangesInOutput, impl_->changes.size());
  o.mode_changes.assign(impl_->changes.end() - static_cast<std::ptrdiff_t>(n), impl_->changes.end());
  o.calibration = impl_->applied;
  o.calibration_fit = impl_->cal.calibration();
  o.declination_known = impl_->pdr.has_location();
  o.declination = impl_->pdr.declination();
  return o;
}

std::vector<ModeChange> Navigator::mode_changes() const { return {impl_->changes.begin(), impl_->changes.end()}; }

const pdr::Pdr& Navigator::pdr() const { return impl_->pdr; }

const terrain::TerrainOptions* Navigator::terrain_options() const {
  return impl_->terrain ? &impl_->terrain->options() : nullptr;
}

std::vector<std::pair<std::string, std::int64_t>> Navigator::fusion_counts() const {
  return {impl_->counts.begin(), impl_->counts.end()};
}

std::vector<std::pair<std::string, std::int64_t>> Navigator::ignored() const {
  return {impl_->ignored.begin(), impl_->ignored.end()};
}

}  // namespace pdnav::fusion
