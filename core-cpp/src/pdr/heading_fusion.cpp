// Gyro-dominant heading with gated magnetic corrections (docs/pdr.md, "Heading fusion").
#include "pdnav/pdr/heading_fusion.h"

#include <algorithm>
#include <cmath>

namespace pdnav::pdr {

HeadingFusion::HeadingFusion(const HeadingFusionOptions& options) : opt_(options) {}

void HeadingFusion::set_reference_field(double total_ut, double inclination_rad) {
  if (std::isfinite(total_ut) && total_ut > 0.0 && std::isfinite(inclination_rad)) {
    ref_total_ut_ = total_ut;
    ref_dip_rad_ = inclination_rad;
  }
}

double HeadingFusion::accuracy_weight(int android_accuracy) const {
  return opt_.accuracy_weight[std::clamp(android_accuracy, 0, 3)];
}

double HeadingFusion::field_weight(const Eigen::Vector3d& field_ut, const Eigen::Vector3d& up_phone) const {
  if (!std::isfinite(ref_total_ut_)) return 1.0;
  const double f = field_ut.norm();
  if (!(f > 0.0) || !std::isfinite(f) || !(up_phone.norm() > 0.0)) return opt_.disturbed_weight;
  const double dip = std::asin(std::clamp(-field_ut.dot(up_phone.normalized()) / f, -1.0, 1.0));
  const bool ok = std::abs(f / ref_total_ut_ - 1.0) <= opt_.field_tolerance &&
                  std::abs(dip - ref_dip_rad_) <= opt_.dip_tolerance_rad;
  return ok ? 1.0 : opt_.disturbed_weight;
}

double HeadingFusion::field_deflection_sigma_rad(const Eigen::Vector3d& field_ut, const Eigen::Vector3d& up_phone) const {
  if (!std::isfinite(ref_total_ut_) || !field_ut.allFinite() || !(up_phone.norm() > 0.0)) return 0.0;
  const double down = -field_ut.dot(up_phone.normalized());
  const double horizontal = std::sqrt(std::max(0.0, field_ut.squaredNorm() - down * down));
  const double ref_horizontal = ref_total_ut_ * std::cos(ref_dip_rad_);
  if (!(ref_horizontal > 0.0)) return 0.0;
  return std::min(kPi / std::sqrt(3.0), std::abs(horizontal - ref_horizontal) / (std::sqrt(2.0) * ref_horizontal));
}

void HeadingFusion::LineSums::shift_and_decay(double dt_s, double decay) {
  // re-anchor at the new reading (tau' = tau - dt), then forget
  s2 = s2 - 2.0 * dt_s * s1 + dt_s * dt_s * s0;
  s1 = s1 - dt_s * s0;
  y1 = y1 - dt_s * y0;
  s0 *= decay, s1 *= decay, s2 *= decay, y0 *= decay, y1 *= decay, yy *= decay;
}

void HeadingFusion::add(TimeNs t_ns, double heading_mag_rad, double yaw_rad, double weight, bool gyro_live,
                        double deflection_sigma_rad) {
  if (!std::isfinite(heading_mag_rad) || !std::isfinite(yaw_rad) || !(weight > 0.0)) return;
  // heading = c - yaw (yaw is counter-clockwise, heading clockwise): c is constant for a gyro
  // without drift, whatever the path.
  const double c = heading_mag_rad + yaw_rad;
  if (!have_last_ || weight_ <= 0.0) {
    reset();
    anchor_rad_ = c;
  } else {
    if (t_ns < last_ns_) return;
    const double dt_s = ns_to_s(t_ns - last_ns_);
    const double decay = std::exp(-dt_s / (gyro_live ? opt_.tau_s : opt_.no_gyro_tau_s));
    all_.shift_and_decay(dt_s, decay);
    circ_ *= decay;
    deflection2_ *= decay;
    trusted_.shift_and_decay(dt_s, gyro_live ? std::exp(-dt_s / opt_.drift_tau_s) : decay);
    weight_s_ = weight_s_ * decay + weight * std::min(1.0, dt_s);
  }
  have_last_ = true;
  last_ns_ = t_ns;
  // unwrap around the current prediction at tau = 0
  const double pred = all_.s0 > 0.0 ? (all_.y0 - drift_radps() * all_.s1) / all_.s0 : 0.0;
  const double y = pred + wrap_pi(c - anchor_rad_ - pred);
  all_.add(weight, y);
  if (std::isfinite(deflection_sigma_rad)) deflection2_ += weight * deflection_sigma_rad * deflection_sigma_rad;
  circ_ += weight * Eigen::Vector2d(std::cos(c), std::sin(c));
  last_c_rad_ = c;
  if (weight >= 1.0) trusted_.add(weight, y);
  weight_ = all_.s0;
  (weight >= 1.0 ? accepted_ : disturbed_) += 1;
}

double HeadingFusion::drift_radps() const {
  const LineSums& t = trusted_;
  if (!(t.s0 > 0.0)) return 0.0;
  const double mt = t.s1 / t.s0, my = t.y0 / t.s0;
  const double var_t = std::max(0.0, t.s2 / t.s0 - mt * mt);
  const double cov_ty = t.y1 / t.s0 - mt * my;
  // scatter of the offsets about the fitted line, and how many of them are independent
  const double var_y = std::max(0.0, t.yy / t.s0 - my * my);
  const double resid = var_t > 0.0 ? std::max(0.0, var_y - cov_ty * cov_ty / var_t) : var_y;
  const double n_independent = std::max(1.0, std::sqrt(12.0 * var_t) / opt_.decorrelation_s);
  const double sigma_b = opt_.drift_prior_sigma_radps;
  const double ridge = std::max(opt_.drift_prior_s * opt_.drift_prior_s,
                                sigma_b > 0.0 ? resid / (sigma_b * sigma_b * n_independent) : 0.0);
  const double b = cov_ty / (var_t + ridge);
  return std::clamp(b, -opt_.max_drift_radps, opt_.max_drift_radps);
}

void HeadingFusion::reset() {
  all_ = LineSums{};
  trusted_ = LineSums{};
  weight_ = weight_s_ = deflection2_ = 0.0;
  circ_.setZero();
  have_last_ = false;
}

double HeadingFusion::heading_mag_rad(double yaw_rad, TimeNs t_ns) const {
  if (all_.s0 > 0.0 && circ_.norm() / all_.s0 < opt_.min_consistency) return wrap_two_pi(last_c_rad_ - yaw_rad);
  const double b = drift_radps();
  const double a = all_.s0 > 0.0 ? (all_.y0 - b * all_.s1) / all_.s0 : 0.0;
  const double since = have_last_ ? std::max(0.0, ns_to_s(t_ns - last_ns_)) : 0.0;
  return wrap_two_pi(anchor_rad_ + a + b * since - yaw_rad);
}

double HeadingFusion::sigma_rad() const {
  if (!valid()) return kPi;
  const double n_independent = std::max(1.0, weight_s_ / opt_.decorrelation_s);
  const double base = opt_.base_sigma_rad / std::sqrt(n_independent);
  const double deflection2 = all_.s0 > 0.0 ? deflection2_ / all_.s0 : 0.0;  // the readings' fields' own
  return std::clamp(std::sqrt(base * base + deflection2), opt_.min_sigma_rad, kPi);
}

void QuasiStaticField::add(TimeNs t_ns, double offset_rad, double field_ut) {
  if (!std::isfinite(offset_rad) || !std::isfinite(field_ut)) return;
  if (!window_.empty() && t_ns <= window_.back().t_ns) return;
  const TimeNs span_ns = s_to_ns(opt_.qsf_window_s);
  if (!window_.empty() && t_ns - window_.back().t_ns > span_ns) window_.clear();  // a gap
  window_.push_back({t_ns, offset_rad, field_ut});
  std::size_t first = 0;
  while (first < window_.size() && window_[first].t_ns < t_ns - span_ns) ++first;
  window_.erase(window_.begin(), window_.begin() + static_cast<std::ptrdiff_t>(first));
  qsf_ = false;
  if (window_.size() < 3 || ns_to_s(t_ns - window_.front().t_ns) < 0.8 * opt_.qsf_window_s) return;
  double c = 0, sn = 0, f = 0, f2 = 0;
  for (const Reading& r : window_) c += std::cos(r.offset_rad), sn += std::sin(r.offset_rad), f += r.field_ut,
                                    f2 += r.field_ut * r.field_ut;
  const double n = static_cast<double>(window_.size());
  const double resultant = std::min(1.0, std::hypot(c, sn) / n);
  offset_std_rad_ = std::sqrt(std::max(0.0, -2.0 * std::log(std::max(resultant, 1e-12))));  // circular std
  field_std_ut_ = std::sqrt(std::max(0.0, f2 / n - (f / n) * (f / n)));
  qsf_ = offset_std_rad_ <= opt_.qsf_max_offset_std_rad && field_std_ut_ <= opt_.qsf_max_field_std_ut;
}

}  // namespace pdnav::pdr
