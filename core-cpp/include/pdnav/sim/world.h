// World error models of the simulators (issue 17): what a phone and a DEM really do wrong,
// drawn from sensor and DEM literature, deliberately NOT the filters' own models (the terrain
// PF and the DR EKF assume a first-order Gauss-Markov heading bias of 15 deg / 60 s, a FOGM
// baro bias, uniform step-length noise and white DEM error; the GNSS KF assumes white noise).
// Every model, its source and how it differs from the filters: docs/simulator.md.
// Seeded (std::mt19937_64), no global state, no file I/O.
#pragma once
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/units.h"

namespace pdnav::sim {

using Rng = std::mt19937_64;

double uniform(Rng& rng, double a, double b);
double gauss(Rng& rng, double sd);

/// Orientation (unit quaternion x, y, z, w, phone -> ENU) of a chest-mounted phone, top edge up,
/// camera forward, walking at `heading_rad` clockwise from north: phone -Z = forward =
/// (sin h, cos h, 0), +Y = up, +X = forward x up. What an ideal rotation vector reports.
Eigen::Vector4d chest_mount_quat_xyzw(double heading_rad);

/// Rotation-vector heading error of a chest-worn phone: a slow random walk of the fused
/// gyro/magnetometer yaw, piecewise-constant bias steps whenever the phone shifts in its
/// holder, and spatial magnetic anomalies around structures (steel, cars, pylons) that the
/// sensor fusion passes with a lag. None of it is first-order Gauss-Markov.
struct HeadingErrorOptions {
  double mount_sigma_rad = 4.0 * kDegToRad;          // initial holder misalignment (per walk)
  double random_walk_rad_per_sqrt_s = 0.08 * kDegToRad;  // yaw drift of the fused rotation vector
  double shift_rate_per_s = 1.0 / 300.0;             // phone shifts on the chest (Poisson)
  double shift_sigma_rad = 5.0 * kDegToRad;          // new misalignment after a shift ~ N(0, s)
  double anomaly_sigma_rad = 25.0 * kDegToRad;       // peak deflection of a structure ~ N(0, s)
  double anomaly_radius_min_m = 4.0;                 // Gaussian footprint radius ~ U(min, max)
  double anomaly_radius_max_m = 15.0;
  double fusion_lag_s = 2.0;                         // Android fusion: mag disturbance low-pass
  double sway_noise_rad = 1.5 * kDegToRad;           // white body-sway noise per reading
};

/// A magnetic anomaly: Gaussian deflection footprint around a structure (local ENU metres).
struct MagneticAnomaly {
  Eigen::Vector2d at_en_m = Eigen::Vector2d::Zero();
  double radius_m = 10.0;
  double peak_rad = 0.0;
};

class HeadingError {
 public:
  HeadingError(const HeadingErrorOptions& o, std::vector<MagneticAnomaly> anomalies, Rng& rng);
  /// Error (rad, added to the true heading) at time t_s (non-decreasing) and position p.
  double advance(double t_s, const Eigen::Vector2d& p_en_m, Rng& rng);
  /// The slowly varying part (mount + random walk + filtered anomaly), without sway: the
  /// "heading bias" a calibration can estimate.
  double bias_rad() const { return mount_rad_ + walk_rad_ + anomaly_lp_rad_; }
  double anomaly_at(const Eigen::Vector2d& p_en_m) const;
  std::size_t shifts() const { return shifts_; }

 private:
  HeadingErrorOptions o_;
  std::vector<MagneticAnomaly> anomalies_;
  double t_last_s_ = 0.0, next_shift_s_ = 0.0;
  double mount_rad_ = 0.0, walk_rad_ = 0.0, anomaly_lp_rad_ = 0.0;
  std::size_t shifts_ = 0;
};

/// Structures along a polyline: `per_km` of them (Poisson), beside the path at 3-20 m.
std::vector<MagneticAnomaly> anomalies_along(const std::vector<Eigen::Vector2d>& path_en_m, double per_km,
                                             const HeadingErrorOptions& o, Rng& rng);

/// True step length of a walker: own stride, shorter on slopes (uphill more than downhill,
/// Kawamura et al. 1991), shorter with fatigue, step-to-step variability (Hausdorff 2005).
struct StrideOptions {
  double stride_sd = 0.06;            // walker's stride vs the APT height model l = 0.415 h (per walk)
  double uphill_per_grade = 0.8;      // relative shortening per unit grade uphill (12 % -> -9.6 %)
  double downhill_per_grade = 0.5;    // ... downhill
  double fatigue_per_hour = 0.03;     // relative shortening per hour of walking
  double step_cv = 0.03;              // step-to-step coefficient of variation (white)
  double cadence_min_hz = 1.65, cadence_max_hz = 1.95;  // per walk
  double cadence_cv = 0.04;
};

class Stride {
 public:
  /// nominal_m: the APT model's step for the user's height (0.415 h).
  Stride(const StrideOptions& o, double nominal_m, Rng& rng);
  /// Length (m) of the next step at elapsed time t_s on grade `grade` (dh/ds, signed).
  double length_m(double t_s, double grade, Rng& rng) const;
  double period_s(double grade, Rng& rng) const;
  double walker_scale() const { return scale_; }  // true stride / model stride (flat, rested)

 private:
  StrideOptions o_;
  double nominal_m_, scale_, cadence_hz_;
};

/// Barometer: the weather's pressure trend (synoptic change of 0.5-3 hPa over 3 h and the
/// semidiurnal atmospheric tide, ~0.5 hPa at mid-latitudes, Dai & Wang 1999), wind gusts
/// (dynamic pressure 1/2 rho v^2), a per-walk sensor offset, white noise and quantisation
/// (Bosch BMP280 datasheet: +-1 hPa absolute, 1.3 Pa rms noise; Android reports 0.01 hPa).
struct BaroWorldOptions {
  double trend_min_pa = 50.0, trend_max_pa = 300.0;  // |change| over trend_window_s
  double trend_window_s = 3.0 * 3600.0;
  double tide_amplitude_pa = 50.0;                   // S2 tide, 12 h period, random phase
  double gust_rate_per_s = 1.0 / 90.0;
  double gust_speed_max_mps = 8.0;                   // gust speed ~ U(2, max), +-dynamic pressure
  double gust_min_s = 1.0, gust_max_s = 8.0;
  double offset_sigma_pa = 60.0;                     // sensor absolute error (per walk)
  double noise_pa = 1.5;
  double quantum_pa = 1.0;                           // 0.01 hPa
  double temperature_offset_sd_k = 5.0;              // day vs ISA
};

class BaroWorld {
 public:
  BaroWorld(const BaroWorldOptions& o, double total_s, Rng& rng);
  /// Measured pressure (Pa) at time t_s for the phone at true height h_m.
  double pressure_pa(double t_s, double h_m, Rng& rng) const;
  /// The weather part only (Pa, relative to t = 0), for tests.
  double weather_pa(double t_s) const;

 private:
  BaroWorldOptions o_;
  double rate_pa_per_s_ = 0.0, tide_phase_ = 0.0, offset_pa_ = 0.0, temp_offset_k_ = 0.0;
  struct Gust { double start, dur, amp; };
  std::vector<Gust> gusts_;
};

/// SRTM-like DEM error: DEM = true ground + e. Long-wavelength correlated error (Rodriguez
/// et al. 2006: Eurasia 90 % absolute error 6.2 m), a short-wavelength part that grows with
/// slope (Falorni et al. 2005; Gorokhovich & Voustianiouk 2006), and forest canopy: C-band
/// returns from within the canopy, a positive bias of about half the tree height (Carabajal &
/// Harding 2006). The forest mask is itself a correlated random field below the tree line.
struct DemErrorOptions {
  double long_sigma_m = 3.0, long_corr_m = 2000.0;
  double short_base_m = 1.5, short_per_deg = 0.25, short_max_m = 15.0, short_corr_m = 150.0;
  double forest_fraction = 0.35;      // of the area below the tree line
  double forest_corr_m = 600.0;
  double tree_line_m = 2200.0;        // Pyrenees
  double canopy_bias_m = 8.0;         // ~ half of 15-20 m canopies
};

class DemError {
 public:
  /// Over [min_e, max_e] x [min_n, max_n]; slope_deg(e, n) and dem_m(e, n) describe the DEM.
  DemError(const DemErrorOptions& o, double min_e, double min_n, double max_e, double max_n,
           std::function<double(double, double)> slope_deg, std::function<double(double, double)> dem_m, Rng& rng);
  /// e = DEM - true ground (m) at (e, n).
  double error_m(double e, double n) const;
  bool forest(double e, double n) const;

 private:
  struct Field {
    double x0 = 0, y0 = 0, cell = 1;
    int cols = 0, rows = 0;
    std::vector<double> v;
    double at(double e, double n) const;
  };
  static Field make_field(double min_e, double min_n, double max_e, double max_n, double corr, Rng& rng);
  DemErrorOptions o_;
  Field long_, short_, forest_;
  double forest_threshold_ = 0.0;
  std::function<double(double, double)> slope_deg_, dem_m_;
};

/// Poisson events with a duration, for gusts, shifts and segments: [start, start + dur).
struct Interval { double start_s = 0.0, end_s = 0.0; };
std::vector<Interval> poisson_intervals(double rate_per_s, double min_s, double max_s, double total_s, Rng& rng);

}  // namespace pdnav::sim
