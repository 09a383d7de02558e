// World error models (docs/simulator.md).
#include "pdnav/sim/world.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "pdnav/geo/baro.h"

namespace pdnav::sim {

double uniform(Rng& rng, double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
double gauss(Rng& rng, double sd) { return sd > 0.0 ? std::normal_distribution<double>(0.0, sd)(rng) : 0.0; }

std::vector<Interval> poisson_intervals(double rate_per_s, double min_s, double max_s, double total_s, Rng& rng) {
  std::vector<Interval> out;
  if (!(rate_per_s > 0.0) || !(total_s > 0.0)) return out;
  double t = 0.0;
  while (true) {
    t += std::exponential_distribution<double>(rate_per_s)(rng);
    if (t > total_s) break;
    const double dur = uniform(rng, min_s, std::max(min_s, max_s) + 1e-9);
    out.push_back({t, t + dur});
    t += dur;
  }
  return out;
}

Eigen::Vector4d chest_mount_quat_xyzw(double heading_rad) {
  const double sh = std::sin(heading_rad), ch = std::cos(heading_rad);
  Eigen::Matrix3d r;  // columns: phone X, Y, Z in ENU
  r.col(0) = Eigen::Vector3d(ch, -sh, 0.0);
  r.col(1) = Eigen::Vector3d(0.0, 0.0, 1.0);
  r.col(2) = Eigen::Vector3d(-sh, -ch, 0.0);
  const Eigen::Quaterniond q(r);
  return Eigen::Vector4d(q.x(), q.y(), q.z(), q.w());
}

// ---------------------------------------------------------------- heading
HeadingError::HeadingError(const HeadingErrorOptions& o, std::vector<MagneticAnomaly> anomalies, Rng& rng)
    : o_(o), anomalies_(std::move(anomalies)) {
  mount_rad_ = gauss(rng, o_.mount_sigma_rad);
  next_shift_s_ = o_.shift_rate_per_s > 0 ? std::exponential_distribution<double>(o_.shift_rate_per_s)(rng) : 1e300;
}

double HeadingError::anomaly_at(const Eigen::Vector2d& p) const {
  double sum = 0.0;
  for (const MagneticAnomaly& a : anomalies_) {
    const double d2 = (p - a.at_en_m).squaredNorm();
    const double r2 = a.radius_m * a.radius_m;
    if (d2 < 16.0 * r2) sum += a.peak_rad * std::exp(-0.5 * d2 / r2);
  }
  return sum;
}

double HeadingError::advance(double t_s, const Eigen::Vector2d& p, Rng& rng) {
  const double dt = std::max(0.0, t_s - t_last_s_);
  t_last_s_ = std::max(t_last_s_, t_s);
  walk_rad_ += gauss(rng, o_.random_walk_rad_per_sqrt_s * std::sqrt(dt));
  while (t_s >= next_shift_s_) {
    mount_rad_ = gauss(rng, o_.shift_sigma_rad);
    ++shifts_;
    next_shift_s_ += std::exponential_distribution<double>(o_.shift_rate_per_s)(rng);
  }
  const double a = o_.fusion_lag_s > 0 ? 1.0 - std::exp(-dt / o_.fusion_lag_s) : 1.0;
  anomaly_lp_rad_ += a * (anomaly_at(p) - anomaly_lp_rad_);
  return bias_rad() + gauss(rng, o_.sway_noise_rad);
}

std::vector<MagneticAnomaly> anomalies_along(const std::vector<Eigen::Vector2d>& path, double per_km,
                                             const HeadingErrorOptions& o, Rng& rng) {
  std::vector<MagneticAnomaly> out;
  if (path.size() < 2 || !(per_km > 0.0)) return out;
  for (std::size_t k = 0; k + 1 < path.size(); ++k) {
    const Eigen::Vector2d d = path[k + 1] - path[k];
    const double len = d.norm();
    if (len < 1e-6) continue;
    const Eigen::Vector2d u = d / len, left(-u.y(), u.x());
    double s = std::exponential_distribution<double>(per_km / 1000.0)(rng);
    for (; s < len; s += std::exponential_distribution<double>(per_km / 1000.0)(rng)) {
      MagneticAnomaly a;
      const double side = uniform(rng, 3.0, 20.0) * (uniform(rng, 0, 1) < 0.5 ? -1.0 : 1.0);
      a.at_en_m = path[k] + s * u + side * left;
      a.radius_m = uniform(rng, o.anomaly_radius_min_m, o.anomaly_radius_max_m);
      a.peak_rad = gauss(rng, o.anomaly_sigma_rad);
      out.push_back(a);
    }
  }
  return out;
}

// ---------------------------------------------------------------- stride
Stride::Stride(const StrideOptions& o, double nominal_m, Rng& rng) : o_(o), nominal_m_(nominal_m) {
  scale_ = std::clamp(1.0 + gauss(rng, o_.stride_sd), 0.75, 1.25);
  cadence_hz_ = uniform(rng, o_.cadence_min_hz, o_.cadence_max_hz);
}

double Stride::length_m(double t_s, double grade, Rng& rng) const {
  const double g = std::clamp(grade, -0.6, 0.6);
  const double slope = 1.0 - (g > 0 ? o_.uphill_per_grade * g : -o_.downhill_per_grade * g);
  const double fatigue = 1.0 - o_.fatigue_per_hour * std::max(0.0, t_s) / 3600.0;
  const double l = nominal_m_ * scale_ * std::max(0.4, slope) * std::max(0.7, fatigue) * (1.0 + gauss(rng, o_.step_cv));
  return std::max(0.2, l);
}

double Stride::period_s(double grade, Rng& rng) const {
  const double slow = 1.0 + 0.3 * std::min(0.6, std::abs(grade));  // cadence drops on steep grades
  return std::max(0.3, slow * (1.0 + gauss(rng, o_.cadence_cv)) / cadence_hz_);
}

// ---------------------------------------------------------------- barometer
BaroWorld::BaroWorld(const BaroWorldOptions& o, double total_s, Rng& rng) : o_(o) {
  const double change = uniform(rng, o_.trend_min_pa, o_.trend_max_pa) * (uniform(rng, 0, 1) < 0.5 ? -1.0 : 1.0);
  rate_pa_per_s_ = change / o_.trend_window_s;
  tide_phase_ = uniform(rng, 0.0, 2.0 * kPi);
  offset_pa_ = gauss(rng, o_.offset_sigma_pa);
  temp_offset_k_ = gauss(rng, o_.temperature_offset_sd_k);
  for (const Interval& iv : poisson_intervals(o_.gust_rate_per_s, o_.gust_min_s, o_.gust_max_s, total_s, rng)) {
    const double v = uniform(rng, 2.0, std::max(2.0, o_.gust_speed_max_mps));
    const double q = 0.5 * 1.1 * v * v;  // dynamic pressure, air density ~1.1 kg/m^3 at 1-2 km
    gusts_.push_back({iv.start_s, iv.end_s - iv.start_s, uniform(rng, 0, 1) < 0.5 ? -q : q});
  }
}

double BaroWorld::weather_pa(double t_s) const {
  constexpr double kTideS = 12.0 * 3600.0;
  return rate_pa_per_s_ * t_s + o_.tide_amplitude_pa * (std::sin(2 * kPi * t_s / kTideS + tide_phase_) - std::sin(tide_phase_));
}

double BaroWorld::pressure_pa(double t_s, double h_m, Rng& rng) const {
  geo::BaroOptions atm;
  atm.ref_temperature_k += temp_offset_k_;
  double gust = 0.0;
  for (const Gust& g : gusts_)
    if (t_s >= g.start && t_s < g.start + g.dur) gust += g.amp * std::sin(kPi * (t_s - g.start) / g.dur);
  const double p = geo::baro_pressure_pa(h_m, 101325.0 + weather_pa(t_s), 0.0, atm) + gust + offset_pa_ +
                   gauss(rng, o_.noise_pa);
  return o_.quantum_pa > 0 ? std::round(p / o_.quantum_pa) * o_.quantum_pa : p;
}

// ---------------------------------------------------------------- DEM error
double DemError::Field::at(double e, double n) const {
  const double fx = std::clamp((e - x0) / cell, 0.0, cols - 1.001);
  const double fy = std::clamp((n - y0) / cell, 0.0, rows - 1.001);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  // Smoothstep weights: C1-continuous surface between the Gaussian nodes.
  auto s = [](double t) { return t * t * (3.0 - 2.0 * t); };
  const double tx = s(fx - ix), ty = s(fy - iy);
  auto g = [&](int i, int j) { return v[static_cast<std::size_t>(j) * cols + static_cast<std::size_t>(i)]; };
  return (1 - ty) * ((1 - tx) * g(ix, iy) + tx * g(ix + 1, iy)) + ty * ((1 - tx) * g(ix, iy + 1) + tx * g(ix + 1, iy + 1));
}

DemError::Field DemError::make_field(double min_e, double min_n, double max_e, double max_n, double corr, Rng& rng) {
  Field f;
  f.x0 = min_e;
  f.y0 = min_n;
  f.cell = std::max(corr, 1.0);
  f.cols = static_cast<int>((max_e - min_e) / f.cell) + 2;
  f.rows = static_cast<int>((max_n - min_n) / f.cell) + 2;
  if (f.cols <= 0 || f.rows <= 0 || static_cast<double>(f.cols) * f.rows > 5e7)
    throw std::invalid_argument("DemError: extent or correlation length out of range");
  f.v.resize(static_cast<std::size_t>(f.cols) * static_cast<std::size_t>(f.rows));
  for (double& x : f.v) x = gauss(rng, 1.0);
  return f;
}

DemError::DemError(const DemErrorOptions& o, double min_e, double min_n, double max_e, double max_n,
                   std::function<double(double, double)> slope_deg, std::function<double(double, double)> dem_m,
                   Rng& rng)
    : o_(o), slope_deg_(std::move(slope_deg)), dem_m_(std::move(dem_m)) {
  long_ = make_field(min_e, min_n, max_e, max_n, o_.long_corr_m, rng);
  short_ = make_field(min_e, min_n, max_e, max_n, o_.short_corr_m, rng);
  forest_ = make_field(min_e, min_n, max_e, max_n, o_.forest_corr_m, rng);
  // Threshold of the (smoothed, roughly Gaussian, variance < 1) forest field for the fraction.
  std::vector<double> sample;
  for (int k = 0; k < 2000; ++k) sample.push_back(forest_.at(uniform(rng, min_e, max_e), uniform(rng, min_n, max_n)));
  std::sort(sample.begin(), sample.end());
  const double frac = std::clamp(o_.forest_fraction, 0.0, 1.0);
  forest_threshold_ = frac <= 0.0 ? 1e300 : sample[static_cast<std::size_t>((1.0 - frac) * static_cast<double>(sample.size() - 1))];
}

bool DemError::forest(double e, double n) const {
  if (dem_m_ && dem_m_(e, n) > o_.tree_line_m) return false;
  return forest_.at(e, n) > forest_threshold_;
}

double DemError::error_m(double e, double n) const {
  const double slope = slope_deg_ ? std::max(0.0, slope_deg_(e, n)) : 0.0;
  const double short_sd = std::min(o_.short_max_m, o_.short_base_m + o_.short_per_deg * slope);
  double err = o_.long_sigma_m * long_.at(e, n) + short_sd * short_.at(e, n);
  if (forest(e, n)) err += o_.canopy_bias_m;
  return err;
}

}  // namespace pdnav::sim
