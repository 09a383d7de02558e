#include "pdnav/fusion/pdr_calibrator.h"

#include <algorithm>
#include <cmath>
#include <iterator>

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
  const TimeNs win_ns = static_cast<TimeNs>(opt_.window_s * 1e9);
  while (!window_.empty() && window_.front().t_ns < t_ns - win_ns) window_.pop_front();
  fit();
}

void PdrCalibrator::reset() {
  steps_.clear();
  window_.clear();
  last_ = PdrCalibration{};
  published_ = PdrCalibration{};
}

namespace {
struct RangeFit {
  bool ok = false;
  std::complex<double> gain = 0.0;
  double var_component = 0.0;  // of Re c and of Im c
  double baseline_m = 0.0, rho = 0.0, span_s = 0.0, moving_s = 0.0;
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
  double chi2 = 0.0, r0 = 0.0, r1 = 0.0;
  std::complex<double> prev = 0.0;
  for (It x = b; x != e; ++x) {
    const std::complex<double> res = x->g - g_mean - f.gain * (x->p - p_mean);
    chi2 += x->w * std::norm(res);
    r0 += std::norm(res);
    if (x != b) r1 += std::real(std::conj(prev) * res);
    prev = res;
  }
  const double dof = std::max(1.0, 2.0 * n - 4.0);
  const double var_factor = std::max(1.0, chi2 / dof);
  // Effective number of independent epochs: GNSS errors (multipath, a chipset's own filter) and
  // PDR drift make the residuals time-correlated. The smaller of span / correlation_time and
  // the AR(1) value n (1 - rho) / (1 + rho) from the residuals' lag-1 autocorrelation rho
  // (Bayley & Hammersley 1946), so a run of smoothed fixes is never counted as many.
  f.rho = r0 > 0.0 ? std::clamp(r1 / r0, 0.0, 0.999) : 0.0;
  const double n_eff_ar = opt.residual_correlation ? n * (1.0 - f.rho) / (1.0 + f.rho) : n;
  const double n_eff = std::clamp(std::min(f.moving_s / opt.correlation_time_s + 1.0, n_eff_ar), 1.0, n);
  f.var_component = var_factor / spp * (n / n_eff);
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
  c.residual_rho = f.rho;
  if (!f.ok) { last_ = c; return; }
  const std::complex<double> gain = f.gain;
  const double var_component = f.var_component;
  c.scale = std::abs(gain);
  c.heading_bias_rad = std::arg(gain);
  c.scale_sigma = std::sqrt(var_component);
  c.heading_bias_sigma_rad = c.scale > 0.0 ? std::sqrt(var_component) / c.scale : kPi;
  // Did the bias stay put over the window? Fit the two halves of the PDR path separately: their
  // difference beyond what their own sigmas explain is how far the bias moved in the window
  // (the fit above is its average; a walk through magnetic disturbances moves it by tens of
  // degrees). Published as heading_bias_drift_sigma_rad; the fused filter carries it.
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
    if (a.ok && b.ok && std::abs(a.gain) > 0.0 && std::abs(b.gain) > 0.0) {
      const double d = std::arg(b.gain / a.gain);
      const double var_d = a.var_component / std::norm(a.gain) + b.var_component / std::norm(b.gain);
      c.heading_bias_drift_sigma_rad = std::sqrt(std::max(0.0, d * d - var_d));
      // moved beyond 2 sigma: the recent half is the better predictor of the bias now
      // (Gauss-Markov bias), the scale stays the whole window's
      if (d * d > 4.0 * var_d) {
        c.heading_bias_rad = std::arg(b.gain);
        c.heading_bias_sigma_rad = std::sqrt(b.var_component) / std::abs(b.gain);
      }
      // and it keeps moving: the bias now is known no better than that
      c.heading_bias_sigma_rad = std::hypot(c.heading_bias_sigma_rad, c.heading_bias_drift_sigma_rad);
    }
  }
  // Scale and heading bias are published independently: a heading fit that does not know the
  // bias to max_heading_bias_sigma_rad is not applied (bias 0, the filter keeps its prior
  // uncertainty, prior_heading_bias_sigma_rad) while a good scale still is.
  c.heading_applied = c.heading_bias_sigma_rad <= opt_.max_heading_bias_sigma_rad;
  c.valid = c.epochs >= opt_.min_epochs && c.baseline_m >= opt_.min_baseline_m && c.scale >= opt_.min_scale &&
            c.scale <= opt_.max_scale && c.scale_sigma <= opt_.max_scale_sigma &&
            (opt_.independent_heading || c.heading_applied);
  if (c.valid && !c.heading_applied) {
    c.heading_bias_rad = 0.0;
    c.heading_bias_sigma_rad = std::max(c.heading_bias_sigma_rad, opt_.prior_heading_bias_sigma_rad);
  }
  last_ = c;
  if (c.valid) published_ = c;
}

}  // namespace pdnav::fusion
