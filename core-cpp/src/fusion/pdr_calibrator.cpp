#include "pdnav/fusion/pdr_calibrator.h"

#include <algorithm>
#include <cmath>

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

void PdrCalibrator::fit() {
  PdrCalibration c;
  c.epochs = static_cast<int>(window_.size());
  c.t_ns = window_.empty() ? 0 : window_.back().t_ns;
  if (window_.size() < 3) { last_ = c; return; }
  double w_sum = 0.0;
  std::complex<double> p_mean = 0.0, g_mean = 0.0;
  for (const Pair& x : window_) {
    w_sum += x.w;
    p_mean += x.w * x.p;
    g_mean += x.w * x.g;
  }
  p_mean /= w_sum;
  g_mean /= w_sum;
  double spp = 0.0, spread = 0.0;
  std::complex<double> spg = 0.0;
  for (const Pair& x : window_) {
    const std::complex<double> dp = x.p - p_mean;
    spp += x.w * std::norm(dp);
    spread += std::norm(dp);
    spg += x.w * std::conj(dp) * (x.g - g_mean);
  }
  const double n = static_cast<double>(window_.size());
  c.baseline_m = std::sqrt(spread / n);
  if (!(spp > 0.0)) { last_ = c; return; }
  const std::complex<double> gain = spg / spp;
  // variance factor from the residuals (2 n observations, 4 parameters), never below 1:
  // the weights are the GNSS sigmas, residuals can only say they were optimistic
  double chi2 = 0.0;
  for (const Pair& x : window_) chi2 += x.w * std::norm(x.g - g_mean - gain * (x.p - p_mean));
  const double dof = std::max(1.0, 2.0 * n - 4.0);
  const double var_factor = std::max(1.0, chi2 / dof);
  const double span_s = static_cast<double>(window_.back().t_ns - window_.front().t_ns) * 1e-9;
  // Effective number of independent epochs: GNSS errors (multipath, a chipset's own filter) and
  // PDR drift make the residuals time-correlated. The smaller of span / correlation_time and
  // the AR(1) value n (1 - rho) / (1 + rho) from the residuals' lag-1 autocorrelation rho
  // (Bayley & Hammersley 1946), so a run of smoothed fixes is never counted as many.
  double r0 = 0.0, r1 = 0.0;
  std::complex<double> prev = 0.0;
  bool have_prev = false;
  for (const Pair& x : window_) {
    const std::complex<double> e = x.g - g_mean - gain * (x.p - p_mean);
    r0 += std::norm(e);
    if (have_prev) r1 += std::real(std::conj(prev) * e);
    prev = e;
    have_prev = true;
  }
  const double rho = r0 > 0.0 ? std::clamp(r1 / r0, 0.0, 0.999) : 0.0;
  c.residual_rho = rho;
  const double n_eff_ar = opt_.residual_correlation ? n * (1.0 - rho) / (1.0 + rho) : n;
  const double n_eff = std::clamp(std::min(span_s / opt_.correlation_time_s + 1.0, n_eff_ar), 1.0, n);
  const double var_component = var_factor / spp * (n / n_eff);  // of Re c and of Im c
  c.scale = std::abs(gain);
  c.heading_bias_rad = std::arg(gain);
  c.scale_sigma = std::sqrt(var_component);
  c.heading_bias_sigma_rad = c.scale > 0.0 ? std::sqrt(var_component) / c.scale : kPi;
  c.valid = c.epochs >= opt_.min_epochs && c.baseline_m >= opt_.min_baseline_m && c.scale >= opt_.min_scale &&
            c.scale <= opt_.max_scale && c.scale_sigma <= opt_.max_scale_sigma &&
            c.heading_bias_sigma_rad <= opt_.max_heading_bias_sigma_rad;
  last_ = c;
  if (c.valid) published_ = c;
}

}  // namespace pdnav::fusion
