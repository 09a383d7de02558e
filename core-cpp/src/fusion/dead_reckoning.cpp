#include "pdnav/fusion/dead_reckoning.h"

#include <algorithm>
#include <cmath>

namespace pdnav::fusion {

void DeadReckoning::initialize(const geo::Geodetic& start, double sigma_m, TimeNs t_ns) {
  frame_ = geo::LocalFrame(geo::Geodetic{start.lat_rad, start.lon_rad, start.h_m});
  x_.setZero();
  p_.setZero();
  p_(0, 0) = p_(1, 1) = sigma_m * sigma_m;
  p_(2, 2) = opt_.heading_bias_sigma_rad * opt_.heading_bias_sigma_rad;
  p_(3, 3) = opt_.length_scale_sigma * opt_.length_scale_sigma;
  p_(4, 4) = p_(5, 5) = opt_.compass_deviation_sigma_rad * opt_.compass_deviation_sigma_rad;
  t_ns_ = t_ns;
  initialized_ = true;
  have_steps_ = false;
}

void DeadReckoning::feed(const PdrStep& step) {
  if (!initialized_ || !std::isfinite(step.length_m) || !std::isfinite(step.heading_rad)) return;
  const double dt = std::max(0.0, ns_to_s(step.t_ns) - ns_to_s(t_ns_));  // no int64 overflow on wild times
  t_ns_ = step.t_ns;
  const bool has_sigma = std::isfinite(step.heading_sigma_rad) && step.heading_sigma_rad > 0.0;
  // A step without a sigma (0/NaN: the caller does not know) counts as absolute, as before.
  const bool absolute = !opt_.use_step_heading_sigma || !has_sigma ||
                        step.heading_sigma_rad < opt_.absolute_heading_max_sigma_rad;
  double bias_sigma = opt_.heading_bias_sigma_rad;
  if (absolute) {
    if (!absolute_heading_seen_ && have_steps_) {
      // The path walked so far with a relative heading only keeps its rotation error.
      p_.topLeftCorner<2, 2>() += rotation_covariance(x_.head<2>(), rotation_sigma_rad_);
    }
    if (!absolute_heading_seen_ && opt_.use_step_heading_sigma && has_sigma) {
      // First absolute heading: the bias is this step's heading error.
      p_(2, 2) = step.heading_sigma_rad * step.heading_sigma_rad;
    }
    absolute_heading_seen_ = true;
    if (opt_.use_step_heading_sigma && has_sigma) bias_sigma = step.heading_sigma_rad;
    if (bias_sigma * bias_sigma > p_(2, 2)) {
      // The heading is known worse than the filter believed: widen the bias (process noise on
      // the bias alone keeps P positive semi-definite and its correlations with position).
      p_(2, 2) = bias_sigma * bias_sigma;
    }
  } else if (!absolute_heading_seen_) {
    rotation_sigma_rad_ = std::min(step.heading_sigma_rad, kPi);
  }
  have_steps_ = true;
  const double l0 = step.length_m, l = (1.0 + x_(3)) * l0, h = step.heading_rad + x_(2);
  const double s = std::sin(h), c = std::cos(h);
  x_(0) += l * s;
  x_(1) += l * c;
  // FOGM bias: b' = phi b + w, phi = exp(-dt/tau), var(w) = sigma^2 (1 - phi^2)
  const double phi = std::exp(-dt / opt_.heading_bias_tau_s);
  x_(2) *= phi;
  Mat6 f = Mat6::Identity();
  f(0, 2) = l * c;
  f(1, 2) = -l * s;
  f(2, 2) = phi;
  f(0, 3) = l0 * s;  // the scale error moves every step along its own direction
  f(1, 3) = l0 * c;
  if (absolute) {
    // heading error B sin(psi) + C cos(psi) at this step's heading (B, C stay 0: never observed here)
    const double sp = std::sin(step.heading_rad), cp = std::cos(step.heading_rad);
    f(0, 4) = l * c * sp;
    f(1, 4) = -l * s * sp;
    f(0, 5) = l * c * cp;
    f(1, 5) = -l * s * cp;
  }
  const double sl = std::isfinite(step.length_sigma_m) && step.length_sigma_m > 0 ? step.length_sigma_m : opt_.length_sigma_m;
  Mat6 q = Mat6::Zero();
  q.topLeftCorner<2, 2>() = sl * sl * (Eigen::Vector2d(s, c) * Eigen::Vector2d(s, c).transpose());
  q(2, 2) = bias_sigma * bias_sigma * (1.0 - phi * phi);
  q(3, 3) = opt_.length_scale_rw_1ps * dt;
  p_ = f * p_ * f.transpose() + q;
}

Eigen::Matrix2d DeadReckoning::rotation_covariance(const Eigen::Vector2d& p_en_m, double sigma_rad) {
  // Walked path p rotated about the start by an unknown e ~ N(0, sigma^2): the error
  // R(e) p - p has, in p's own frame, along = |p| (cos e - 1) and cross = |p| sin e, with
  // E[(cos e - 1)^2] = 1 - 2 exp(-s^2/2) + (1 + exp(-2 s^2)) / 2 and E[sin^2 e] = (1 - exp(-2 s^2)) / 2
  // (exact for a Gaussian e; sigma = pi is practically a uniform angle: E|R p - p|^2 = 2 |p|^2).
  const double r2 = p_en_m.squaredNorm();
  if (r2 <= 0.0 || !(sigma_rad > 0.0)) return Eigen::Matrix2d::Zero();
  const double s2 = sigma_rad * sigma_rad;
  const double along = 1.0 - 2.0 * std::exp(-0.5 * s2) + 0.5 * (1.0 + std::exp(-2.0 * s2));
  const double cross = 0.5 * (1.0 - std::exp(-2.0 * s2));
  const Eigen::Vector2d u = p_en_m / std::sqrt(r2);
  const Eigen::Vector2d v(u.y(), -u.x());
  return r2 * (along * u * u.transpose() + cross * v * v.transpose());
}

Estimate DeadReckoning::estimate() const {
  Estimate e;
  e.engine = EngineKind::kDeadReckoning;
  if (!initialized_) {
    e.status = EstimateStatus::kNotInitialized;
    e.reason = "no start position";
    return e;
  }
  e.t_ns = t_ns_;
  if (have_steps_ && !absolute_heading_seen_) {
    e.status = EstimateStatus::kDegraded;
    e.reason = "dead reckoning, relative heading only";
  } else {
    e.status = EstimateStatus::kOk;
    e.reason = "dead reckoning";
  }
  e.en_m = x_.head<2>();
  e.cov_en_m2 = p_.topLeftCorner<2, 2>();
  if (have_steps_ && !absolute_heading_seen_) e.cov_en_m2 += rotation_covariance(x_.head<2>(), rotation_sigma_rad_);
  e.position = frame_.to_geodetic(geo::Enu(x_(0), x_(1), 0.0));
  e.position.h_m = frame_.origin().h_m;
  return e;
}

}  // namespace pdnav::fusion
