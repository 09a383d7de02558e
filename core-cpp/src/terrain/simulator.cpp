// Walk simulator and evaluation (docs/terrain.md "Simulator").
#include "pdnav/terrain/simulator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "fast_math.h"
#include "pdnav/geo/baro.h"

namespace pdnav::terrain {
namespace {

using Rng = std::mt19937_64;

double uniform(Rng& rng, double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
double gauss(Rng& rng, double sd) { return std::normal_distribution<double>(0.0, sd)(rng); }

/// Smooth, spatially correlated DEM error: Gaussian node values every corr_m, bilinear.
class ErrorField {
 public:
  ErrorField(const Dem& dem, double sigma_m, double corr_m, Rng& rng)
      : x0_(dem.min_e_m()), y0_(dem.min_n_m()), cell_(std::max(corr_m, 1.0)) {
    cols_ = static_cast<int>((dem.max_e_m() - x0_) / cell_) + 2;
    rows_ = static_cast<int>((dem.max_n_m() - y0_) / cell_) + 2;
    v_.resize(static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_));
    for (double& x : v_) x = sigma_m > 0 ? gauss(rng, sigma_m) : 0.0;
  }
  double at(double e, double n) const {
    const double fx = std::clamp((e - x0_) / cell_, 0.0, cols_ - 1.001);
    const double fy = std::clamp((n - y0_) / cell_, 0.0, rows_ - 1.001);
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const double tx = fx - ix, ty = fy - iy;
    auto g = [&](int i, int j) { return v_[static_cast<std::size_t>(j) * cols_ + static_cast<std::size_t>(i)]; };
    return (1 - ty) * ((1 - tx) * g(ix, iy) + tx * g(ix + 1, iy)) + ty * ((1 - tx) * g(ix, iy + 1) + tx * g(ix + 1, iy + 1));
  }

 private:
  double x0_, y0_, cell_;
  int cols_ = 0, rows_ = 0;
  std::vector<double> v_;
};

/// A bump process: events at a Poisson rate, each a half-sine of random amplitude/duration.
class BumpProcess {
 public:
  BumpProcess(double rate_per_s, double max_amp, double min_s, double max_s, double total_s, Rng& rng) {
    if (rate_per_s <= 0 || max_amp <= 0) return;
    double t = 0;
    while (true) {
      t += std::exponential_distribution<double>(rate_per_s)(rng);
      if (t > total_s) break;
      const double dur = uniform(rng, min_s, max_s);
      events_.push_back({t, dur, uniform(rng, -max_amp, max_amp)});
      t += dur;
    }
  }
  double at(double t) const {
    for (const auto& ev : events_)
      if (t >= ev.start && t < ev.start + ev.dur) return ev.amp * std::sin(kPi * (t - ev.start) / ev.dur);
    return 0.0;
  }

 private:
  struct Event { double start, dur, amp; };
  std::vector<Event> events_;
};

/// First-order Gauss-Markov process sampled at increasing times (exact discretisation).
class Fogm {
 public:
  Fogm(double sigma, double tau_s, Rng& rng) : sigma_(sigma), tau_(tau_s), x_(gauss(rng, sigma)) {}
  double advance(double dt_s, Rng& rng) {
    const double phi = std::exp(-std::max(dt_s, 0.0) / tau_);
    x_ = phi * x_ + gauss(rng, sigma_ * std::sqrt(1 - phi * phi));
    return x_;
  }

 private:
  double sigma_, tau_, x_;
};

struct RoutePoint { double e, n, heading; };

bool leg_ok(const Dem& dem, const WalkSimOptions& o, double e, double n, double heading, double len) {
  const double margin = o.edge_margin_m;
  double prev = dem.at_local(e, n).elevation_m;
  for (double s = 10.0; s <= len + 1e-9; s += 10.0) {
    const double x = e + s * std::sin(heading), y = n + s * std::cos(heading);
    if (x < dem.min_e_m() + margin || x > dem.max_e_m() - margin || y < dem.min_n_m() + margin ||
        y > dem.max_n_m() - margin)
      return false;
    const DemSample h = dem.at_local(x, y);
    if (!h.valid() || std::abs(h.elevation_m - prev) > o.max_slope * 10.0) return false;
    prev = h.elevation_m;
  }
  return true;
}

/// Legs of 40-300 m with random turns, staying inside the tile and off cliffs.
std::vector<RoutePoint> make_route(const Dem& dem, const WalkSimOptions& o, double target_m, Rng& rng) {
  const double m = o.edge_margin_m;
  if (dem.max_e_m() - dem.min_e_m() < 2 * m + 100 || dem.max_n_m() - dem.min_n_m() < 2 * m + 100)
    throw std::runtime_error("simulate: DEM tile too small for the edge margin");
  for (int attempt = 0; attempt < 200; ++attempt) {
    std::vector<RoutePoint> route;
    double e = uniform(rng, dem.min_e_m() + m, dem.max_e_m() - m);
    double n = uniform(rng, dem.min_n_m() + m, dem.max_n_m() - m);
    if (!dem.at_local(e, n).valid()) continue;
    double heading = uniform(rng, 0, 2 * kPi), walked = 0;
    route.push_back({e, n, heading});
    while (walked < target_m) {
      const double len = std::min(uniform(rng, 40, 300), target_m - walked + 1.0);
      bool found = false;
      for (int k = 0; k < 40 && !found; ++k) {
        const double turn = k < 20 ? gauss(rng, 60 * kDegToRad) : uniform(rng, -kPi, kPi);
        const double h = wrap_two_pi(heading + turn);
        if (leg_ok(dem, o, e, n, h, len)) {
          heading = h;
          found = true;
        }
      }
      if (!found) break;
      e += len * std::sin(heading);
      n += len * std::cos(heading);
      walked += len;
      route.push_back({e, n, heading});
    }
    if (walked >= target_m) return route;
  }
  throw std::runtime_error("simulate: no walkable route of " + std::to_string(target_m) +
                           " m found (tile too small, too steep or too many voids)");
}

}  // namespace

std::uint64_t walk_seed(std::uint64_t base_seed, std::uint64_t k) {
  std::uint64_t x = base_seed * 0x100000001B3ULL + k;
  return detail::splitmix64(x);
}

namespace {

/// What a step of the walk is: its period and true length.
struct StepMotion { double dt_s, len_m; };

/// The earlier filter-like error models (docs/terrain.md): FOGM heading and baro bias, magnetic
/// disturbance and gust bumps, a smooth DEM error field, a per-walk step length and scale error.
/// Members are drawn from the walk's generator in declaration order (the walk's seed fixes them).
class FilterModels {
 public:
  FilterModels(const Dem& dem, const WalkSimOptions& o, double target_m, const std::vector<RoutePoint>& /*route*/,
               Rng& rng)
      : dem_(dem),
        o_(o),
        dem_error_(dem, o.dem_error_sigma_m, o.dem_error_corr_m, rng),
        expected_s_(target_m / o.step_length_mean_m / o.step_rate_hz * 1.3 + 60.0),
        disturbance_(o.disturbance_rate_per_s, o.disturbance_max_rad, o.disturbance_min_s, o.disturbance_max_s,
                     expected_s_, rng),
        gusts_(o.gust_rate_per_s, o.gust_max_pa, o.gust_min_s, o.gust_max_s, expected_s_, rng),
        heading_bias_(o.heading_bias_sigma_rad, o.heading_bias_tau_s, rng),
        baro_bias_(o.baro_bias_sigma_m, o.baro_bias_tau_s, rng),
        drift_pa_per_s_(gauss(rng, o.weather_drift_sd_pa_per_h) / 3600.0),
        walk_step_m_(std::max(0.4, o.step_length_mean_m + gauss(rng, o.step_length_walk_sd_m))),
        scale_error_(gauss(rng, o.length_scale_error_sd)) {
    // The day's atmosphere: ISA lapse rate, warmer or colder.
    atmosphere_.ref_temperature_k += gauss(rng, o.temperature_offset_sd_k);
  }
  /// After the declared start is drawn: the baro bias's first sample.
  void start(Rng& rng) { bias_m_ = baro_bias_.advance(0.0, rng); }
  /// Each loop pass draws the step period first, even on a pass that only moves to the next leg.
  void begin_pass(Rng& rng) {
    dt_s_ = std::max(0.2, (1.0 + gauss(rng, o_.step_period_jitter)) / o_.step_rate_hz);
  }
  StepMotion motion(double /*e*/, double /*n*/, double /*heading*/, double /*t_s*/, double dist, Rng& rng) {
    return {dt_s_, std::min(dist, std::max(0.3, walk_step_m_ + gauss(rng, o_.step_length_jitter_m)))};
  }
  double true_height(double e, double n) const { return dem_.at_local(e, n).elevation_m + dem_error_.at(e, n); }
  double pressure_pa(double t_s, double baro_dt_s, double e, double n, Rng& rng) {
    bias_m_ = baro_bias_.advance(baro_dt_s, rng);
    const double h = true_height(e, n) + bias_m_;
    return geo::baro_pressure_pa(h, o_.sea_level_pressure_pa + drift_pa_per_s_ * t_s, 0.0, atmosphere_) +
           gusts_.at(t_s) + gauss(rng, o_.baro_noise_pa);
  }
  /// The PDR's step: biased, disturbed and noisy heading; scaled, noisy length.
  void measure(PdrStep& step, double t_s, double dt_s, double heading, double len, double /*e*/, double /*n*/,
               Rng& rng) {
    const double hb = heading_bias_.advance(dt_s, rng);
    step.length_m = std::max(0.0, len * (1.0 + scale_error_) + gauss(rng, o_.length_noise_m));
    step.heading_rad = wrap_two_pi(heading + hb + disturbance_.at(t_s) + gauss(rng, o_.heading_noise_rad));
  }

 private:
  const Dem& dem_;
  const WalkSimOptions& o_;
  const ErrorField dem_error_;
  const double expected_s_;
  const BumpProcess disturbance_;
  const BumpProcess gusts_;
  Fogm heading_bias_;
  Fogm baro_bias_;
  const double drift_pa_per_s_;
  const double walk_step_m_;
  const double scale_error_;
  geo::BaroOptions atmosphere_;
  double bias_m_ = 0.0;
  double dt_s_ = 0.0;
};

/// The world error models (docs/simulator.md): nothing here is the filter's own model.
/// Members are drawn from the walk's generator in declaration order (the walk's seed fixes them).
class WorldModels {
 public:
  WorldModels(const Dem& dem, const WalkSimOptions& o, double target_m, const std::vector<RoutePoint>& route, Rng& rng)
      : dem_(dem),
        o_(o),
        dem_error_(
            o.dem_world, dem.min_e_m(), dem.min_n_m(), dem.max_e_m(), dem.max_n_m(),
            [&dem](double e, double n) {
              const double d = 30.0;
              const double gx = (dem.at_local(e + d, n).elevation_m - dem.at_local(e - d, n).elevation_m) / (2 * d);
              const double gy = (dem.at_local(e, n + d).elevation_m - dem.at_local(e, n - d).elevation_m) / (2 * d);
              return std::isfinite(gx) && std::isfinite(gy) ? std::atan(std::hypot(gx, gy)) * kRadToDeg : 0.0;
            },
            [&dem](double e, double n) { return dem.at_local(e, n).elevation_m; }, rng),
        baro_(o.baro_world, target_m / o.step_length_mean_m / o.step_rate_hz * 1.5 + 120.0, rng),
        heading_err_(o.heading_world, sim::anomalies_along(route_points(route), o.anomalies_per_km, o.heading_world, rng),
                     rng),
        stride_(stride_options(o), o.step_length_mean_m, rng) {}
  void start(Rng& /*rng*/) {}
  void begin_pass(Rng& /*rng*/) {}
  /// The true stride follows the grade 2 m ahead.
  StepMotion motion(double e, double n, double heading, double t_s, double dist, Rng& rng) const {
    const double x_ahead = e + 2.0 * std::sin(heading), y_ahead = n + 2.0 * std::cos(heading);
    double grade = (true_height(x_ahead, y_ahead) - true_height(e, n)) / 2.0;
    if (!std::isfinite(grade)) grade = 0.0;
    const double dt = stride_.period_s(grade, rng);
    return {dt, std::min(dist, stride_.length_m(t_s, grade, rng))};
  }
  /// DEM = true ground + error.
  double true_height(double e, double n) const { return dem_.at_local(e, n).elevation_m - dem_error_.error_m(e, n); }
  double pressure_pa(double t_s, double /*baro_dt_s*/, double e, double n, Rng& rng) const {
    return baro_.pressure_pa(t_s, true_height(e, n) + o_.phone_height_m, rng);
  }
  /// The PDR's model step: it does not know the walker.
  void measure(PdrStep& step, double t_s, double /*dt_s*/, double heading, double /*len*/, double e, double n,
               Rng& rng) {
    step.length_m = o_.step_length_mean_m;
    step.heading_rad = wrap_two_pi(heading + heading_err_.advance(t_s, Eigen::Vector2d(e, n), rng));
  }

 private:
  static std::vector<Eigen::Vector2d> route_points(const std::vector<RoutePoint>& route) {
    std::vector<Eigen::Vector2d> pts;
    for (const RoutePoint& p : route) pts.emplace_back(p.e, p.n);
    return pts;
  }
  static sim::StrideOptions stride_options(const WalkSimOptions& o) {
    sim::StrideOptions so = o.stride_world;
    so.cadence_min_hz = so.cadence_max_hz = o.step_rate_hz;  // the walk's cadence option still applies
    so.cadence_cv = o.step_period_jitter;
    return so;
  }

  const Dem& dem_;
  const WalkSimOptions& o_;
  const sim::DemError dem_error_;
  const sim::BaroWorld baro_;
  sim::HeadingError heading_err_;
  const sim::Stride stride_;
};

/// One walk: a route, the error models drawn for it, the declared start, then the route walked
/// step by step with pressure samples at baro_rate_hz between steps.
template <class Models>
SimulatedWalk simulate_walk_with(const Dem& dem, const WalkSimOptions& o, std::uint64_t seed) {
  Rng rng(seed);
  SimulatedWalk w;
  w.seed = seed;
  w.t0_ns = kNsPerS;
  const double target = uniform(rng, o.min_length_m, o.max_length_m);
  const std::vector<RoutePoint> route = make_route(dem, o, target, rng);
  Models models(dem, o, target, route, rng);

  // Declared start.
  const Eigen::Vector2d start(route[0].e, route[0].n);
  w.declared_start_en = start + Eigen::Vector2d(gauss(rng, o.start_sigma_m), gauss(rng, o.start_sigma_m));
  w.declared_start = dem.to_geodetic(w.declared_start_en.x(), w.declared_start_en.y());
  w.declared_sigma_m = o.start_sigma_m;
  models.start(rng);

  double e = start.x(), n = start.y(), heading = route[0].heading, t_s = 0.0, t_baro = 0.0;
  const double baro_dt = 1.0 / o.baro_rate_hz;
  std::size_t leg = 1;
  while (leg < route.size()) {
    models.begin_pass(rng);
    // Aim at the next route point; turn at most 30 degrees per step (smooth corners).
    const double de = route[leg].e - e, dn = route[leg].n - n;
    const double dist = std::hypot(de, dn);
    if (dist < 1.0) {
      ++leg;
      continue;
    }
    const double turn = std::clamp(wrap_pi(std::atan2(de, dn) - heading), -30 * kDegToRad, 30 * kDegToRad);
    heading = wrap_two_pi(heading + turn);
    const StepMotion m = models.motion(e, n, heading, t_s, dist, rng);
    const double dt = m.dt_s, len = m.len_m;
    const double e_prev = e, n_prev = n;
    e += len * std::sin(heading);
    n += len * std::cos(heading);
    const double t_prev = t_s;
    t_s += dt;
    // Pressure samples in (t_prev, t_s], position interpolated along the step.
    while (t_baro + baro_dt <= t_s) {
      t_baro += baro_dt;
      const double f = (t_baro - t_prev) / dt;
      PressureSample ps;
      ps.t_ns = w.t0_ns + s_to_ns(t_baro);
      ps.pressure_pa = models.pressure_pa(t_baro, baro_dt, e_prev + f * (e - e_prev), n_prev + f * (n - n_prev), rng);
      w.pressure.push_back(ps);
    }
    PdrStep step;
    step.t_ns = w.t0_ns + s_to_ns(t_s);
    models.measure(step, t_s, dt, heading, len, e, n, rng);
    step.heading_sigma_rad = o.heading_bias_sigma_rad;
    step.length_sigma_m = o.length_noise_m;
    w.steps.push_back(step);
    const geo::Geodetic g = dem.to_geodetic(e, n);
    TruthSample truth;
    truth.t_ns = step.t_ns;
    truth.lat_deg = g.lat_deg();
    truth.lon_deg = g.lon_deg();
    truth.h_m = models.true_height(e, n);
    truth.heading_deg = rad_to_deg(heading);
    w.truth.push_back(truth);
    w.truth_en.emplace_back(e, n);
    w.length_m += len;
  }
  return w;
}

}  // namespace

SimulatedWalk simulate_walk(const Dem& dem, const WalkSimOptions& o, std::uint64_t seed) {
  return o.world_errors ? simulate_walk_with<WorldModels>(dem, o, seed) : simulate_walk_with<FilterModels>(dem, o, seed);
}

WalkEvaluation evaluate_walk(const SimulatedWalk& walk, std::shared_ptr<const Dem> dem,
                             const TerrainOptions& options, std::uint64_t seed) {
  WalkEvaluation ev;
  ev.length_m = walk.length_m;
  TerrainEngine pf(options, std::move(dem), seed);
  pf.initialize(walk.declared_start, walk.declared_sigma_m, walk.t0_ns);
  Eigen::Vector2d dr = walk.declared_start_en;
  std::size_t next_p = 0;
  double sum_dr2 = 0.0, sum_pf2 = 0.0;
  std::vector<double> m2s;
  m2s.reserve(walk.steps.size());
  for (std::size_t k = 0; k < walk.steps.size(); ++k) {
    const PdrStep& s = walk.steps[k];
    while (next_p < walk.pressure.size() && walk.pressure[next_p].t_ns <= s.t_ns) pf.feed(walk.pressure[next_p++]);
    pf.feed(s);
    dr += s.length_m * Eigen::Vector2d(std::sin(s.heading_rad), std::cos(s.heading_rad));
    const Estimate est = pf.estimate();
    const Eigen::Vector2d d_pf = walk.truth_en[k] - est.en_m;
    const Eigen::Vector2d d_dr = walk.truth_en[k] - dr;
    if (!est.en_m.allFinite() || !est.cov_en_m2.allFinite()) {
      ev.all_finite = false;
      continue;
    }
    sum_pf2 += d_pf.squaredNorm();
    sum_dr2 += d_dr.squaredNorm();
    const double m2 = mahalanobis2(est.cov_en_m2, d_pf);  // finite or +inf (not positive definite)
    m2s.push_back(m2);
    if (m2 <= kOneSigmaM2) ++ev.inside_1sigma;
    if (m2 <= 1.0) ++ev.inside_unit;
    ++ev.epochs;
    ev.final_dr_error_m = d_dr.norm();
    ev.final_pf_error_m = d_pf.norm();
  }
  if (ev.epochs > 0) {
    const auto n = static_cast<double>(ev.epochs);
    ev.dr_drms_m = std::sqrt(sum_dr2 / n);
    ev.pf_drms_m = std::sqrt(sum_pf2 / n);
    ev.coverage_1sigma = static_cast<double>(ev.inside_1sigma) / n;
    ev.coverage_unit = static_cast<double>(ev.inside_unit) / n;
    ev.median_percentile = chi2_2dof_percent(median_mahalanobis2(std::move(m2s)));
  }
  ev.stats = pf.stats();
  return ev;
}

}  // namespace pdnav::terrain
