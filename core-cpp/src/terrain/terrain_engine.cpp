// SIR particle filter of Broyles et al., Sensors 2018, 18, 2232 (Eq. 1-10), structure of arrays.
// A step runs over blocks of 256 particles: propagate (Eq. 1-4) and find the DEM cell
// (vectorised), gather the cell's nodes (scalar), weight (Eq. 5-7), update the bias means and
// accumulate the sums for Neff (Eq. 10) and the residual monitor (vectorised). Weights are kept
// unnormalised with their sum; resampling copies into a second buffer and swaps.
#include "pdnav/terrain/terrain_engine.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

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
  std::vector<float> an;  // start anchoring: DEM(declared start) - DEM(own start), constant
  std::vector<float> h0;  // DEM elevation at the last update (segment_mean_elevation; NaN = none)
  void resize(std::size_t count) {
    sc.assign(count, 0.0f);
    an.assign(count, 0.0f);
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
    an[dst_i] = src.an[src_i];
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

/// Particles per block of the step kernels: the block's scratch (4 random words, a cell index,
/// 3 floats) is 8 KiB, inside L1 with the particle slices it works on.
constexpr std::size_t kBlock = 256;
using LaneRng = detail::LaneXoshiro128Plus<kBlock>;

struct BlockScratch {
  alignas(64) std::uint32_t r0[kBlock], r1[kBlock], r2[kBlock], r3[kBlock];  // random words
  alignas(64) std::int32_t idx[kBlock];  // south-west node of the particle's cell (0 when off)
  alignas(64) float tx[kBlock], ty[kBlock];  // position inside the cell, 0..1
  alignas(64) float off[kBlock];  // 0 on the tile, NaN off it (added to the elevation)
  alignas(64) float h[kBlock];    // bilinear DEM elevation (NaN = void / off the tile)
};

/// Per-step constants of the propagation (Eq. 1-4).
struct PropagateCoeffs {
  float len, dl_span, s_th, c_th, phi_h, q_h, phi_b, q_b, phi_s, q_s;
};

/// Per-update constants of the weighting (Eq. 5-7) and the Rao-Blackwellised bias update.
struct WeighCoeffs {
  float z, inv_2r, no_info_ll, renorm, gain_k;
  float outlier_r2;  // the monitor's bound: (outlier sigmas)^2 x innovation variance
  bool segment, track_h0;
};

/// Pass 1: Eq. 1-4 for m particles from the block's random words. One straight loop without calls or stores that depend on data: GCC
/// vectorises it (-fopt-info-vec; docs/terrain.md "Speed").
void propagate_block(const PropagateCoeffs& k, std::size_t m, float* __restrict e,
                     float* __restrict n, float* __restrict bh, float* __restrict bb, float* __restrict sc,
                     BlockScratch& __restrict s) {
  for (std::size_t j = 0; j < m; ++j) {
    float sb, cb;
    detail::fast_sincos(bh[j], sb, cb);
    const std::uint32_t r3 = s.r3[j];
    // Step-length noise dl ~ U(-sigma_l, sigma_l) (Eq. 1-2) from the top 16 bits of word 3.
    const float dl = (static_cast<float>(static_cast<std::int32_t>(r3 >> 16)) * (1.0f / 65536.0f) - 0.5f) * k.dl_span;
    const float step_len = k.len * (1.0f + sc[j]) + dl;
    e[j] += step_len * (k.s_th * cb + k.c_th * sb);  // east = l sin(theta + b), Eq. 1
    n[j] += step_len * (k.c_th * cb - k.s_th * sb);  // north = l cos(theta + b), Eq. 2
    bh[j] = detail::wrap_pi_f(k.phi_h * bh[j] + k.q_h * detail::normal_from_words(s.r0[j], s.r1[j]));  // Eq. 3
    // Eq. 4 with an Irwin-Hall(3) normal from word 2 and the low half of word 3.
    const float nb =
        (static_cast<float>(detail::halves_sum(s.r2[j]) + static_cast<std::int32_t>(r3 & 0xFFFFu)) * (1.0f / 65536.0f) -
         1.5f) * 2.0f;
    bb[j] = k.phi_b * bb[j] + k.q_b * nb;
    sc[j] = k.phi_s * sc[j] + k.q_s * nb;  // slope-varying stride (q_s = 0 unless the bias is RB)
  }
}

/// Pass 1b: the DEM cell of each new position (a second straight loop: GCC does not if-convert
/// it inside pass 1).
void locate_block(const Dem::Grid& g, std::size_t m, const float* __restrict e, const float* __restrict n,
                  BlockScratch& __restrict s) {
  for (std::size_t j = 0; j < m; ++j) {
    const float fx = (e[j] - g.x0_m) * g.inv_cell;
    const float fy = (n[j] - g.y0_m) * g.inv_cell;
    // & not &&: no branches, so that the loop vectorises; false for NaN
    const bool on = (fx >= 0.0f) & (fy >= 0.0f) & (fx < g.max_fx) & (fy < g.max_fy);
    // Clamp into the grid without branches (NaN -> 0; maxss/minss): the conversions below then
    // run unconditionally, which lets GCC if-convert the loop (a guarded float -> int
    // conversion may trap and is never if-converted).
    float cx = 0.0f < fx ? fx : 0.0f;
    float cy = 0.0f < fy ? fy : 0.0f;
    cx = cx < g.max_fx ? cx : g.last_fx;
    cy = cy < g.max_fy ? cy : g.last_fy;
    const auto ix = static_cast<std::int32_t>(cx);
    const auto iy = static_cast<std::int32_t>(cy);
    s.idx[j] = iy * g.cols + ix;
    s.tx[j] = cx - static_cast<float>(ix);
    s.ty[j] = cy - static_cast<float>(iy);
    s.off[j] = on ? 0.0f : std::numeric_limits<float>::quiet_NaN();
  }
}

/// Pass 2: bilinear elevation of each particle's cell (the scalar gather; voids are NaN nodes).
void gather_block(const Dem::Grid& g, std::size_t m, BlockScratch& __restrict s) {
  const float* v = g.values;
  const std::size_t cols = static_cast<std::size_t>(g.cols);
  for (std::size_t j = 0; j < m; ++j) {
    const float* q = v + static_cast<std::size_t>(s.idx[j]);
    const float tx = s.tx[j];
    const float south = q[0] + tx * (q[1] - q[0]);
    const float north = q[cols] + tx * (q[cols + 1] - q[cols]);
    s.h[j] = south + s.ty[j] * (north - south) + s.off[j];
  }
}

/// Accumulators of one update: weights, squared weights, weight on valid DEM, the weighted
/// first two moments of the residual z - pred over valid particles, and the number of valid
/// particles within the monitor's outlier bound.
struct Sums {
  double w = 0, w2 = 0, valid = 0, r = 0, r2 = 0, within = 0;
};

/// Pass 3: Eq. 5-7, the bias-mean update and the sums for Neff and the monitor, four particles
/// at a time in explicit SIMD lanes (fast_math.h: GCC does not vectorise the reductions nor the
/// selects around the exp polynomial by itself); float partials per block, added to the
/// double totals once per block. The scalar tail does the same per particle.
void weigh_block(const WeighCoeffs& c, std::size_t m, const float* __restrict hs, float* __restrict h0,
                 float* __restrict bb, const float* __restrict an, float* __restrict w, Sums& total) {
  using detail::Float4;
  using detail::Int4;
  using detail::load4;
  using detail::select4;
  using detail::splat4;
  using detail::store4;
  const Int4 segment = c.segment ? Int4{-1, -1, -1, -1} : Int4{};
  const Float4 zero = splat4(0.0f), one = splat4(1.0f);
  Float4 sw{}, sw2{}, sv{}, sr{}, sr2{}, sin{};
  std::size_t i = 0;
  for (; i + 4 <= m; i += 4) {
    const Float4 h = load4(hs + i), before = load4(h0 + i);
    // Segment mean (trapezoid of the elevation at the last update and now) when known.
    const Float4 pred = select4(segment & (before == before), 0.5f * (before + h), h);
    store4(h0 + i, c.track_h0 ? h : before);
    const Float4 b = load4(bb + i);
    const Float4 r = c.z - (pred + b + load4(an + i));
    const Float4 wi = load4(w + i) * c.renorm;
    const Float4 r2 = r * r;
    const Int4 valid = r2 == r2;  // false for voids / off the tile (NaN)
    const Float4 ll = select4(valid, -r2 * c.inv_2r, splat4(c.no_info_ll));  // Gaussian likelihood, Eq. 5-7
    Float4 wn = wi * detail::fast_exp_neg4(ll);
    wn = select4(wn < 1e-30f, zero, wn);  // keep clear of denormals
    store4(w + i, wn);
    const Float4 r_ok = select4(valid, r, zero);
    const Float4 wv = select4(valid, wi, zero);
    store4(bb + i, b + c.gain_k * r_ok);  // Rao-Blackwellised bias mean (gain 0 otherwise)
    sw += wn;
    sw2 += wn * wn;
    sv += wv;
    sr += wv * r_ok;
    sr2 += wv * r_ok * r_ok;
    sin += select4(valid & (r2 <= c.outlier_r2), one, zero);
  }
  for (; i < m; ++i) {  // tail: lane 0
    const float h = hs[i], before = h0[i];
    const float pred = c.segment && before == before ? 0.5f * (before + h) : h;
    h0[i] = c.track_h0 ? h : before;
    const float r = c.z - (pred + bb[i] + an[i]);
    const float wi = w[i] * c.renorm;
    const float r2 = r * r;
    const bool valid = r2 == r2;
    float wn = wi * detail::fast_exp_neg(valid ? -r2 * c.inv_2r : c.no_info_ll);
    wn = wn < 1e-30f ? 0.0f : wn;
    w[i] = wn;
    const float r_ok = valid ? r : 0.0f;
    const float wv = valid ? wi : 0.0f;
    bb[i] += c.gain_k * r_ok;
    sw[0] += wn;
    sw2[0] += wn * wn;
    sv[0] += wv;
    sr[0] += wv * r_ok;
    sr2[0] += wv * r_ok * r_ok;
    sin[0] += valid && r2 <= c.outlier_r2 ? 1.0f : 0.0f;
  }
  const auto lane_sum = [](Float4 v) {
    return static_cast<double>(v[0]) + static_cast<double>(v[1]) + static_cast<double>(v[2]) + static_cast<double>(v[3]);
  };
  total.w += lane_sum(sw);
  total.w2 += lane_sum(sw2);
  total.valid += lane_sum(sv);
  total.r += lane_sum(sr);
  total.r2 += lane_sum(sr2);
  total.within += lane_sum(sin);
}

/// Weighted mean (Eq. 8) and covariance (Eq. 9) of a cloud: two passes (mean, then centred
/// second moments) in 4-lane float partials added to double totals every kBlock particles;
/// positions relative to the first particle, so float keeps millimetres on any tile.
struct CloudMoments {
  double sw = 0, me = 0, mn = 0, cee = 0, cnn = 0, cen = 0;
};

/// The same moments in double, particle by particle: used when the float partials overflow (a
/// cloud spread over more than ~1e19 m, e.g. dead reckoning fed absurd steps), so the estimate
/// stays finite as it was before the float lanes.
CloudMoments cloud_moments_double(const float* e, const float* n, const float* w, std::size_t count) {
  CloudMoments c;
  double se = 0, sn = 0;
  for (std::size_t i = 0; i < count; ++i) {
    c.sw += w[i];
    se += static_cast<double>(w[i]) * e[i];
    sn += static_cast<double>(w[i]) * n[i];
  }
  if (!(c.sw > 0.0)) c.sw = 1.0;
  c.me = se / c.sw;
  c.mn = sn / c.sw;
  for (std::size_t i = 0; i < count; ++i) {
    const double wi = w[i], de = e[i] - c.me, dn = n[i] - c.mn;
    c.cee += wi * de * de / c.sw;
    c.cnn += wi * dn * dn / c.sw;
    c.cen += wi * de * dn / c.sw;
  }
  return c;
}

CloudMoments cloud_moments(const float* e, const float* n, const float* w, std::size_t count) {
  using detail::Float4;
  using detail::load4;
  CloudMoments c;
  if (count == 0) return c;
  const auto lane_sum = [](Float4 v) {
    return static_cast<double>(v[0]) + static_cast<double>(v[1]) + static_cast<double>(v[2]) + static_cast<double>(v[3]);
  };
  const float e0 = e[0], n0 = n[0];
  double se = 0, sn = 0;
  std::size_t i = 0;
  while (i + 4 <= count) {
    Float4 aw{}, ae{}, an{};
    for (const std::size_t end = std::min(count, i + kBlock); i + 4 <= end; i += 4) {
      const Float4 wi = load4(w + i);
      aw += wi;
      ae += wi * (load4(e + i) - e0);
      an += wi * (load4(n + i) - n0);
    }
    c.sw += lane_sum(aw);
    se += lane_sum(ae);
    sn += lane_sum(an);
  }
  for (; i < count; ++i) {
    c.sw += w[i];
    se += static_cast<double>(w[i]) * (e[i] - e0);
    sn += static_cast<double>(w[i]) * (n[i] - n0);
  }
  if (!(c.sw > 0.0)) c.sw = 1.0;
  const double de_mean = se / c.sw, dn_mean = sn / c.sw;
  c.me = e0 + de_mean;
  c.mn = n0 + dn_mean;
  const auto fe = static_cast<float>(de_mean) + e0, fn = static_cast<float>(dn_mean) + n0;
  // Centre on the float mean; the residual offset (< 1 ulp of the position) is corrected below.
  double see = 0, snn = 0, sen = 0, sde = 0, sdn = 0;
  i = 0;
  while (i + 4 <= count) {
    Float4 aee{}, ann{}, aen{}, ae{}, an{};
    for (const std::size_t end = std::min(count, i + kBlock); i + 4 <= end; i += 4) {
      const Float4 wi = load4(w + i), de = load4(e + i) - fe, dn = load4(n + i) - fn;
      const Float4 wde = wi * de, wdn = wi * dn;
      aee += wde * de;
      ann += wdn * dn;
      aen += wde * dn;
      ae += wde;
      an += wdn;
    }
    see += lane_sum(aee);
    snn += lane_sum(ann);
    sen += lane_sum(aen);
    sde += lane_sum(ae);
    sdn += lane_sum(an);
  }
  for (; i < count; ++i) {
    const double wi = w[i], de = e[i] - fe, dn = n[i] - fn;
    see += wi * de * de;
    snn += wi * dn * dn;
    sen += wi * de * dn;
    sde += wi * de;
    sdn += wi * dn;
  }
  const double mde = sde / c.sw, mdn = sdn / c.sw;  // mean offset from the centre used
  c.cee = std::max(0.0, see / c.sw - mde * mde);
  c.cnn = std::max(0.0, snn / c.sw - mdn * mdn);
  c.cen = sen / c.sw - mde * mdn;
  if (!std::isfinite(c.me) || !std::isfinite(c.mn) || !std::isfinite(c.cee) || !std::isfinite(c.cnn) ||
      !std::isfinite(c.cen))
    return cloud_moments_double(e, n, w, count);
  return c;
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
  o.dem_error_sigma_m = 5.0;
  o.dem_error_corr_m = 150.0;
  o.baro_scale_sigma = 0.017;
  o.stride_grade_sigma = 0.10;
  o.stride_grade_corr_m = 300.0;
  o.stride_walk_grade_sigma = 0.15;  // issue 28: route-mean grade, a walk constant (docs/terrain.md)
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
  LaneRng lanes;                // propagation noise: kBlock vectorised streams
  std::unique_ptr<BlockScratch> scratch = std::make_unique<BlockScratch>();

  bool initialized = false;
  TimeNs t_ns = 0;              // time of the last step (or initialisation)
  geo::BaroAltimeter baro;
  bool baro_usable = false;     // anchored at a valid DEM elevation
  double baro_sum_m = 0.0;
  int baro_count = 0;
  double walked_since_update_m = 0.0;
  double bias_var_m2 = 0.0;     // Rao-Blackwellised baro bias: common Kalman variance P
  double last_z_m = kNaN;       // barometer altitude at the last update (scale-error term)

  std::vector<double> nis_window;
  std::size_t nis_next = 0;
  std::size_t nis_filled = 0;
  TimeNs recovering_until_ns = std::numeric_limits<TimeNs>::min();
  std::string alarm;            // last residual-monitor alarm
  TerrainStats stats;
  std::string start_err;        // why the last initialize() was refused
  bool h0_stale = false;        // an update was skipped: segment-start elevations are stale
  std::uint64_t version = 0;    // bumped by every change the estimate can see
  mutable std::uint64_t cache_version = ~std::uint64_t{0};
  mutable Estimate cache_est;
  mutable std::vector<TerrainMode> cache_modes;

  Impl(const TerrainOptions& o, std::shared_ptr<const Dem> d, std::uint64_t seed)
      : opt(o), dem(std::move(d)), rng(seed), lanes(seed ^ 0x6A09E667F3BCC909ULL) {
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
    nis_window.assign(static_cast<std::size_t>(std::max(1, opt.monitor_window)), 0.0);
  }

  float normal() { return normal_from_bits(rng.next()); }

  bool recovering() const { return t_ns < recovering_until_ns; }

  double start_sigma(double sigma_m) const {
    return std::isfinite(sigma_m) && sigma_m > 0 ? sigma_m : opt.initial_sigma_m;
  }

  /// Empty when the start area fits the tile (or the start is off the tile / on a void: that
  /// start is accepted as degraded dead reckoning), else the reason for refusing it.
  std::string start_problem(const geo::Geodetic& start, double sigma_m) const {
    const Eigen::Vector2d en = dem->to_local(start);
    if (!en.allFinite() || !dem->at_local(en.x(), en.y()).valid()) return {};
    const double s = start_sigma(sigma_m);
    const double reach = opt.start_coverage_sigmas * s;
    const double beyond = std::max({dem->min_e_m() - (en.x() - reach), (en.x() + reach) - dem->max_e_m(),
                                    dem->min_n_m() - (en.y() - reach), (en.y() + reach) - dem->max_n_m()});
    if (!(beyond > 0.0)) return {};
    std::ostringstream os;
    os.precision(9);
    os << "terrain: start sigma " << s << " m refused: the " << opt.start_coverage_sigmas << "-sigma start area (+-"
       << reach << " m around " << start.lat_deg() << ", " << start.lon_deg() << ") reaches " << beyond
       << " m beyond the DEM tile (" << dem->max_e_m() - dem->min_e_m() << " x " << dem->max_n_m() - dem->min_n_m()
       << " m); declare a tighter start or use a larger tile";
    return os.str();
  }

  void initialize(const geo::Geodetic& start, double sigma_m, TimeNs t) {
    ++version;
    start_err = start_problem(start, sigma_m);
    if (!start_err.empty()) {
      initialized = false;
      t_ns = t;
      return;
    }
    const Eigen::Vector2d en = dem->to_local(start);
    const auto s = static_cast<float>(start_sigma(sigma_m));
    const auto hs = static_cast<float>(opt.heading_bias_sigma_rad);
    const auto bs = static_cast<float>(opt.baro_bias_sigma_m);
    // Per-walk step-scale draw: the walker's stride vs the model and, with the grade stride
    // term, the route's mean-grade shortening (independent, so in quadrature).
    const double walk_grade = opt.stride_grade_sigma > 0.0 ? opt.stride_walk_grade_sigma : 0.0;
    const auto ss = static_cast<float>(std::hypot(opt.step_scale_sigma, walk_grade));
    const DemSample ground = dem->at_local(en.x(), en.y());
    const auto h_start = static_cast<float>(ground.valid() ? ground.elevation_m : kNaN);
    for (std::size_t i = 0; i < count; ++i) {
      p.e[i] = static_cast<float>(en.x()) + s * normal();
      p.n[i] = static_cast<float>(en.y()) + s * normal();
      p.bh[i] = hs * normal();
      p.bb[i] = opt.rao_blackwell_baro_bias ? 0.0f : bs * normal();
      p.sc[i] = ss * normal();
      p.h0[i] = dem->elevation_or_nan(p.e[i], p.n[i]);
      // The barometer reads DEM(declared start) at the start; a particle that starts at x_i
      // explains that reading only with the offset DEM(declared) - DEM(x_i) (docs/terrain.md).
      const float an = h_start - p.h0[i];
      p.an[i] = an == an && opt.anchor_start_bias ? an : 0.0f;
      w[i] = 1.0f;
    }
    h0_stale = false;
    stats.uninformative = false;
    stats.relief_m = 0.0;
    w_sum = sum_sq = static_cast<double>(count);
    t_ns = t;
    initialized = true;
    restart_baro_average();
    walked_since_update_m = 0.0;
    last_pa = last_h_m = kNaN;
    stats.baro_jump_offset_m = 0.0;
    stats.baro_stuck = false;
    bias_var_m2 = opt.baro_bias_sigma_m * opt.baro_bias_sigma_m;
    last_z_m = kNaN;
    nis_filled = nis_next = 0;
    recovering_until_ns = std::numeric_limits<TimeNs>::min();
    alarm.clear();
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
    const bool stuck_before = stats.baro_stuck;
    const std::int64_t jumps_before = stats.baro_jumps;
    feed_pressure_checked(s);
    if (stats.baro_stuck != stuck_before || stats.baro_jumps != jumps_before) ++version;  // the reason changes
  }

  void feed_pressure_checked(const PressureSample& s) {
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
    ++version;
    ++stats.steps;
    walked_since_update_m += step.length_m;
    bool measure = baro_usable && baro_count > 0 && walked_since_update_m >= opt.update_distance_m;
    const bool due = measure;
    if (measure && opt.uninformative_relief_sigmas > 0.0) {
      stats.relief_m = relief_around_cloud();
      stats.uninformative = stats.relief_m < opt.uninformative_relief_sigmas * std::sqrt(opt.measurement_var_m2);
      if (stats.uninformative) {  // featureless: the update could only lock on DEM noise
        ++stats.uninformative_updates;
        measure = false;
        h0_stale = true;
      }
    }
    const double z = measure ? baro_sum_m / baro_count : kNaN;
    propagate_and_weight(step, dt_s, z);
    if (due) {
      restart_baro_average();
      walked_since_update_m = 0.0;
    }
    const double neff = neff_fraction();
    stats.neff_fraction = neff;
    if (measure && neff < opt.resample_threshold) resample();
  }

  double sum_sq = 0.0;  // sum of squared unnormalised weights (for Neff)

  /// DEM relief around the cloud: 1-sigma of the elevations at the cloud's weighted mean and
  /// on rings of radius r/2 (8 points) and r (16 points), r = max(informative_radius_m,
  /// 2 sigma of the cloud). Mean and sigma from 64 evenly strided particles (a relief scale,
  /// not an estimate). Voids and off-tile points are left out (0 when fewer than 3 remain).
  double relief_around_cloud() const {
    const std::size_t stride = std::max<std::size_t>(1, count / 64);
    double sw = 0, se = 0, sn = 0, see = 0, snn = 0;
    for (std::size_t i = 0; i < count; i += stride) {
      const double wi = w[i], e = p.e[i], n = p.n[i];
      sw += wi;
      se += wi * e;
      sn += wi * n;
      see += wi * e * e;
      snn += wi * n * n;
    }
    if (!(sw > 0.0)) return 0.0;
    const double me = se / sw, mn = sn / sw;
    const double var = std::max(0.0, see / sw - me * me) + std::max(0.0, snn / sw - mn * mn);
    const double r = std::max(opt.informative_radius_m, 2.0 * std::sqrt(0.5 * var));
    double s1 = 0, s2 = 0;
    int k = 0;
    auto add = [&](double e, double n) {
      const DemSample h = dem->at_local(e, n);
      if (!h.valid()) return;
      s1 += h.elevation_m;
      s2 += h.elevation_m * h.elevation_m;
      ++k;
    };
    add(me, mn);
    for (int j = 0; j < 8; ++j) add(me + 0.5 * r * std::sin(j * kPi / 4), mn + 0.5 * r * std::cos(j * kPi / 4));
    for (int j = 0; j < 16; ++j)
      add(me + r * std::sin(j * kPi / 8 + kPi / 16), mn + r * std::cos(j * kPi / 8 + kPi / 16));
    if (k < 3) return 0.0;
    const double mean = s1 / k;
    return std::sqrt(std::max(0.0, s2 / k - mean * mean));
  }

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
      // Correlated DEM error (docs/terrain.md "issue 17, world errors"): the DEM error under a
      // walker changes with distance walked, not time (correlation length L): the bias, which
      // holds it, gains sigma^2 (1 - exp(-2 l / L)) per step of length l (a FOGM in distance).
      if (opt.dem_error_sigma_m > 0.0 && opt.dem_error_corr_m > 0.0)
        bias_var_m2 += opt.dem_error_sigma_m * opt.dem_error_sigma_m *
                       (1.0 - std::exp(-2.0 * std::max(0.0, step.length_m) / opt.dem_error_corr_m));
      // Barometric scale error (the day's temperature vs the ISA the altimeter assumes) makes the
      // altitude error grow with the height climbed or descended since the last update.
      if (std::isfinite(z) && opt.baro_scale_sigma > 0.0) {
        if (std::isfinite(last_z_m)) {
          const double dz = opt.baro_scale_sigma * (z - last_z_m);
          bias_var_m2 += dz * dz;
        }
        last_z_m = z;
      }
    }
    q_h *= static_cast<float>(gain);
    const auto len = static_cast<float>(step.length_m);
    // Stride varies with grade along the route (shorter uphill and down; Minetti 1995 gait data):
    // the scale state is a FOGM in distance (sigma, correlation length) on top of its per-walk
    // draw. It reuses the bias noise draw, which is free when the bias is Rao-Blackwellised.
    float phi_s = 1.0f, q_s = 0.0f;
    if (rb && opt.stride_grade_sigma > 0.0 && opt.stride_grade_corr_m > 0.0) {
      const double ph = std::exp(-std::max(0.0, step.length_m) / opt.stride_grade_corr_m);
      phi_s = static_cast<float>(ph);
      q_s = static_cast<float>(opt.stride_grade_sigma * std::sqrt(std::max(0.0, 1.0 - ph * ph)));
    }
    PropagateCoeffs k;
    k.dl_span = static_cast<float>(2.0 * opt.step_length_sigma_m * gain);
    k.s_th = static_cast<float>(std::sin(step.heading_rad));
    k.c_th = static_cast<float>(std::cos(step.heading_rad));
    k.len = len;
    k.phi_h = phi_h;
    k.q_h = q_h;
    k.phi_b = phi_b;
    k.q_b = q_b;
    k.phi_s = phi_s;
    k.q_s = q_s;
    const bool measure = std::isfinite(z);
    WeighCoeffs wc;
    wc.z = static_cast<float>(z);
    const double innov_var = innovation_var();  // Eq. 5-7 (+ P)
    wc.inv_2r = static_cast<float>(0.5 / innov_var);
    wc.no_info_ll = static_cast<float>(-0.5 * opt.no_info_sigmas * opt.no_info_sigmas);
    wc.renorm = static_cast<float>(static_cast<double>(count) / w_sum);  // keeps mean weight ~1
    wc.outlier_r2 = static_cast<float>(opt.monitor_outlier_sigmas * opt.monitor_outlier_sigmas * innov_var);
    // Rao-Blackwellised bias: the Kalman gain is common to all particles, so each mean is
    // updated with its own residual in the weighting pass (voids / off the tile: no update).
    const double gain_k = rb ? bias_var_m2 / innov_var : 0.0;
    wc.gain_k = static_cast<float>(gain_k);
    wc.segment = opt.segment_mean_elevation && !h0_stale;
    wc.track_h0 = opt.segment_mean_elevation;
    if (measure) h0_stale = false;
    const Dem::Grid grid = dem->grid();
    Sums total;
    BlockScratch& b = *scratch;
    // Blocks of kBlock particles: the scratch (random words, cell indices, elevations) stays in
    // L1; pass 1 and 3 are plain float loops that GCC vectorises, pass 2 is the scalar gather.
    for (std::size_t base = 0; base < count; base += kBlock) {
      const std::size_t m = std::min(kBlock, count - base);
      lanes.fill4(b.r0, b.r1, b.r2, b.r3);
      propagate_block(k, m, p.e.data() + base, p.n.data() + base, p.bh.data() + base, p.bb.data() + base,
                      p.sc.data() + base, b);
      if (!measure) continue;
      locate_block(grid, m, p.e.data() + base, p.n.data() + base, b);
      gather_block(grid, m, b);
      weigh_block(wc, m, b.h, p.h0.data() + base, p.bb.data() + base, p.an.data() + base, w.data() + base,
                  total);
    }
    if (!measure) return;
    if (rb) bias_var_m2 *= 1.0 - gain_k;  // before a recovery in the monitor widens it again
    finish_update(total, innov_var);
  }

  /// Totals of the update; innov_var is the innovation variance the weights used.
  void finish_update(const Sums& sums, double innov_var) {
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
    monitor(s_valid, sums.r, sums.r2, sums.within, innov_var);
  }

  /// Residual monitoring: window mean of the normalised innovation squared of the baro
  /// measurement against the particle prediction (r_var: the update's innovation variance);
  /// alarms re-spread the cloud.
  void monitor(double s_valid, double s_r, double s_r2, double within, double r_var) {
    const double mean_r = s_r / s_valid;  // z - mean prediction
    const double var = std::max(0.0, s_r2 / s_valid - mean_r * mean_r);
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
    const bool outlier = !(within > 0.0);  // no valid particle within out sigmas (weigh_block)
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

  /// The estimate and the modes, recomputed only when something they depend on changed.
  void refresh() const {
    if (cache_version == version) return;
    cache_modes.clear();
    cache_est = compute_estimate();
    cache_version = version;
  }

  /// Weighted moments of a group of particles.
  struct Moments {
    double w = 0, e = 0, n = 0, ee = 0, nn = 0, en = 0;
    void add(double wi, double x, double y) {
      w += wi;
      e += wi * x;
      n += wi * y;
      ee += wi * x * x;
      nn += wi * y * y;
      en += wi * x * y;
    }
    void add(const Moments& o) {
      w += o.w;
      e += o.e;
      n += o.n;
      ee += o.ee;
      nn += o.nn;
      en += o.en;
    }
    Eigen::Vector2d mean() const { return w > 0 ? Eigen::Vector2d(e / w, n / w) : Eigen::Vector2d::Zero(); }
    Eigen::Matrix2d cov() const {
      const Eigen::Vector2d m = mean();
      Eigen::Matrix2d c;
      c(0, 0) = std::max(0.0, ee / w - m.x() * m.x());
      c(1, 1) = std::max(0.0, nn / w - m.y() * m.y());
      c(0, 1) = c(1, 0) = en / w - m.x() * m.y();
      return w > 0 ? c : Eigen::Matrix2d::Zero();
    }
  };

  /// Modes along the cloud's major axis: a 48-bin weighted histogram of the projections (+-4 sigma),
  /// smoothed twice with [1 2 1]/4, cut at valleys deeper than mode_valley_fraction of the
  /// smaller neighbouring peak; groups lighter than mode_min_weight join their neighbour
  /// across the shallower cut, groups closer than mode_min_separation_m merge.
  /// Empty: one mode, the estimate itself (a cloud narrower than mode_min_separation_m / 4, or
  /// a histogram without a valley: then the per-bin moments are never computed).
  std::vector<Moments> find_modes(const Eigen::Vector2d& mean, const Eigen::Matrix2d& cov) const {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    const double major_sd = std::sqrt(std::max(0.0, eig.eigenvalues()(1)));
    if (!(major_sd > 0.25 * opt.mode_min_separation_m)) return {};
    const Eigen::Vector2d u = eig.eigenvectors().col(1);
    constexpr int kBins = 48;
    // +-4 sigma along the major axis (one pass; particles beyond go to the end bins).
    const double lo = -4.0 * major_sd, hi = 4.0 * major_sd;
    const double scale = kBins / (hi - lo) * (1.0 - 1e-9);
    // Bin of a particle, in float (a bin is 1/6 sigma wide); NaN and far-out particles land
    // in the end bins.
    const auto me = static_cast<float>(mean.x()), mn = static_cast<float>(mean.y());
    const auto ux = static_cast<float>(u.x() * scale), uy = static_cast<float>(u.y() * scale);
    const auto f0 = static_cast<float>(-lo * scale);
    const auto bin_of = [&](std::size_t i) {
      const float f = (p.e[i] - me) * ux + (p.n[i] - mn) * uy + f0;
      return f > 0.0f ? (f < kBins - 1.0f ? static_cast<int>(f) : kBins - 1) : 0;
    };
    // Pass 1: the weight histogram alone. The per-bin moments (pass 2) are needed only when
    // the histogram has a valley, i.e. when the cloud may be multimodal.
    std::array<double, kBins> h{};
    for (std::size_t i = 0; i < count; ++i) h[static_cast<std::size_t>(bin_of(i))] += w[i];
    double all_w = 0.0;
    for (double v : h) all_w += v;
    if (!(all_w > 0)) return {};
    for (int pass = 0; pass < 2; ++pass) {
      std::array<double, kBins> g{};
      for (int b = 0; b < kBins; ++b)
        g[b] = 0.25 * (b > 0 ? h[b - 1] : 0.0) + 0.5 * h[b] + 0.25 * (b + 1 < kBins ? h[b + 1] : 0.0);
      h = g;
    }
    // Cuts: walk left to right keeping the highest peak since the last cut.
    std::vector<int> cuts;      // a cut at b: bins < b on the left
    std::vector<double> depth;  // valley / smaller peak at each cut (smaller = deeper)
    int peak = 0, valley = 0;  // highest bin since the last cut; lowest bin after it (== peak: none)
    for (int b = 1; b < kBins; ++b) {
      if (valley == peak || h[b] < h[valley]) valley = b;
      const double smaller = std::min(h[peak], h[b]);
      if (valley != b && h[valley] < opt.mode_valley_fraction * smaller) {  // rising out of a deep valley
        cuts.push_back(valley);
        depth.push_back(h[valley] / smaller);
        peak = valley = b;
      } else if (h[b] >= h[peak]) {  // a higher peak without a deep valley between: same group
        peak = valley = b;
      }
    }
    if (cuts.empty()) return {};  // one group: the estimate itself
    std::array<Moments, kBins> bin{};
    for (std::size_t i = 0; i < count; ++i)
      if (w[i] > 0.0f) bin[static_cast<std::size_t>(bin_of(i))].add(w[i], p.e[i], p.n[i]);
    std::vector<Moments> groups;
    std::vector<double> cut_depth;  // between groups[k] and groups[k + 1]
    int start = 0;
    for (std::size_t c = 0; c <= cuts.size(); ++c) {
      const int end = c < cuts.size() ? cuts[c] : kBins;
      Moments m;
      for (int b = start; b < end; ++b) m.add(bin[static_cast<std::size_t>(b)]);
      groups.push_back(m);
      if (c < cuts.size()) cut_depth.push_back(depth[c]);
      start = end;
    }
    auto merge = [&](std::size_t k) {  // groups k and k + 1
      groups[k].add(groups[k + 1]);
      groups.erase(groups.begin() + static_cast<long>(k) + 1);
      cut_depth.erase(cut_depth.begin() + static_cast<long>(k));
    };
    for (bool changed = true; changed && groups.size() > 1;) {
      changed = false;
      for (std::size_t k = 0; k < groups.size() && groups.size() > 1; ++k) {
        if (groups[k].w >= opt.mode_min_weight * all_w) continue;
        if (k == 0) merge(0);
        else if (k + 1 == groups.size()) merge(k - 1);
        else merge(cut_depth[k - 1] > cut_depth[k] ? k - 1 : k);  // across the shallower cut
        changed = true;
        break;
      }
      for (std::size_t k = 0; !changed && k + 1 < groups.size(); ++k) {
        if ((groups[k].mean() - groups[k + 1].mean()).norm() < opt.mode_min_separation_m) {
          merge(k);
          changed = true;
        }
      }
    }
    std::sort(groups.begin(), groups.end(), [](const Moments& a, const Moments& b) { return a.w > b.w; });
    return groups;
  }

  Estimate compute_estimate() const {
    Estimate est;
    est.engine = EngineKind::kTerrain;
    est.t_ns = t_ns;
    if (!initialized) {
      est.reason = start_err.empty() ? "terrain: no start position" : start_err;
      return est;
    }
    const CloudMoments cm = cloud_moments(p.e.data(), p.n.data(), w.data(), count);
    const double sw = cm.sw, me = cm.me, mn = cm.mn;
    est.en_m = Eigen::Vector2d(me, mn);  // Eq. 8
    est.cov_en_m2 << cm.cee, cm.cen, cm.cen, cm.cnn;  // Eq. 9
    est.position = dem->to_geodetic(me, mn);
    const DemSample ground = dem->at_local(me, mn);
    est.position.h_m = ground.valid() ? ground.elevation_m : 0.0;  // DEM datum (docs/terrain.md)
    est.vertical_sigma_m = std::sqrt(opt.measurement_var_m2);
    const std::vector<Moments> groups = find_modes(est.en_m, est.cov_en_m2);
    if (groups.empty()) {
      TerrainMode m;
      m.en_m = est.en_m;
      m.cov_en_m2 = est.cov_en_m2;
      m.weight = 1.0;
      m.position = dem->to_geodetic(m.en_m.x(), m.en_m.y());
      cache_modes.push_back(m);
    }
    for (const Moments& g : groups) {
      TerrainMode m;
      m.en_m = g.mean();
      m.cov_en_m2 = g.cov();
      m.weight = g.w / sw;
      m.position = dem->to_geodetic(m.en_m.x(), m.en_m.y());
      cache_modes.push_back(m);
    }
    status_and_reason(est);
    return est;
  }

  void status_and_reason(Estimate& est) const {
    est.status = EstimateStatus::kOk;
    std::ostringstream os;
    os.precision(3);
    os << "terrain PF " << count << " particles";
    if (cache_modes.size() > 1) {
      est.status = EstimateStatus::kAmbiguous;
      os << "; ambiguous: " << cache_modes.size() << " modes";
      for (const TerrainMode& m : cache_modes) {
        const ErrorEllipse el = ErrorEllipse::from_covariance(m.cov_en_m2);
        os << ", " << std::lround(100.0 * m.weight) << "% at " << std::fixed << std::setprecision(6)
           << m.position.lat_deg() << " " << m.position.lon_deg() << std::defaultfloat << std::setprecision(3)
           << " (1-sigma " << el.semi_major_m << " x " << el.semi_minor_m << " m)";
      }
      os << "; the mean and ellipse span them";
    }
    if (stats.uninformative) {
      est.status = est.status == EstimateStatus::kAmbiguous ? est.status : EstimateStatus::kDegraded;
      os << "; terrain uninformative (relief " << stats.relief_m << " m under the cloud, below the "
         << opt.uninformative_relief_sigmas * std::sqrt(opt.measurement_var_m2)
         << " m noise): no terrain update, sigma growing as dead reckoning";
    }
    if (!baro_usable) {
      est.status = EstimateStatus::kDegraded;
      os << "; start is off the DEM or on a void: no terrain updates (dead reckoning)";
    } else if (stats.updates == 0) {
      os << "; waiting for barometer";
    }
    const auto degrade = [&] {
      if (est.status != EstimateStatus::kAmbiguous) est.status = EstimateStatus::kDegraded;
    };
    if (stats.off_dem_fraction > 0.5) {
      degrade();
      os << "; " << 100.0 * stats.off_dem_fraction << "% of the weight off the DEM or on voids";
    }
    if (stats.baro_stuck) {
      degrade();
      os << "; barometer stuck (one value for " << opt.baro_stuck_s << "+ s): terrain updates paused";
    }
    if (stats.baro_jumps > 0) os << "; " << stats.baro_jumps << " barometer step(s) compensated";
    if (recovering()) {
      degrade();
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
Estimate TerrainEngine::estimate() const {
  impl_->refresh();
  return impl_->cache_est;
}
std::vector<TerrainMode> TerrainEngine::modes() const {
  impl_->refresh();
  return impl_->cache_modes;
}
std::string TerrainEngine::start_problem(const geo::Geodetic& start, double sigma_m) const {
  return impl_->start_problem(start, sigma_m);
}
void TerrainEngine::check_start(const geo::Geodetic& start, double sigma_m) const {
  const std::string why = impl_->start_problem(start, sigma_m);
  if (!why.empty()) throw std::invalid_argument(why);
}
const std::string& TerrainEngine::start_error() const { return impl_->start_err; }
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

std::vector<double> TerrainEngine::particle_weights(std::size_t max) const {
  std::vector<double> out;
  const std::size_t n = impl_->count;
  if (max == 0 || !impl_->initialized) return out;
  double total = 0.0;
  for (float wi : impl_->w) total += wi;
  const double inv = total > 0.0 ? 1.0 / total : 0.0;
  const std::size_t take = std::min(max, n);
  out.reserve(take);
  for (std::size_t k = 0; k < take; ++k) out.push_back(impl_->w[k * n / take] * inv);
  return out;
}

Eigen::Vector2d TerrainEngine::bias_estimate() const {
  double sw = 0.0, sh = 0.0, sb = 0.0;
  for (std::size_t i = 0; i < impl_->count; ++i) {
    sw += impl_->w[i];
    sh += impl_->w[i] * impl_->p.bh[i];
    sb += impl_->w[i] * (impl_->p.bb[i] + impl_->p.an[i]);
  }
  if (!(sw > 0.0)) return {0.0, 0.0};
  return {sh / sw, sb / sw};
}

std::size_t TerrainEngine::bytes_per_particle() {
  // 7 floats (5 states + segment-start elevation + start-anchor offset) x 2 buffers + 1 float
  // weight + 1 double resampling scratch (the step's residuals live in a per-block scratch)
  return 2 * 7 * sizeof(float) + sizeof(float) + sizeof(double);
}

}  // namespace pdnav::terrain
