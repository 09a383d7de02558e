// Phone-session simulator (issue 14): a whole session as the phone records it, walking the
// real OSM walkway graph over the real DEM: Accel/Gyro (50 Hz), RotationVector (10 Hz),
// Pressure (5 Hz), StepDetector events, GNSS `Raw` rows generated from real broadcast
// ephemeris with the world's errors, chipset-like `Fix` rows and `Truth` rows, with a scripted
// GNSS outage and degraded segments. Error models: pdnav/sim/world.h and docs/simulator.md
// (none of them is a filter's own model). Seeded, reproducible, no file I/O.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/samples.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/route/walk_graph.h"
#include "pdnav/sim/world.h"
#include "pdnav/terrain/dem.h"

namespace pdnav::phonesim {

/// GNSS world errors (docs/simulator.md "GNSS"). Defaults from phone measurements in the
/// literature (Zhang et al. 2018, Robustelli et al. 2019, Humphreys et al. 2016).
struct GnssWorldOptions {
  double cn0_zenith_dbhz = 43.0;        // chest-worn phone, open sky, zenith
  double cn0_horizon_dbhz = 28.0;       // ... at 0 deg elevation (antenna gain roll-off)
  double body_block_db = 9.0;           // signals from behind the walker (|az - heading| > 120 deg)
  double cn0_fading_db = 1.5;           // per-epoch scintillation/fading (white, dB)
  double track_min_cn0_dbhz = 18.0;     // below: the chipset loses the signal
  double code_sigma_at_40_m = 2.0;      // code noise 1-sigma at 40 dB-Hz, scales 10^(-(C/N0-40)/20)
  double reported_sigma_factor = 0.9;   // chipset's ReceivedSvTimeUncertainty vs real white noise
  double multipath_open_m = 1.2;        // quasi-periodic code multipath amplitude at low elevation
  double multipath_degraded_m = 4.0;
  double nlos_probability = 0.4;        // per satellite below 45 deg, per 30 s, in degraded segments
  double nlos_min_m = 5.0, nlos_max_m = 45.0;
  double nlos_cn0_loss_db = 8.0;
  double foliage_loss_db = 7.0;         // forest (from the DEM error's forest mask)
  double urban_loss_db = 6.0;           // degraded "urban" segments
  double iono_scale_sd = 0.35;          // true iono = Klobuchar x N(1, sd) (Klobuchar removes ~50 %)
  // ... plus a horizontal gradient of the vertical delay across the pierce points, N(0, sd) per
  // axis per session (m per km), which a Klobuchar-shaped error lacks: it biases the horizontal
  // fix for minutes (0 = off; docs/simulator.md "GNSS").
  double iono_gradient_sd_m_per_km = 0.5e-3;
  double tropo_scale_sd = 0.05;
  double orbit_clock_sd_m = 0.7;        // broadcast orbit+clock error per satellite (SISRE)
  double clock_drift_sd_nsps = 80.0;    // hardware clock drift d0 ~ N(0, sd), ns/s
  double clock_drift_walk_nsps_per_sqrt_s = 0.05;
  double clock_bias_est_sd_ns = 15.0;   // chipset's FullBias estimate error (smooth)
  double adr_noise_at_40_m = 0.003;
  double cycle_slip_per_epoch_at_30 = 0.01;  // scales 10^(-(C/N0-30)/10)
  double undetected_slip_fraction = 0.1;
  double adr_min_cn0_dbhz = 24.0;
  double terrain_mask_margin_rad = 1.0 * kDegToRad;  // diffraction band around the horizon
  double fix_error_open_m = 2.5;        // chipset fix: low-passed error, 1-sigma per axis
  double fix_error_degraded_m = 10.0;
  double fix_tau_s = 8.0;
  double reacquire_min_s = 1.0, reacquire_max_s = 6.0;  // per satellite after an outage
};

struct SessionOptions {
  double lead_s = 360.0;                // open-sky GNSS before the outage (calibration)
  double outage_min_s = 120.0;          // scripted outage duration ~ U(min, max)
  double outage_max_s = 1200.0;
  double tail_s = 180.0;                // after the outage
  int degraded_segments = 2;            // per walk, outside the outage and the first 120 s
  double degraded_min_s = 45.0, degraded_max_s = 150.0;
  double user_height_m = 1.75;          // written to Meta; the APT model uses it
  double imu_rate_hz = 50.0;
  double rotation_rate_hz = 10.0;
  double baro_rate_hz = 5.0;
  double gnss_rate_hz = 1.0;
  double anomalies_per_km_urban = 12.0; // magnetic structures along urban ways (roads, streets)
  double anomalies_per_km_rural = 1.0;  // ... along paths and tracks
  double edge_margin_m = 1500.0;        // path stays this far inside the DEM tile
  double phone_height_m = 1.3;          // above the ground (chest)
  bool write_accel_gyro = true;
  bool declare_start = false;           // Meta start lines (default: the Navigator starts from GNSS)
  sim::HeadingErrorOptions heading;
  sim::StrideOptions stride;
  sim::BaroWorldOptions baro;
  sim::DemErrorOptions dem_error;
  GnssWorldOptions gnss;
};

/// One truth epoch per step, in the DEM tile's local ENU frame.
struct TruthPoint {
  TimeNs t_ns = 0;
  Eigen::Vector2d en_m = Eigen::Vector2d::Zero();
  double h_m = 0.0;
  double heading_rad = 0.0;
  bool outage = false, degraded = false;
};

struct SessionStats {
  double length_m = 0.0, duration_s = 0.0;
  double walker_stride_scale = 1.0;     // true stride / APT model (flat, rested)
  double heading_bias_at_outage_deg = 0.0;  // slowly varying heading error at the outage start
  double mean_sats_tracked = 0.0;       // over epochs with GNSS
  std::int64_t gnss_epochs = 0, raw_rows = 0, fix_rows = 0, steps = 0;
  std::int64_t masked_by_terrain = 0, nlos_rows = 0, cycle_slips = 0, phone_shifts = 0;
  double forest_fraction = 0.0;         // of the steps
  Eigen::Vector2d iono_gradient_m_per_km = Eigen::Vector2d::Zero();  // east, north (GnssWorldOptions)
};

struct PhoneSession {
  std::uint64_t seed = 0;
  std::vector<Sample> samples;          // time ordered (Meta first)
  std::vector<TruthPoint> truth;
  TimeNs outage_start_ns = 0, outage_end_ns = 0;
  std::vector<std::pair<TimeNs, TimeNs>> degraded;
  TimeNs gps_start_ns = 0;              // GPS time of the first sample
  SessionStats stats;
};

/// The whole session. Throws std::runtime_error with the reason when no walk fits (graph
/// outside the tile, no ephemeris at any time of the nav files' span, ...).
PhoneSession simulate_session(const terrain::Dem& dem, const route::WalkGraph& graph,
                              const gnss::EphemerisStore& eph, const SessionOptions& options, std::uint64_t seed);

/// Unix time of the ephemeris's day used for the session (GPS time -> UTC), for Meta lines.
std::int64_t session_unix_ms(const PhoneSession& s, TimeNs t_ns);

}  // namespace pdnav::phonesim
