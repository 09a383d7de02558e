#include "pdnav/fusion/pdr_calibrator.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <vector>

namespace pdnav::fusion {

// A step of length L at heading h (clockwise from north) moves (L sin h, L cos h), i.e.
// z = i L exp(-i h). With the measured heading h = h_true + b and L = L_true / s, the true
// displacement is s exp(i b) z: the complex gain c of the fit.
void PdrCalibrator::add_step(const PdrStep& s) {
  if (!std::isfinite(s.length_m) || !std::isfinite(s.heading_rad) || s.length_m < 0.0) return;
  track_ += std::complex<double>(s.length_m * std::sin(s.heading_rad), s.length_m * std::cos(s.heading_rad));
  steps_.emplace_back(s.t_ns, track_);
  while (steps_.size() > opt_.max_steps_kept) steps_.pop_front();
  const TimeNs keep_ns = static_cast<TimeNs>(opt_.window_s * 1e9) + 60 * kNsPerS;
  while (steps_.size() > 2 && steps_.front().first < s.t_ns - keep_ns) steps_.pop_front();
}

std::complex<double> PdrCalibrator::pdr_at(TimeNs t_ns) const {
  if (steps_.empty()) return track_;
  // last step at or before t_ns
  auto it = std::upper_bound(steps_.begin(), steps_.end(), t_ns,
                             [](TimeNs t, const std::pair<TimeNs, std::complex<double>>& x) { return t < x.first; });
  if (it == steps_.begin()) {
    // before every kept step: the track before the first kept step
    const auto& f = steps_.front();
    return f.second;  // (one step of error at most, only at the very start)
  }
  return (it - 1)->second;
}

void PdrCalibrator::add_gnss(TimeNs t_ns, const Eigen::Vector2d& en_m, double sigma_m) {
  if (!en_m.allFinite() || !(sigma_m > 0.0) || !std::isfinite(sigma_m)) return;
  window_.push_back({t_ns, pdr_at(t_ns), std::complex<double>(en_m.x(), en_m.y()), 1.0 / (sigma_m * sigma_m)});
  forget_before_window(t_ns);
  fit();
}

// Positions and course samples leave the window together (course samples from before an
// outage go with the positions, not when the next course sample comes).
void PdrCalibrator::forget_before_window(TimeNs t_ns) {
  const TimeNs start_ns = t_ns - static_cast<TimeNs>(opt_.window_s * 1e9);
  while (!window_.empty() && window_.front().t_ns < start_ns) window_.pop_front();
  while (!courses_.empty() && courses_.front().t_ns < start_ns) courses_.pop_front();
  while (!speeds_.empty() && speeds_.front().t_ns < start_ns) speeds_.pop_front();
}

bool PdrCalibrator::straight_span(TimeNs t_ns, std::complex<double>* net, double* path_m, int* steps) const {
  const TimeNs from_ns = t_ns - static_cast<TimeNs>(opt_.course_pdr_span_s * 1e9);
  if (steps_.empty() || steps_.front().first > from_ns) return false;  // the PDR path before t_ns is not kept
  std::complex<double> prev = pdr_at(from_ns);
  *net = pdr_at(t_ns) - prev;
  *path_m = 0.0;
  *steps = 0;
  for (const auto& [t, z] : steps_) {
    if (t <= from_ns) continue;
    if (t > t_ns) break;
    *path_m += std::abs(z - prev);
    prev = z;
    ++*steps;
  }
  // a turn inside the span, or no step in it: the PDR and GNSS velocities are not comparable
  return *path_m > 0.0 && std::abs(*net) >= opt_.course_min_straightness * *path_m;
}

// The course sample: with the PDR direction h (clockwise from north) over the straight path
// just before t_ns and the GNSS course k, the bias is h - k (PDR heading = true + bias).
void PdrCalibrator::add_course(TimeNs t_ns, double course_rad, double speed_mps, double sigma_rad) {
  if (!opt_.use_course || !std::isfinite(course_rad) || !std::isfinite(speed_mps) || speed_mps < opt_.course_min_speed_mps)
    return;
  std::complex<double> net;
  double path = 0.0;
  int steps = 0;
  if (!straight_span(t_ns, &net, &path, &steps)) return;
  const double pdr_heading = 0.5 * kPi - std::arg(net);
  const double sigma = std::isfinite(sigma_rad) && sigma_rad > 0.0
                           ? sigma_rad
                           : std::atan2(opt_.course_velocity_sigma_mps, speed_mps);
  courses_.push_back({t_ns, std::remainder(pdr_heading - course_rad, 2.0 * kPi), 1.0 / (sigma * sigma)});
  forget_before_window(t_ns);
}

// The speed sample: the GNSS speed over the same straight span against the PDR path in it, as a
// log step scale (true length = scale x PDR length); its sigma from the speed's and from the
// whole steps a fixed span holds (uniform +-1/2 step: 1/sqrt(12) step).
void PdrCalibrator::add_speed(TimeNs t_ns, double speed_mps, double sigma_mps) {
  if (!opt_.use_speed || !std::isfinite(speed_mps) || speed_mps < opt_.course_min_speed_mps) return;
  std::complex<double> net;
  double path = 0.0;
  int steps = 0;
  if (!straight_span(t_ns, &net, &path, &steps)) return;
  const double sv = std::isfinite(sigma_mps) && sigma_mps > 0.0 ? sigma_mps : opt_.course_velocity_sigma_mps;
  const double sigma_log = std::hypot(sv / speed_mps, 1.0 / std::sqrt(12.0) / steps);
  speeds_.push_back({t_ns, std::log(speed_mps * opt_.course_pdr_span_s / path), 1.0 / (sigma_log * sigma_log)});
  forget_before_window(t_ns);
}

void PdrCalibrator::reset() {
  steps_.clear();
  window_.clear();
  courses_.clear();
  speeds_.clear();
  last_ = PdrCalibration{};
  published_ = PdrCalibration{};
}

namespace {
/// The integrated autocorrelation time (in samples) of a residual series, tau = 1 + 2 sum rho(k),
/// the sum measured, not extrapolated from rho(1), over Sokal's automatic window: the smallest M
/// with M >= 5 tau(M) (Sokal 1997, "Monte Carlo methods in statistical mechanics", Sec. 3; c = 5
/// as there). A smooth series (a chipset's filtered course, a 3 s PDR direction) has rho(1) near
/// 1 and decorrelates within seconds, where the AR(1) value (1 + rho(1)) / (1 - rho(1)) counted a
/// whole window as one sample; a long tail (multipath) counts in full. Complex residuals
/// (positions) correlate through Re(conj(r_i) r_i+k). 1 for fewer than 3 samples.
double autocorrelation_time(const std::vector<std::complex<double>>& r) {
  const std::size_t n = r.size();
  double c0 = 0.0;
  for (const auto& x : r) c0 += std::norm(x);
  if (n < 3 || !(c0 > 0.0)) return 1.0;
  double tau = 1.0;
  for (std::size_t k = 1; k < n; ++k) {
    double c = 0.0;
    for (std::size_t i = k; i < n; ++i) c += std::real(std::conj(r[i - k]) * r[i]);
    tau += 2.0 * c / c0;
    if (static_cast<double>(k) >= 5.0 * tau) break;
  }
  return std::clamp(tau, 1.0, static_cast<double>(n));
}

/// The effective number of independent samples of a time-correlated series (GNSS errors:
/// multipath, a chipset's own filter; PDR drift): the smaller of moving time / correlation time
/// and n / tau from the residuals' integrated autocorrelation time (von Storch & Zwiers 1999,
/// Sec. 17.1.3, as the GNSS filter's fix scale), so a run of smoothed fixes is never counted as
/// many.
double effective_samples(double n, double moving_s, double tau, const PdrCalibrationOptions& opt) {
  const double n_eff_ac = opt.residual_correlation ? n / tau : n;
  return std::clamp(std::min(moving_s / opt.correlation_time_s + 1.0, n_eff_ac), 1.0, n);
}

/// A heading bias fitted over a window and over its two halves (a: older, b: recent). Their
/// difference beyond what their own sigmas explain is how far the bias moved in the window (a
/// walk through magnetic disturbances moves it by tens of degrees); beyond 2 sigma the recent
/// half is the better predictor of the bias now (Gauss-Markov bias). Either way the bias now is
/// known no better than that movement: it is added to the sigma. Returns the movement (1-sigma).
double account_for_drift(double a_rad, double a_var, double b_rad, double b_var, double* bias_rad, double* sigma_rad) {
  const double d = std::remainder(b_rad - a_rad, 2.0 * kPi);
  const double var_d = a_var + b_var;
  const double drift = std::sqrt(std::max(0.0, d * d - var_d));
  if (d * d > 4.0 * var_d) {
    *bias_rad = b_rad;
    *sigma_rad = std::sqrt(b_var);
  }
  *sigma_rad = std::hypot(*sigma_rad, drift);
  return drift;
}

/// Inverse-variance combination of a second estimate (y, sy) into (x, sx), or (y, sy) itself
/// when there is no first one; angles (circular) combine along the shorter arc.
void combine(bool have_first, double* x, double* sx, double y, double sy, bool circular) {
  if (!have_first) {
    *x = y;
    *sx = sy;
    return;
  }
  const double wx = 1.0 / (*sx * *sx), wy = 1.0 / (sy * sy);
  *x = circular ? std::remainder(*x + std::remainder(y - *x, 2.0 * kPi) * wy / (wx + wy), 2.0 * kPi)
                : (wx * *x + wy * y) / (wx + wy);
  *sx = 1.0 / std::sqrt(wx + wy);
}

struct SeriesFit {
  bool ok = false;
  double mean = 0.0, var = 0.0;
};

/// Weighted mean (circular for angles: the course samples; linear: the log speed scales) of the
/// samples over [b, e), its variance inflated like the position fit's (residual variance
/// factor, effective number of samples).
template <typename It>
SeriesFit fit_series(It b, It e, const PdrCalibrationOptions& opt, bool circular) {
  SeriesFit f;
  const double n = static_cast<double>(std::distance(b, e));
  if (n < 2) return f;
  std::complex<double> sum = 0.0;
  double w_sum = 0.0, moving_s = 0.0, lin = 0.0;
  for (It x = b; x != e; ++x) {
    sum += x->w * std::polar(1.0, x->value);
    lin += x->w * x->value;
    w_sum += x->w;
    // a gap (standing, a turn) counts as at most one correlation time
    if (x != b) moving_s += std::min(opt.correlation_time_s, static_cast<double>(x->t_ns - std::prev(x)->t_ns) * 1e-9);
  }
  f.mean = circular ? std::arg(sum) : lin / w_sum;
  double chi2 = 0.0;
  std::vector<std::complex<double>> res;
  res.reserve(static_cast<std::size_t>(n));
  for (It x = b; x != e; ++x) {
    const double r = circular ? std::remainder(x->value - f.mean, 2.0 * kPi) : x->value - f.mean;
    chi2 += x->w * r * r;
    res.emplace_back(r, 0.0);
  }
  const double var_factor = std::max(1.0, chi2 / (n - 1.0));
  f.var = var_factor / w_sum * (n / effective_samples(n, moving_s, autocorrelation_time(res), opt));
  f.ok = true;
  return f;
}

struct RangeFit {
  bool ok = false;
  std::complex<double> gain = 0.0;
  double var_component = 0.0;  // of Re c and of Im c
  double baseline_m = 0.0, tau = 1.0, span_s = 0.0, moving_s = 0.0;
};
}  // namespace

// Weighted least squares of G = a + c P over window_[b, e), with the variance of c inflated by
// the residual variance factor and the effective number of independent epochs.
template <typename It>
static RangeFit fit_range(It b, It e, const PdrCalibrationOptions& opt) {
  RangeFit f;
  const double n = static_cast<double>(std::distance(b, e));
  if (n < 3) return f;
  double w_sum = 0.0;
  std::complex<double> p_mean = 0.0, g_mean = 0.0;
  for (It x = b; x != e; ++x) {
    w_sum += x->w;
    p_mean += x->w * x->p;
    g_mean += x->w * x->g;
  }
  p_mean /= w_sum;
  g_mean /= w_sum;
  double spp = 0.0, spread = 0.0;
  std::complex<double> spg = 0.0;
  for (It x = b; x != e; ++x) {
    const std::complex<double> dp = x->p - p_mean;
    spp += x->w * std::norm(dp);
    spread += std::norm(dp);
    spg += x->w * std::conj(dp) * (x->g - g_mean);
  }
  f.baseline_m = std::sqrt(spread / n);
  f.span_s = static_cast<double>(std::prev(e)->t_ns - b->t_ns) * 1e-9;
  // the time the PDR track moved between epochs: epochs of a walker standing still repeat one
  // PDR position and say nothing about the scale or the bias
  for (It x = std::next(b); x != e; ++x)
    if (x->p != std::prev(x)->p) f.moving_s += static_cast<double>(x->t_ns - std::prev(x)->t_ns) * 1e-9;
  if (!(spp > 0.0)) return f;
  f.gain = spg / spp;
  // variance factor from the residuals (2 n observations, 4 parameters), never below 1:
  // the weights are the GNSS sigmas, residuals can only say they were optimistic
  double chi2 = 0.0;
  std::vector<std::complex<double>> res;
  res.reserve(static_cast<std::size_t>(n));
  for (It x = b; x != e; ++x) {
    res.push_back(x->g - g_mean - f.gain * (x->p - p_mean));
    chi2 += x->w * std::norm(res.back());
  }
  const double dof = std::max(1.0, 2.0 * n - 4.0);
  const double var_factor = std::max(1.0, chi2 / dof);
  f.tau = autocorrelation_time(res);
  f.var_component = var_factor / spp * (n / effective_samples(n, f.moving_s, f.tau, opt));
  f.ok = true;
  return f;
}

void PdrCalibrator::fit() {
  PdrCalibration c;
  c.epochs = static_cast<int>(window_.size());
  c.t_ns = window_.empty() ? 0 : window_.back().t_ns;
  const RangeFit f = fit_range(window_.begin(), window_.end(), opt_);
  c.baseline_m = f.baseline_m;
  c.span_s = f.span_s;
  c.residual_tau = f.tau;
  if (f.ok) {
    const std::complex<double> gain = f.gain;
    const double var_component = f.var_component;
    c.scale = std::abs(gain);
    c.heading_bias_rad = std::arg(gain);
    c.scale_sigma = std::sqrt(var_component);
    c.heading_bias_sigma_rad = c.scale > 0.0 ? std::sqrt(var_component) / c.scale : kPi;
    // Did the bias stay put over the window? Fit the two halves of the PDR path separately
    // (account_for_drift); the movement is published as heading_bias_drift_sigma_rad.
    if (opt_.check_bias_drift && window_.size() >= 6) {
      double path = 0.0;
      for (std::size_t i = 1; i < window_.size(); ++i) path += std::abs(window_[i].p - window_[i - 1].p);
      double acc = 0.0;
      std::size_t mid = 1;
      for (; mid < window_.size(); ++mid) {
        acc += std::abs(window_[mid].p - window_[mid - 1].p);
        if (acc >= 0.5 * path) break;
      }
      const auto m = window_.begin() + static_cast<std::ptrdiff_t>(std::clamp<std::size_t>(mid, 3, window_.size() - 3));
      const RangeFit a = fit_range(window_.begin(), m, opt_), b = fit_range(m, window_.end(), opt_);
      if (a.ok && b.ok && std::abs(a.gain) > 0.0 && std::abs(b.gain) > 0.0)  // (the scale stays the whole window's)
        c.heading_bias_drift_sigma_rad =
            account_for_drift(std::arg(a.gain), a.var_component / std::norm(a.gain), std::arg(b.gain),
                              b.var_component / std::norm(b.gain), &c.heading_bias_rad, &c.heading_bias_sigma_rad);
    }
  }
  // The position fit says something only over a baseline; the course and speed samples (GNSS
  // velocity against the PDR over the same straight span) need none.
  c.positions_used = f.ok && c.baseline_m >= opt_.min_baseline_m;
  bool have_heading = c.positions_used && c.heading_bias_sigma_rad > 0.0;
  bool have_scale = c.positions_used && c.scale_sigma > 0.0;
  // The GNSS course: a second, independent sample of the heading bias (Doppler velocity, not
  // positions), with the same drift check over its two halves; inverse-variance combined.
  c.course_epochs = static_cast<int>(courses_.size());
  if (opt_.use_course && c.course_epochs >= opt_.course_min_epochs) {
    const SeriesFit k = fit_series(courses_.begin(), courses_.end(), opt_, true);
    double kb = k.mean, ks = std::sqrt(k.var);
    if (opt_.check_bias_drift && courses_.size() >= 6) {
      const auto m = courses_.begin() + static_cast<std::ptrdiff_t>(courses_.size() / 2);
      const SeriesFit a = fit_series(courses_.begin(), m, opt_, true), b = fit_series(m, courses_.end(), opt_, true);
      if (a.ok && b.ok) account_for_drift(a.mean, a.var, b.mean, b.var, &kb, &ks);
    }
    if (k.ok && ks > 0.0) {
      c.course_bias_rad = kb;
      c.course_bias_sigma_rad = ks;
      combine(have_heading, &c.heading_bias_rad, &c.heading_bias_sigma_rad, kb, ks, true);
      have_heading = true;
    }
  }
  // The GNSS speed: a sample of the step scale, combined the same way (in the scale itself;
  // its log-normal sigma is small enough to be taken as Gaussian there).
  c.speed_epochs = static_cast<int>(speeds_.size());
  if (opt_.use_speed && c.speed_epochs >= opt_.course_min_epochs) {
    const SeriesFit v = fit_series(speeds_.begin(), speeds_.end(), opt_, false);
    if (v.ok && v.var > 0.0) {
      c.speed_scale = std::exp(v.mean);
      c.speed_scale_sigma = c.speed_scale * std::sqrt(v.var);
      combine(have_scale, &c.scale, &c.scale_sigma, c.speed_scale, c.speed_scale_sigma, false);
      have_scale = true;
    }
  }
  // Scale and heading bias are published independently: a heading fit that does not know the
  // bias to max_heading_bias_sigma_rad is not applied (bias 0, the filter keeps its prior
  // uncertainty, prior_heading_bias_sigma_rad) while a good scale still is. With nothing that
  // measured the heading, the same prior.
  c.heading_applied = have_heading && c.heading_bias_sigma_rad <= opt_.max_heading_bias_sigma_rad;
  c.valid = c.epochs >= opt_.min_epochs && have_scale && c.scale >= opt_.min_scale && c.scale <= opt_.max_scale &&
            c.scale_sigma <= opt_.max_scale_sigma && (opt_.independent_heading || c.heading_applied);
  if (!have_heading || (c.valid && !c.heading_applied)) {
    c.heading_bias_rad = 0.0;
    c.heading_bias_sigma_rad = std::max(c.heading_bias_sigma_rad, opt_.prior_heading_bias_sigma_rad);
  }
  last_ = c;
  if (c.valid) published_ = c;
}

}  // namespace pdnav::fusion
