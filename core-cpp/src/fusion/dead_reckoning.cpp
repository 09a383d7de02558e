#include "pdnav/fusion/dead_reckoning.h"

#include <cmath>

namespace pdnav::fusion {

void DeadReckoning::initialize(const geo::Geodetic& start, double sigma_m, TimeNs t_ns) {
  frame_ = geo::LocalFrame(geo::Geodetic{start.lat_rad, start.lon_rad, start.h_m});
  x_.setZero();
  p_.setZero();
  p_(0, 0) = p_(1, 1) = sigma_m * sigma_m;
  p_(2, 2) = opt_.heading_bias_sigma_rad * opt_.heading_bias_sigma_rad;
  t_ns_ = t_ns;
  initialized_ = true;
}

void DeadReckoning::feed(const PdrStep& step) {
  if (!initialized_ || !std::isfinite(step.length_m) || !std::isfinite(step.heading_rad)) return;
  const double dt = std::max(0.0, ns_to_s(step.t_ns) - ns_to_s(t_ns_));  // no int64 overflow on wild times
  t_ns_ = step.t_ns;
  const double l = step.length_m, h = step.heading_rad + x_(2);
  const double s = std::sin(h), c = std::cos(h);
  x_(0) += l * s;
  x_(1) += l * c;
  // FOGM bias: b' = phi b + w, phi = exp(-dt/tau), var(w) = sigma^2 (1 - phi^2)
  const double phi = std::exp(-dt / opt_.heading_bias_tau_s);
  x_(2) *= phi;
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 2) = l * c;
  f(1, 2) = -l * s;
  f(2, 2) = phi;
  const double sl = std::isfinite(step.length_sigma_m) && step.length_sigma_m > 0 ? step.length_sigma_m : opt_.length_sigma_m;
  Eigen::Matrix3d q = Eigen::Matrix3d::Zero();
  q.topLeftCorner<2, 2>() = sl * sl * (Eigen::Vector2d(s, c) * Eigen::Vector2d(s, c).transpose());
  q(2, 2) = opt_.heading_bias_sigma_rad * opt_.heading_bias_sigma_rad * (1.0 - phi * phi);
  p_ = f * p_ * f.transpose() + q;
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
  e.status = EstimateStatus::kOk;
  e.reason = "dead reckoning";
  e.en_m = x_.head<2>();
  e.cov_en_m2 = p_.topLeftCorner<2, 2>();
  e.position = frame_.to_geodetic(geo::Enu(x_(0), x_(1), 0.0));
  e.position.h_m = frame_.origin().h_m;
  return e;
}

}  // namespace pdnav::fusion
