#include "pdnav/gnss/solver_smoothing.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pdnav::gnss {

void CodeSmoother::begin_epoch(double dt_s, double clock_jump_m, bool carrier_broken) {
  ++epoch_;
  dt_s_ = dt_s;
  carrier_broken_ = carrier_broken;
  clock_jump_m_ = std::isfinite(clock_jump_m) ? clock_jump_m : 0.0;
  if (!(dt_s > 0.0)) sats_.clear();
}

double CodeSmoother::innovation(const SmoothingInput& in) const {
  if (!std::isfinite(in.pseudorange_m)) return std::nan("");
  const auto it = sats_.find(in.sat);
  if (it == sats_.end()) return std::nan("");
  const Sat& s = it->second;
  if (!(s.epoch == epoch_ - 1 && dt_s_ > 0.0 && opt_.window_s > 0.0 && s.iono_free == in.iono_free && s.band == in.band))
    return std::nan("");
  double delta = std::nan("");
  if (!carrier_broken_ && std::isfinite(in.adr_m) && std::isfinite(s.adr_m)) delta = in.adr_m - s.adr_m - clock_jump_m_;
  else if (std::isfinite(in.pr_rate_mps) && std::isfinite(s.pr_rate_mps))
    delta = 0.5 * (in.pr_rate_mps + s.pr_rate_mps) * dt_s_ - clock_jump_m_;
  return in.pseudorange_m - (s.pr_sm_m + delta);
}

SmoothingInput CodeSmoother::with_iono_average(const SmoothingInput& in) {
  if (!in.iono_free || !std::isfinite(in.pseudorange_m) || !std::isfinite(in.pseudorange_l1_m) ||
      !(opt_.iono_window_s > 0.0))
    return in;
  Sat& s = sats_[in.sat];
  const double corr = in.pseudorange_m - in.pseudorange_l1_m;
  const bool continuous = s.epoch == epoch_ - 1 && dt_s_ > 0.0 && s.iono_free && s.iono_n > 0.0 &&
                          std::fabs(corr - s.iono_corr_m) <= opt_.iono_max_jump_m;
  if (continuous) {
    s.iono_n = std::min(s.iono_n + 1.0, std::max(1.0, opt_.iono_window_s / dt_s_));
    s.iono_corr_m += (corr - s.iono_corr_m) / s.iono_n;
  } else {
    s.iono_n = 1.0;
    s.iono_corr_m = corr;
  }
  SmoothingInput out = in;
  out.pseudorange_m = in.pseudorange_l1_m + s.iono_corr_m;
  return out;
}

std::vector<double> CodeSmoother::smooth_epoch(const std::vector<SmoothingInput>& in_raw, std::vector<std::string>* reasons) {
  // the averaged ionosphere correction first (it does not depend on the carrier)
  std::vector<SmoothingInput> in;
  in.reserve(in_raw.size());
  for (const auto& x : in_raw) in.push_back(with_iono_average(x));
  common_step_m_ = 0.0;
  if (opt_.remove_common_step) {
    std::vector<double> d;
    for (const auto& x : in) {
      const double v = innovation(x);
      if (std::isfinite(v)) d.push_back(v);
    }
    if (static_cast<int>(d.size()) >= std::max(1, opt_.min_sats_common_step)) {
      std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
      common_step_m_ = d[d.size() / 2];
    }
  }
  const double saved = clock_jump_m_;
  clock_jump_m_ -= common_step_m_;  // the step moves the code: add it to every propagation
  std::vector<double> out;
  out.reserve(in.size());
  if (reasons) reasons->assign(in.size(), std::string());
  for (std::size_t i = 0; i < in.size(); ++i) out.push_back(smooth(in[i], reasons ? &(*reasons)[i] : nullptr));
  clock_jump_m_ = saved;
  return out;
}

double CodeSmoother::white_variance_ratio(const SatId& sat) const {
  const auto it = sats_.find(sat);
  return it == sats_.end() || it->second.epoch != epoch_ ? 1.0 : it->second.white_ratio;
}

double CodeSmoother::smooth(const SmoothingInput& in, std::string* reason) {
  if (!std::isfinite(in.pseudorange_m)) return in.pseudorange_m;
  Sat& s = sats_[in.sat];
  const bool continuous =
      s.epoch == epoch_ - 1 && dt_s_ > 0.0 && opt_.window_s > 0.0 && s.iono_free == in.iono_free && s.band == in.band;
  if (s.epoch == epoch_ - 1 && s.iono_free != in.iono_free && reason != nullptr)
    *reason = "smoothing: single/dual frequency switch (restarted)";
  else if (s.epoch == epoch_ - 1 && s.band != in.band && reason != nullptr)
    *reason = "smoothing: L1/L5 band switch (restarted)";
  double delta = std::nan("");
  double propagation_ratio = 0.0;  // the propagation's variance over the code's white variance
  if (continuous && !carrier_broken_ && std::isfinite(in.adr_m) && std::isfinite(s.adr_m)) {
    delta = in.adr_m - s.adr_m - clock_jump_m_;
  } else if (continuous && std::isfinite(in.pr_rate_mps) && std::isfinite(s.pr_rate_mps)) {
    delta = 0.5 * (in.pr_rate_mps + s.pr_rate_mps) * dt_s_ - clock_jump_m_;
    propagation_ratio = in.white_var_m2 > 0.0 && in.rate_var_m2ps2 >= 0.0
                            ? in.rate_var_m2ps2 * dt_s_ * dt_s_ / in.white_var_m2
                            : std::numeric_limits<double>::infinity();
  }
  const double predicted = s.pr_sm_m + delta;
  if (std::isfinite(delta) && std::fabs(in.pseudorange_m - predicted) > opt_.max_jump_m) {
    if (reason != nullptr) *reason = "smoothing: code-carrier jump (restarted)";
    delta = std::nan("");
  }
  if (std::isfinite(delta)) {
    s.n = std::min(s.n + 1.0, std::max(1.0, opt_.window_s / dt_s_));
    s.pr_sm_m = in.pseudorange_m / s.n + (s.n - 1.0) / s.n * predicted;
    const double keep = (s.n - 1.0) / s.n;
    if (std::isfinite(propagation_ratio))
      s.white_ratio = std::min(1.0, keep * keep * (s.white_ratio + propagation_ratio) + 1.0 / (s.n * s.n));
  } else {
    s.n = 1.0;
    s.white_ratio = 1.0;
    s.pr_sm_m = in.pseudorange_m;
  }
  s.adr_m = carrier_broken_ ? std::nan("") : in.adr_m;  // the carrier restarts at a clock break
  s.pr_rate_mps = in.pr_rate_mps;
  s.epoch = epoch_;
  s.iono_free = in.iono_free;
  s.band = in.band;
  return s.pr_sm_m;
}

}  // namespace pdnav::gnss
