// SIR particle filter of Broyles et al., Sensors 2018, 18, 2232 (Eq. 1-10), structure of arrays.
// One fused pass per step: propagate (Eq. 1-4), look up the DEM, weight (Eq. 5-7) and
// accumulate the sums for Neff (Eq. 10) and the residual monitor. Weights are kept
// unnormalised with their sum; resampling copies into a second buffer and swaps.
#include "pdnav/terrain/terrain_engine.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "fast_math.h"

namespace pdnav::terrain {
namespace {

using detail::fast_exp_neg;
using detail::fast_sincos;
using detail::normal_from_bits;
using detail::Xoshiro256Plus;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Particle state as structure of arrays.
struct Particles {
  std::vector<float> e, n, bh, bb, sc;  // sc: step-length scale error (beyond the paper)
  std::vector<float> h0;  // DEM elevation at the last update (segment_mean_elevation; NaN = none)
  void resize(std::size_t count) {
    sc.assign(count, 0.0f);
    h0.assign(count, std::numeric_limits<float>::quiet_NaN());
    e.assign(count, 0.0f);
    n.assign(count, 0.0f);
    bh.assign(count, 0.0f);
    bb.assign(count, 0.0f);
  }
  void copy_from(const Particles& src, std::size_t dst_i, std::size_t src_i) {
    e[dst_i] = src.e[src_i];
    n[dst_i] = src.n[src_i];
    bh[dst_i] = src.bh[src_i];
    bb[dst_i] = src.bb[src_i];
    sc[dst_i] = src.sc[src_i];
    h0[dst_i] = src.h0[src_i];
  }
};

/// ln(x) for x in (0, 1] (double; relative error < 1e-7): exponent + atanh series.
double fast_log(double x) {
  int ex = 0;
  double m = std::frexp(x, &ex);  // x = m 2^ex, m in [0.5, 1)
  if (m < 0.70710678118654752) {
    m *= 2.0;
    --ex;
  }
  const double t = (m - 1.0) / (m + 1.0);
  const double t2 = t * t;
  const double s = t * (2.0 + t2 * (2.0 / 3 + t2 * (2.0 / 5 + t2 * (2.0 / 7 + t2 * (2.0 / 9)))));
  return static_cast<double>(ex) * 0.69314718055994531 + s;
}

/// Fading factor and driving-noise 1-sigma of a first-order Gauss-Markov process over dt:
/// b_k = phi b_{k-1} + w, var(w) = sigma^2 (1 - phi^2), the exact discretisation of the
/// paper's continuous FOGM driven by white noise of PSD 2 sigma^2 / tau (Eq. 3-4).
void fogm(double sigma, double tau_s, double dt_s, float& phi, float& q) {
  const double p = std::exp(-dt_s / tau_s);
  phi = static_cast<float>(p);
  q = static_cast<float>(sigma * std::sqrt(std::max(0.0, 1.0 - p * p)));
}

}  // namespace

const char* to_string(Resampling r) {
  switch (r) {
    case Resampling::kMultinomial: return "multinomial";
    case Resampling::kSystematic: return "systematic";
    case Resampling::kStratified: return "stratified";
  }
  return "?";
}

Resampling resampling_from_string(const std::string& s) {
  if (s == "multinomial") return Resampling::kMultinomial;
  if (s == "systematic") return Resampling::kSystematic;
  if (s == "stratified") return Resampling::kStratified;
  throw std::invalid_argument("unknown resampling '" + s + "' (multinomial, systematic, stratified)");
}

TerrainOptions TerrainOptions::srtm_preset() {
  TerrainOptions o;
  o.baro_bias_sigma_m = 20.0;     // Broyles 2018: 30 m DEM tuning
  o.baro_bias_tau_s = 1200.0;
  o.measurement_var_m2 = 160.0;
  return o;
}

TerrainOptions TerrainOptions::srtm_tuned() {
  TerrainOptions o;
  o.baro_bias_sigma_m = 5.0;      // bias state absorbs baro drift + DEM error over ~600 s
  o.baro_bias_tau_s = 600.0;
  o.measurement_var_m2 = 20.0;    // with the bias Rao-Blackwellised and no slope lag left
  o.update_distance_m = 10.0;
  o.step_scale_sigma = 0.03;
  o.roughening_k = 0.2;
  o.segment_mean_elevation = true;
  o.rao_blackwell_baro_bias = true;
  return o;
}

TerrainOptions TerrainOptions::preset(const std::string& name) {
  if (name == "paper") return paper();
  if (name == "srtm") return srtm_preset();
  if (name == "srtm-tuned") return srtm_tuned();
  throw std::invalid_argument("unknown terrain preset '" + name + "' (paper, srtm, srtm-tuned)");
}

struct TerrainEngine::Impl {
  TerrainOptions opt;
  std::shared_ptr<const Dem> dem;
  Xoshiro256Plus rng;
  std::size_t count = 0;
  Particles p, spare;
  std::vector<float> w;         // unnormalised weights, sum in w_sum
  double w_sum = 0.0;
  std::vector<double> cdf;      // resampling scratch
  std::vector<float> resid;     // z - prediction per particle (NaN: void / off the tile)

  bool initialized = false;
  TimeNs t_ns = 0;              // time of the last step (or initialisation)
  geo::BaroAltimeter baro;
  bool baro_usable = false;     // anchored at a valid DEM elevation
  double baro_sum_m = 0.0;
  int baro_count = 0;
  double walked_since_update_m = 0.0;
  double bias_var_m2 = 0.0;     // Rao-Blackwellised baro bias: common Kalman variance P

  std::vector<double> nis_window;
  std::size_t nis_next = 0;
  std::size_t nis_filled = 0;
  TimeNs recovering_until_ns = std::numeric_limits<TimeNs>::min();
  std::string alarm;            // last residual-monitor alarm
  TerrainStats stats;

  Impl(const TerrainOptions& o, std::shared_ptr<const Dem> d, std::uint64_t seed)
      : opt(o), dem(std::move(d)), rng(seed) {
    if (!dem) throw std::invalid_argument("TerrainEngine: no DEM");
    if (opt.particles < 1 || opt.particles > 50'000'000)
      throw std::invalid_argument("TerrainEngine: particles must be 1..5e7");
    if (!(opt.measurement_var_m2 > 0.0) || !(opt.heading_bias_tau_s > 0.0) || !(opt.baro_bias_tau_s > 0.0) ||
        !(opt.step_length_sigma_m >= 0.0) || !(opt.resample_threshold >= 0.0 && opt.resample_threshold <= 1.0))
      throw std::invalid_argument("TerrainEngine: options out of range (R, tau > 0; threshold 0..1)");
    count = static_cast<std::size_t>(opt.particles);
    p.resize(count);
    spare.resize(count);
    w.assign(count, 1.0f);
    w_sum = static_cast<double>(count);
    cdf.assign(count, 0.0);
    resid.assign(count, 0.0f);
    nis_window.assign(static_cast<std::size_t>(std::max(1, opt.monitor_window)), 0.0);
  }

  float normal() { return normal_from_bits(rng.next()); }

  bool recovering() const { return t_ns < recovering_until_ns; }

  void initialize(const geo::Geodetic& start, double sigma_m, TimeNs t) {
    const Eigen::Vector2d en = dem->to_local(start);
    const auto s = static_cast<float>(std::isfinite(sigma_m) && sigma_m > 0 ? sigma_m : opt.initial_sigma_m);
    const auto hs = static_cast<float>(opt.heading_bias_sigma_rad);
    const auto bs = static_cast<float>(opt.baro_bias_sigma_m);
    for (std::size_t i = 0; i < count; ++i) {
      p.e[i] = static_cast<float>(en.x()) + s * normal();
      p.n[i] = static_cast<float>(en.y()) + s * normal();
      p.bh[i] = hs * normal();
      p.bb[i] = opt.rao_blackwell_baro_bias ? 0.0f : bs * normal();
      p.sc[i] = static_cast<float>(opt.step_scale_sigma) * normal();
      p.h0[i] = dem->elevation_or_nan(p.e[i], p.n[i]);
      w[i] = 1.0f;
    }
    w_sum = sum_sq = static_cast<double>(count);
    t_ns = t;
    initialized = true;
    restart_baro_average();
    walked_since_update_m = 0.0;
    last_pa = last_h_m = kNaN;
    stats.baro_jump_offset_m = 0.0;
    stats.baro_stuck = false;
    bias_var_m2 = opt.baro_bias_sigma_m * opt.baro_bias_sigma_m;
    nis_filled = nis_next = 0;
    recovering_until_ns = std::numeric_limits<TimeNs>::min();
    alarm.clear();
    const DemSample ground = dem->at_local(en.x(), en.y());
    baro_usable = ground.valid();
    if (baro_usable) {
      // Hypsometric formula referenced at the start: ISA temperature at the start elevation.
      geo::BaroOptions bo;
      bo.ref_temperature_k = bo.ref_temperature_k - bo.lapse_rate_kpm * ground.elevation_m;
      baro = geo::BaroAltimeter(bo);
      baro.anchor(ground.elevation_m);
    }
  }

  /// Start a new barometer average (after an update, a sensor step, a stuck sensor, a restart).
  void restart_baro_average() {
    baro_sum_m = 0.0;
    baro_count = 0;
  }

  /// Variance of z - (h + bias mean): R, plus the common bias variance P when Rao-Blackwellised.
  double innovation_var() const {
    return opt.measurement_var_m2 + (opt.rao_blackwell_baro_bias ? bias_var_m2 : 0.0);
  }

  // Barometer integrity state (feed_pressure).
  double last_pa = kNaN;        // last sample (stuck check)
  TimeNs same_since_ns = 0;     //   first time it was seen
  double last_h_m = kNaN;       // last accepted raw altitude (jump check) and its time
  TimeNs last_h_ns = 0;

  void feed_pressure(const PressureSample& s) {
    if (!initialized || !baro_usable) return;
    const double pa = s.pressure_pa;
    if (!std::isfinite(pa) || pa < 25e3 || pa > 115e3) {  // outside any surface pressure
      ++stats.baro_rejected;
      return;
    }
    if (stuck_check(pa, s.t_ns)) return;
    const double h = baro.update(pa);
    if (!std::isfinite(h)) return;
    jump_check(h, s.t_ns);
    baro_sum_m += h - stats.baro_jump_offset_m;
    ++baro_count;
  }

  /// True while the sensor repeats one exact value for baro_stuck_s or longer.
  bool stuck_check(double pa, TimeNs t) {
    if (pa != last_pa) {
      last_pa = pa;
      same_since_ns = t;
      stats.baro_stuck = false;
      return false;
    }
    if (opt.baro_stuck_s > 0.0 && ns_to_s(t) - ns_to_s(same_since_ns) >= opt.baro_stuck_s && !stats.baro_stuck) {
      stats.baro_stuck = true;
      ++stats.baro_stuck_events;
      restart_baro_average();  // the average so far holds stuck samples too
    }
    return stats.baro_stuck;
  }

  /// A step between consecutive samples that no walk can explain is a sensor step: measure it
  /// and drop the average taken so far (it straddles the step).
  void jump_check(double h, TimeNs t) {
    const double dt_s = ns_to_s(t) - ns_to_s(last_h_ns);
    const double dh = h - last_h_m;
    const bool jump = opt.baro_jump_m > 0.0 && std::isfinite(dh) && dt_s >= 0.0 &&
                      std::abs(dh) > opt.baro_jump_m + opt.baro_max_vertical_speed_mps * dt_s;
    if (jump) {
      ++stats.baro_jumps;
      stats.baro_jump_offset_m += dh;
      restart_baro_average();
    }
    last_h_m = h;
    last_h_ns = t;
  }

  void feed_step(const PdrStep& step) {
    if (!initialized || !std::isfinite(step.length_m) || !std::isfinite(step.heading_rad) ||
        step.length_m < 0.0 || step.length_m > 5.0)
      return;
    double dt_s = ns_to_s(step.t_ns) - ns_to_s(t_ns);  // no int64 overflow on wild times
    if (!(dt_s >= 0.0)) dt_s = 0.0;
    t_ns = step.t_ns;
    ++stats.steps;
    walked_since_update_m += step.length_m;
    const bool measure = baro_usable && baro_count > 0 && walked_since_update_m >= opt.update_distance_m;
    const double z = measure ? baro_sum_m / baro_count : kNaN;
    propagate_and_weight(step, dt_s, z);
    if (measure) {
      restart_baro_average();
      walked_since_update_m = 0.0;
    }
    const double neff = neff_fraction();
    stats.neff_fraction = neff;
    if (measure && neff < opt.resample_threshold) resample();
  }

  double sum_sq = 0.0;  // sum of squared unnormalised weights (for Neff)

  double neff_fraction() const {
    if (!(sum_sq > 0.0)) return 1.0;
    return (w_sum * w_sum / sum_sq) / static_cast<double>(count);
  }

  /// Eq. 1-4 for every particle and, when z is finite, Eq. 5-7 in the same pass.
  void propagate_and_weight(const PdrStep& step, double dt_s, double z) {
    const double gain = recovering() ? opt.recovery_noise_gain : 1.0;
    float phi_h, q_h, phi_b, q_b;
    fogm(opt.heading_bias_sigma_rad, opt.heading_bias_tau_s, dt_s, phi_h, q_h);
    fogm(opt.baro_bias_sigma_m, opt.baro_bias_tau_s, dt_s, phi_b, q_b);
    const bool rb = opt.rao_blackwell_baro_bias;
    if (rb) {  // Kalman time update of the common variance; the means only fade
      bias_var_m2 = static_cast<double>(phi_b) * phi_b * bias_var_m2 + static_cast<double>(q_b) * q_b;
      q_b = 0.0f;
    }
    q_h *= static_cast<float>(gain);
    const auto len = static_cast<float>(step.length_m);
    const auto dl_span = static_cast<float>(2.0 * opt.step_length_sigma_m * gain);
    const auto s_th = static_cast<float>(std::sin(step.heading_rad));
    const auto c_th = static_cast<float>(std::cos(step.heading_rad));
    const bool measure = std::isfinite(z);
    const auto zf = static_cast<float>(z);
    const double innov_var = innovation_var();  // Eq. 5-7 (+ P)
    const auto inv_2r = static_cast<float>(0.5 / innov_var);
    const auto no_info_ll = static_cast<float>(-0.5 * opt.no_info_sigmas * opt.no_info_sigmas);
    const auto renorm = static_cast<float>(static_cast<double>(count) / w_sum);  // keeps mean weight ~1
    const Dem& d = *dem;
    float* pe = p.e.data();
    float* pn = p.n.data();
    float* pbh = p.bh.data();
    float* pbb = p.bb.data();
    const float* psc = p.sc.data();
    float* ph0 = p.h0.data();
    const bool segment = opt.segment_mean_elevation;
    float* pr = resid.data();
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint64_t r1 = rng.next();
      const std::uint64_t r2 = rng.next();
      float sb, cb;
      fast_sincos(pbh[i], sb, cb);
      const float dl = (static_cast<float>(r2 >> 48) * (1.0f / 65536.0f) - 0.5f) * dl_span;
      const float step_len = len * (1.0f + psc[i]) + dl;
      pe[i] += step_len * (s_th * cb + c_th * sb);  // east = l sin(theta + b), Eq. 1
      pn[i] += step_len * (c_th * cb - s_th * sb);  // north = l cos(theta + b), Eq. 2
      pbh[i] = detail::wrap_pi_f(phi_h * pbh[i] + q_h * normal_from_bits(r1));  // Eq. 3
      // Eq. 4 with an Irwin-Hall(3) normal from the low 48 bits of r2.
      const float nb = (static_cast<float>((r2 & 0xFFFFu) + ((r2 >> 16) & 0xFFFFu) + ((r2 >> 32) & 0xFFFFu)) *
                            (1.0f / 65536.0f) - 1.5f) * 2.0f;
      pbb[i] = phi_b * pbb[i] + q_b * nb;
      if (measure) {
        const float h = d.elevation_or_nan(pe[i], pn[i]);  // NaN = void / off the tile
        float pred = h;
        if (segment) {
          pred = ph0[i] == ph0[i] ? 0.5f * (ph0[i] + h) : h;  // segment mean (trapezoid)
          ph0[i] = h;
        }
        pr[i] = zf - (pred + pbb[i]);
      }
    }
    if (!measure) return;
    weight_pass(renorm, inv_2r, no_info_ll);
    if (rb) update_bias_means(innov_var);
  }

  /// Rao-Blackwellised baro bias: Kalman measurement update of each particle's bias mean with
  /// its own residual (voids / off the tile: no update) and of the common variance.
  void update_bias_means(double innov_var) {
    const double k = bias_var_m2 / innov_var;
    const auto kf = static_cast<float>(k);
    float* pbb = p.bb.data();
    const float* pr = resid.data();
    for (std::size_t i = 0; i < count; ++i) {
      const float r = pr[i];
      pbb[i] += r == r ? kf * r : 0.0f;
    }
    bias_var_m2 *= 1.0 - k;
  }

  /// Eq. 5-7 over the residuals of the propagation pass, in lanes of 8 so that the compiler can
  /// vectorise the likelihood, the weights and the sums for Neff and the monitor.
  void weight_pass(float renorm, float inv_2r, float no_info_ll) {
    constexpr std::size_t kLanes = 8;
    float* pw = w.data();
    const float* pr = resid.data();
    Sums total;
    float lw[kLanes] = {}, lw2[kLanes] = {}, lv[kLanes] = {}, lr[kLanes] = {}, lr2[kLanes] = {};
    float lmin[kLanes];
    std::fill(lmin, lmin + kLanes, std::numeric_limits<float>::infinity());
    auto one = [&](std::size_t i, std::size_t l) {
      const float wi = pw[i] * renorm;
      const float r = pr[i];
      const float r2f = r * r;
      const bool valid = r2f == r2f;  // false for voids / off the tile (NaN)
      const float ll = valid ? -r2f * inv_2r : no_info_ll;  // Gaussian likelihood, Eq. 5-7
      float wn = wi * fast_exp_neg(ll);
      wn = wn < 1e-30f ? 0.0f : wn;  // keep clear of denormals
      pw[i] = wn;
      const float wv = valid ? wi : 0.0f;
      const float rv = valid ? r : 0.0f;
      lmin[l] = valid && r2f < lmin[l] ? r2f : lmin[l];
      lw[l] += wn;
      lw2[l] += wn * wn;
      lv[l] += wv;
      lr[l] += wv * rv;
      lr2[l] += wv * rv * rv;
    };
    std::size_t i = 0;
    for (; i + kLanes <= count; i += kLanes) {
      for (std::size_t l = 0; l < kLanes; ++l) one(i + l, l);
      if ((i & 1023u) == 1016u) flush_lanes(total, lw, lw2, lv, lr, lr2);  // float partials -> double
    }
    for (std::size_t l = 0; i < count; ++i, ++l) one(i, l);
    flush_lanes(total, lw, lw2, lv, lr, lr2);
    float min_r2 = lmin[0];
    for (float m : lmin) min_r2 = std::min(min_r2, m);
    finish_update(total, min_r2);
  }


  /// Accumulators of one update: weights, squared weights, weight on valid DEM, and the
  /// weighted first two moments of the residual z - pred over valid particles.
  struct Sums {
    double w = 0, w2 = 0, valid = 0, r = 0, r2 = 0;
  };

  template <std::size_t N>
  static void flush_lanes(Sums& t, float (&lw)[N], float (&lw2)[N], float (&lv)[N], float (&lr)[N], float (&lr2)[N]) {
    for (std::size_t l = 0; l < N; ++l) {
      t.w += lw[l];
      t.w2 += lw2[l];
      t.valid += lv[l];
      t.r += lr[l];
      t.r2 += lr2[l];
      lw[l] = lw2[l] = lv[l] = lr[l] = lr2[l] = 0.0f;
    }
  }

  void finish_update(const Sums& sums, float min_r2) {
    double s_w = sums.w, s_w2 = sums.w2;
    const double s_valid = sums.valid;
    const double prior_total = static_cast<double>(count);  // weights were renormalised to mean 1
    stats.off_dem_fraction = 1.0 - s_valid / prior_total;
    if (s_valid <= 0.0) {  // no particle on valid DEM: every weight got the same factor
      ++stats.skipped_updates;
      w_sum = s_w;
      sum_sq = s_w2;
      return;
    }
    ++stats.updates;
    if (!(s_w > 0.0) || !std::isfinite(s_w)) {  // total weight underflow
      ++stats.weight_underflows;
      std::fill(w.begin(), w.end(), 1.0f);
      s_w = s_w2 = prior_total;
    }
    w_sum = s_w;
    sum_sq = s_w2;
    monitor(s_valid, sums.r, sums.r2, min_r2);
  }

  /// Residual monitoring: window mean of the normalised innovation squared of the baro
  /// measurement against the particle prediction; alarms re-spread the cloud.
  void monitor(double s_valid, double s_r, double s_r2, float min_r2) {
    const double mean_r = s_r / s_valid;  // z - mean prediction
    const double var = std::max(0.0, s_r2 / s_valid - mean_r * mean_r);
    const double r_var = innovation_var();
    const double nis = mean_r * mean_r / (var + r_var);
    stats.last_nis = nis;
    nis_window[nis_next] = nis;
    nis_next = (nis_next + 1) % nis_window.size();
    nis_filled = std::min(nis_filled + 1, nis_window.size());
    const double mean = std::accumulate(nis_window.begin(), nis_window.begin() + static_cast<long>(nis_filled), 0.0) /
                        static_cast<double>(nis_filled);
    stats.mean_nis = mean;
    if (!opt.residual_monitor) return;
    const double out = opt.monitor_outlier_sigmas;
    const bool outlier = static_cast<double>(min_r2) > out * out * r_var;
    const bool drift = nis_filled == nis_window.size() && mean > opt.monitor_nis_threshold;
    if (!outlier && !drift) return;
    std::ostringstream os;
    os.precision(3);
    if (outlier) os << "no particle within " << out << " sigma of the barometer";
    else os << "innovation NIS mean " << mean << " over " << nis_filled << " updates";
    alarm = os.str();
    recover();
  }

  /// Re-spread around the current cloud, reset weights, raise process noise for a while.
  void recover() {
    ++stats.recoveries;
    const auto rs = static_cast<float>(opt.respread_sigma_m);
    const auto hs = static_cast<float>(0.5 * opt.heading_bias_sigma_rad);
    const auto bs = static_cast<float>(0.5 * opt.baro_bias_sigma_m);
    for (std::size_t i = 0; i < count; ++i) {
      p.e[i] += rs * normal();
      p.n[i] += rs * normal();
      p.bh[i] = detail::wrap_pi_f(p.bh[i] + hs * normal());
      if (!opt.rao_blackwell_baro_bias) p.bb[i] += bs * normal();
      p.h0[i] = std::numeric_limits<float>::quiet_NaN();  // moved: the segment start is unknown
    }
    bias_var_m2 += static_cast<double>(bs) * bs;
    std::fill(w.begin(), w.end(), 1.0f);
    w_sum = sum_sq = static_cast<double>(count);
    nis_filled = nis_next = 0;
    recovering_until_ns = t_ns + s_to_ns(opt.recovery_duration_s);
  }

  /// Ordered pointers u_k in [0, 1) for the chosen scheme (Eq. 10 resampling).
  template <typename Visit>
  void for_each_pointer(Visit&& visit) {
    const double inv_n = 1.0 / static_cast<double>(count);
    switch (opt.resampling) {
      case Resampling::kSystematic: {
        const double u0 = (rng.uniform_open0() - 0x1.0p-53) * inv_n;
        for (std::size_t k = 0; k < count; ++k) visit(u0 + static_cast<double>(k) * inv_n);
        break;
      }
      case Resampling::kStratified:
        for (std::size_t k = 0; k < count; ++k)
          visit((static_cast<double>(k) + rng.uniform_open0() - 0x1.0p-53) * inv_n);
        break;
      case Resampling::kMultinomial: {
        // N sorted iid uniforms = normalised partial sums of N+1 unit exponentials.
        double total = 0.0;
        for (std::size_t k = 0; k < count; ++k) {
          cdf[k] = -fast_log(rng.uniform_open0());
          total += cdf[k];
        }
        total += -fast_log(rng.uniform_open0());
        double acc = 0.0;
        const double inv_total = 1.0 / total;
        for (std::size_t k = 0; k < count; ++k) {
          acc += cdf[k];
          visit(acc * inv_total);
        }
        break;
      }
    }
  }

  void resample() {
    ++stats.resamples;
    const double inv_sum = 1.0 / w_sum;
    std::size_t src = 0;
    double cum = static_cast<double>(w[0]) * inv_sum;
    std::size_t dst = 0;
    for_each_pointer([&](double u) {
      while (u >= cum && src + 1 < count) cum += static_cast<double>(w[++src]) * inv_sum;
      spare.copy_from(p, dst++, src);
    });
    std::swap(p, spare);
    std::fill(w.begin(), w.end(), 1.0f);
    w_sum = sum_sq = static_cast<double>(count);
    if (opt.roughening_k > 0.0) roughen();
  }

  /// Roughening (Gordon, Salmond, Smith 1993): jitter the resampled positions by
  /// K * range * N^(-1/d) per axis (d = 4 state dimensions), against sample impoverishment.
  void roughen() {
    const auto [e_lo, e_hi] = std::minmax_element(p.e.begin(), p.e.end());
    const auto [n_lo, n_hi] = std::minmax_element(p.n.begin(), p.n.end());
    const double shrink = opt.roughening_k * std::pow(static_cast<double>(count), -0.25);
    const auto se = static_cast<float>(shrink * (*e_hi - *e_lo));
    const auto sn = static_cast<float>(shrink * (*n_hi - *n_lo));
    for (std::size_t i = 0; i < count; ++i) {
      p.e[i] += se * normal();
      p.n[i] += sn * normal();
    }
  }

  Estimate estimate() const {
    Estimate est;
    est.engine = EngineKind::kTerrain;
    est.t_ns = t_ns;
    if (!initialized) {
      est.reason = "terrain: no start position";
      return est;
    }
    double sw = 0.0, me = 0.0, mn = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
      const double wi = w[i];
      sw += wi;
      me += wi * p.e[i];
      mn += wi * p.n[i];
    }
    if (!(sw > 0.0)) sw = 1.0;
    me /= sw;
    mn /= sw;
    double cee = 0.0, cnn = 0.0, cen = 0.0;
    for (std::size_t i = 0; i < count; ++i) {  // Eq. 9
      const double de = p.e[i] - me, dn = p.n[i] - mn, wi = w[i];
      cee += wi * de * de;
      cnn += wi * dn * dn;
      cen += wi * de * dn;
    }
    est.en_m = Eigen::Vector2d(me, mn);  // Eq. 8
    est.cov_en_m2 << cee / sw, cen / sw, cen / sw, cnn / sw;
    est.position = dem->to_geodetic(me, mn);
    const DemSample ground = dem->at_local(me, mn);
    est.position.h_m = ground.valid() ? ground.elevation_m : 0.0;  // DEM datum (docs/terrain.md)
    est.vertical_sigma_m = std::sqrt(opt.measurement_var_m2);
    status_and_reason(est);
    return est;
  }

  void status_and_reason(Estimate& est) const {
    est.status = EstimateStatus::kOk;
    std::ostringstream os;
    os.precision(3);
    os << "terrain PF " << count << " particles";
    if (!baro_usable) {
      est.status = EstimateStatus::kDegraded;
      os << "; start is off the DEM or on a void: no terrain updates (dead reckoning)";
    } else if (stats.updates == 0) {
      os << "; waiting for barometer";
    }
    if (stats.off_dem_fraction > 0.5) {
      est.status = EstimateStatus::kDegraded;
      os << "; " << 100.0 * stats.off_dem_fraction << "% of the weight off the DEM or on voids";
    }
    if (stats.baro_stuck) {
      est.status = EstimateStatus::kDegraded;
      os << "; barometer stuck (one value for " << opt.baro_stuck_s << "+ s): terrain updates paused";
    }
    if (stats.baro_jumps > 0) os << "; " << stats.baro_jumps << " barometer step(s) compensated";
    if (recovering()) {
      est.status = EstimateStatus::kDegraded;
      os << "; recovering (" << alarm << ")";
    }
    est.reason = os.str();
  }
};

TerrainEngine::TerrainEngine(const TerrainOptions& options, std::shared_ptr<const Dem> dem, std::uint64_t seed)
    : impl_(std::make_unique<Impl>(options, std::move(dem), seed)) {}
TerrainEngine::~TerrainEngine() = default;
TerrainEngine::TerrainEngine(TerrainEngine&&) noexcept = default;
TerrainEngine& TerrainEngine::operator=(TerrainEngine&&) noexcept = default;

void TerrainEngine::initialize(const geo::Geodetic& start, double sigma_m, TimeNs t_ns) {
  impl_->initialize(start, sigma_m, t_ns);
}
void TerrainEngine::feed(const PdrStep& step) { impl_->feed_step(step); }
void TerrainEngine::feed(const PressureSample& p) { impl_->feed_pressure(p); }
Estimate TerrainEngine::estimate() const { return impl_->estimate(); }
const TerrainStats& TerrainEngine::stats() const { return impl_->stats; }
const TerrainOptions& TerrainEngine::options() const { return impl_->opt; }
const Dem& TerrainEngine::dem() const { return *impl_->dem; }

std::vector<Eigen::Vector2d> TerrainEngine::particles_en(std::size_t max) const {
  std::vector<Eigen::Vector2d> out;
  const std::size_t n = impl_->count;
  if (max == 0 || !impl_->initialized) return out;
  const std::size_t take = std::min(max, n);
  out.reserve(take);
  for (std::size_t k = 0; k < take; ++k) {
    const std::size_t i = k * n / take;
    out.emplace_back(impl_->p.e[i], impl_->p.n[i]);
  }
  return out;
}

Eigen::Vector2d TerrainEngine::bias_estimate() const {
  double sw = 0.0, sh = 0.0, sb = 0.0;
  for (std::size_t i = 0; i < impl_->count; ++i) {
    sw += impl_->w[i];
    sh += impl_->w[i] * impl_->p.bh[i];
    sb += impl_->w[i] * impl_->p.bb[i];
  }
  if (!(sw > 0.0)) return {0.0, 0.0};
  return {sh / sw, sb / sw};
}

std::size_t TerrainEngine::bytes_per_particle() {
  // 6 floats (5 states + segment-start elevation) x 2 buffers + 1 float weight + 1 float
  // residual + 1 double resampling scratch
  return 2 * 6 * sizeof(float) + 2 * sizeof(float) + sizeof(double);
}

}  // namespace pdnav::terrain
