// fusion::Navigator: the single entry point of the core for the app (JNI), the replay CLI
// and the tests. Feed it the time-ordered sample stream; ask it for the estimate.
// It runs PDR on the inertial samples and hands steps/turns/pressure/GNSS to the engines,
// and picks the estimate to show (GNSS when healthy, else route, else terrain, else DR).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pdnav/geo/estimate.h"
#include "pdnav/geo/samples.h"
#include "pdnav/pdr/heading.h"

namespace pdnav::terrain { class Dem; }
namespace pdnav::route { class WalkGraph; }
namespace pdnav::gnss { class EphemerisStore; }

namespace pdnav::fusion {

enum class EngineMode { kAuto, kDeadReckoning, kTerrain, kRoute, kGnss };
EngineMode engine_mode_from_string(const std::string& s);  // "auto", "dr", "terrain", "route", "gnss"; throws std::invalid_argument
const char* to_string(EngineMode m);

inline constexpr double kDefaultUserHeightM = 1.75;

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
  /// mount overrides both (the default keeps the app's chest mount; `pdnav replay` uses auto).
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
  /// Errors here are thrown from the constructor (std::runtime_error with file and reason).
};

/// Everything a UI or replay wants after each update.
struct NavigatorOutput {
  Estimate estimate;                       // the one shown
  std::vector<Estimate> engines;           // every running engine's own estimate
  std::int64_t steps = 0;                  // steps detected so far
  std::vector<Eigen::Vector2d> particles_en_m;  // a thinned particle cloud (terrain), may be empty
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
  /// Declare or reset the start position (e.g. user long-press on the map).
  void set_start(double lat_deg, double lon_deg, double sigma_m, TimeNs t_ns);

  Estimate estimate() const;
  NavigatorOutput output(std::size_t max_particles = 200) const;
  /// Samples ignored so far, by reason.
  std::vector<std::pair<std::string, std::int64_t>> ignored() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pdnav::fusion
