#include "pdnav/fusion/navigator.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "pdnav/fusion/dead_reckoning.h"
#include "pdnav/geo/frames.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/gnss_engine.h"
#include "pdnav/pdr/pdr.h"
#include "pdnav/route/route_engine.h"
#include "pdnav/terrain/terrain_engine.h"

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

namespace {
constexpr TimeNs kGnssFreshNs = 3 * kNsPerS;  // a GNSS estimate older than this is "lost"

template <typename T, typename = void>
struct has_utc : std::false_type {};
template <typename T>
struct has_utc<T, std::void_t<decltype(std::declval<T>().utc_ms)>> : std::true_type {};

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
  std::int64_t steps = 0;
  std::int64_t first_utc_ms = kMissingInt;  // wall clock of the session (WMM date)
  geo::Geodetic start_position;
  double pending_start_lat = kNaN, pending_start_lon = kNaN, pending_start_sigma = kNaN;

  Impl(const NavigatorConfig& c, std::uint64_t s) : cfg(c), seed(s), pdr(pdr_options(c)) {
    if ((cfg.dem || !cfg.dem_path.empty()) && wants(cfg.mode, EngineMode::kTerrain)) {
      auto dem = cfg.dem ? cfg.dem : std::make_shared<const terrain::Dem>(terrain::Dem::load(cfg.dem_path));
      terrain::TerrainOptions topt = terrain::TerrainOptions::preset(cfg.terrain_preset);
      topt.particles = std::max(1, cfg.particles);
      // The step-length model's stated 1-sigma (APT height model: 10 %) is mostly a per-walk
      // scale error (the user's stride vs 0.415 h): a preset with a scale state must cover it.
      // (The paper's four-state presets keep their per-step sigma_l only.)
      if (topt.step_scale_sigma > 0.0)
        topt.step_scale_sigma = std::max(topt.step_scale_sigma, pdr.options().length.sigma_fraction);
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
    started = true;
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
    for (const PdrStep& s : pdr.take_steps()) {
      ++steps;
      maybe_start(s.t_ns);
      dr.feed(s);
      if (terrain) terrain->feed(s);
      if (route) route->feed(s);
    }
    for (const PdrTurn& t : pdr.take_turns())
      if (route) route->feed(t);
  }

  void drain_gnss() {
    if (!gnss) return;
    for (const gnss::EpochSolution& sol : gnss->take_solutions()) {
      (void)sol;
    }
    const Estimate g = gnss->estimate();
    if (g.status == EstimateStatus::kOk) {
      last_gnss_ok_ns = g.t_ns;
      if (!started) {
        pending_start_lat = g.position.lat_deg();
        pending_start_lon = g.position.lon_deg();
        pending_start_sigma = std::max(1.0, std::sqrt(std::max(0.0, g.cov_en_m2.trace())));
        start(pending_start_lat, pending_start_lon, pending_start_sigma, g.t_ns);
      }
    }
  }

  void on_fix(const FixSample& f) {
    std::string p = f.provider;
    std::transform(p.begin(), p.end(), p.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    if (p != "GPS" || !std::isfinite(f.lat_deg) || !std::isfinite(f.lon_deg)) return;
    const double sigma = std::isfinite(f.accuracy_m) && f.accuracy_m > 0 ? f.accuracy_m : 15.0;
    if (!started && !std::isfinite(pending_start_lat) && !gnss_has_nav()) start(f.lat_deg, f.lon_deg, sigma, f.t_ns);
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
    if (first_utc_ms != kMissingInt && started) pdr.set_location(start_position, first_utc_ms);
  }

  void feed(const Sample& s) {
    if (!in_order(s)) return;
    note_utc(s);
    std::visit(
        [&](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, AccelSample> || std::is_same_v<T, GyroSample> || std::is_same_v<T, MagSample> ||
                        std::is_same_v<T, RotationVectorSample> || std::is_same_v<T, StepDetectorSample>) {
            pdr.feed(x);
            drain_pdr();
          } else if constexpr (std::is_same_v<T, PressureSample>) {
            maybe_start(x.t_ns);
            if (terrain && started) terrain->feed(x);
          } else if constexpr (std::is_same_v<T, GnssRawSample> || std::is_same_v<T, NavMessageSample>) {
            if (gnss) {
              gnss->feed(x);
              drain_gnss();
            }
          } else if constexpr (std::is_same_v<T, FixSample>) {
            on_fix(x);
          } else if constexpr (std::is_same_v<T, MetaSample>) {
            on_meta(x);
          }
        },
        s);
  }

  Estimate choose() const {
    if (gnss && wants(cfg.mode, EngineMode::kGnss)) {
      Estimate g = gnss->estimate();
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
    Estimate d = dr.estimate();
    if (d.valid()) d.reason = std::string(why) + "dead reckoning";
    return d;
  }
};

Navigator::Navigator(const NavigatorConfig& config, std::uint64_t seed) : impl_(std::make_unique<Impl>(config, seed)) {}
Navigator::~Navigator() = default;
Navigator::Navigator(Navigator&&) noexcept = default;
Navigator& Navigator::operator=(Navigator&&) noexcept = default;

void Navigator::feed(const Sample& s) { impl_->feed(s); }

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
  if (impl_->gnss) o.engines.push_back(impl_->gnss->estimate());
  return o;
}

std::vector<std::pair<std::string, std::int64_t>> Navigator::ignored() const {
  return {impl_->ignored.begin(), impl_->ignored.end()};
}

}  // namespace pdnav::fusion
