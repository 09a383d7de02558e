#include "pdnav/gnss/kalman.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace pdnav::gnss {
namespace {

/// Symmetrise and floor the diagonal so rounding never makes P indefinite.
Eigen::Matrix4d tidy(const Eigen::Matrix4d& p) {
  Eigen::Matrix4d s = 0.5 * (p + p.transpose());
  for (int i = 0; i < 4; ++i) s(i, i) = std::max(s(i, i), 1e-12);
  return s;
}

}  // namespace

void RobustKalman::reset(const geo::Ecef& pos, const Eigen::Matrix3d& pos_cov, double clock_m, double clock_var_m2) {
  x_ << pos.p_m, clock_m;
  p_.setZero();
  p_.topLeftCorner<3, 3>() = pos_cov;
  p_(3, 3) = clock_var_m2;
  p_ = tidy(p_);
  initialized_ = x_.allFinite() && p_.allFinite();
  rejections_in_row_ = 0;
}

void RobustKalman::predict(const Eigen::Vector3d& disp_m, const Eigen::Matrix3d& disp_cov, double clock_change_m,
                           double clock_change_var_m2) {
  if (!initialized_ || !disp_m.allFinite() || !disp_cov.allFinite()) return;
  x_.head<3>() += disp_m;
  p_.topLeftCorner<3, 3>() += disp_cov + Eigen::Matrix3d::Identity() * opt_.displacement_q_m2;
  if (std::isfinite(clock_change_m) && std::isfinite(clock_change_var_m2)) {
    x_(3) += clock_change_m;
    p_(3, 3) += clock_change_var_m2;
  } else {
    p_(3, 3) += opt_.clock_q_m2ps;
  }
  p_ = tidy(p_);
}

void RobustKalman::coast(double dt_s) {
  if (!initialized_ || !(dt_s > 0.0)) return;
  p_.topLeftCorner<3, 3>() += Eigen::Matrix3d::Identity() * opt_.coast_q_m2ps2 * dt_s;
  p_(3, 3) += opt_.clock_q_m2ps * dt_s;
  p_ = tidy(p_);
}

void RobustKalman::reset_clock(double clock_m, double clock_var_m2) {
  if (!initialized_) return;
  x_(3) = std::isfinite(clock_m) ? clock_m : 0.0;
  p_.row(3).setZero();
  p_.col(3).setZero();
  p_(3, 3) = std::isfinite(clock_var_m2) ? clock_var_m2 : 1e12;
  p_ = tidy(p_);
}

KalmanUpdateResult RobustKalman::update(const geo::Ecef& fix, const Eigen::Matrix3d& fix_cov, double clock_m,
                                        double clock_var_m2) {
  KalmanUpdateResult out;
  if (!fix.p_m.allFinite() || !fix_cov.allFinite() || !std::isfinite(clock_m) || !std::isfinite(clock_var_m2)) return out;
  Eigen::Matrix4d r = Eigen::Matrix4d::Zero();
  r.topLeftCorner<3, 3>() = fix_cov * opt_.fix_variance_scale;
  for (int i = 0; i < 3; ++i) r(i, i) = std::max(r(i, i), opt_.min_fix_variance_m2);
  r(3, 3) = std::max(clock_var_m2 * opt_.fix_variance_scale, opt_.min_fix_variance_m2);
  if (!initialized_) {
    reset(fix, r.topLeftCorner<3, 3>(), clock_m, r(3, 3));
    out.accepted = initialized_;
    out.reset = true;
    return out;
  }
  Eigen::Vector4d z;
  z << fix.p_m, clock_m;
  // H = I: the fix measures the state directly
  const Eigen::Matrix4d s = p_ + r;
  const Eigen::Matrix4d k = p_ * s.inverse();
  const Eigen::Vector4d x_post = x_ + k * (z - x_);
  const Eigen::Matrix4d p_post = tidy((Eigen::Matrix4d::Identity() - k) * p_);
  // posterior residual and its covariance C = R - P+ (Joseph-free form for H = I)
  const Eigen::Vector4d e = z - x_post;
  const Eigen::Matrix4d c = r - p_post;
  for (int i = 0; i < 4; ++i) {
    const double var = std::max(c(i, i), 1e-9);
    out.max_normalised_residual = std::max(out.max_normalised_residual, e(i) * e(i) / var);
  }
  if (!x_post.allFinite() || out.max_normalised_residual > opt_.residual_threshold) {
    if (++rejections_in_row_ > opt_.max_consecutive_rejections) {
      reset(fix, r.topLeftCorner<3, 3>(), clock_m, r(3, 3));
      out.reset = true;
      out.accepted = true;
    }
    return out;
  }
  rejections_in_row_ = 0;
  x_ = x_post;
  p_ = p_post;
  out.accepted = true;
  return out;
}

Eigen::Matrix3d RobustKalman::position_cov_enu() const {
  const Eigen::Matrix3d rot = geo::ecef_to_enu_rotation(geo::to_geodetic(position()));
  return rot * position_cov_ecef() * rot.transpose();
}

}  // namespace pdnav::gnss
