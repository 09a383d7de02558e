// Online hard-iron sphere fit (docs/pdr.md, "Hard-iron calibration").
#include "pdnav/pdr/mag_calibration.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace pdnav::pdr {

void MagCalibration::clear_sums() {
  w_ = sy_ = syy_ = 0.0;
  sm_.setZero();
  sym_.setZero();
  smm_.setZero();
}

void MagCalibration::add(TimeNs t_ns, const Eigen::Vector3d& field_ut) {
  if (!opt_.enabled || !field_ut.allFinite()) return;
  if (have_last_ && t_ns < last_ns_ + s_to_ns(opt_.sample_interval_s)) return;  // backwards or too close
  const double dt_s = have_last_ ? ns_to_s(t_ns - last_ns_) : opt_.sample_interval_s;
  have_last_ = true;
  last_ns_ = t_ns;
  const double decay = std::exp(-dt_s / opt_.tau_s);
  w_ *= decay, sy_ *= decay, syy_ *= decay, sm_ *= decay, sym_ *= decay, smm_ *= decay;
  const double w = std::min(dt_s, opt_.max_weight_s);
  const double y = field_ut.squaredNorm();
  w_ += w;
  sm_ += w * field_ut;
  smm_ += w * field_ut * field_ut.transpose();
  sy_ += w * y;
  sym_ += w * y * field_ut;
  syy_ += w * y * y;
  if (w_ < opt_.min_time_s) return;

  // centred normal equations of 2 (m - mu).b = y - mean(y), with the ridge on b
  const Eigen::Vector3d mu = sm_ / w_;
  const Eigen::Matrix3d cov = smm_ / w_ - mu * mu.transpose();
  const double y_mean = sy_ / w_;
  const Eigen::Vector3d cov_my = sym_ / w_ - y_mean * mu;
  const double var_y = syy_ / w_ - y_mean * y_mean;
  const Eigen::Vector3d b = (cov + opt_.ridge_ut2 * Eigen::Matrix3d::Identity()).ldlt().solve(0.5 * cov_my);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov, Eigen::EigenvaluesOnly);
  spread_ut2_ = eig.eigenvalues()[1];  // ascending: the second largest
  const double r2 = y_mean - 2.0 * mu.dot(b) + b.squaredNorm();  // mean |m - b|^2
  const double e2 = std::max(0.0, var_y - 4.0 * b.dot(cov_my) + 4.0 * b.dot(cov * b));
  // algebraic residual |m - b|^2 - r^2 ~ 2 r (|m - b| - r)
  const double residual = r2 > 0.0 ? std::sqrt(e2) / (2.0 * r2) : kNaN;
  last_explained_ = var_y > 0.0 ? 1.0 - e2 / var_y : 0.0;
  last_residual_ = residual;
  if (!b.allFinite() || !(residual <= opt_.max_residual) || b.norm() > opt_.max_bias_ut) {
    ++refusals_;  // disturbed, not biased: forget this window (the bias in use stays)
    clear_sums();
    return;
  }
  if (spread_ut2_ < opt_.min_spread_ut2) return;  // not enough directions yet
  // the bias must explain the variation of |m|^2 (a field that changes along the walk does not
  // vary with the phone's orientation); this also leaves a small bias (a calibrated phone) alone
  if (!(last_explained_ >= opt_.min_explained)) return;
  active_ = true;
  ++accepted_;
  bias_ut_ = b;
  radius_ut_ = std::sqrt(r2);
  residual_ = residual;
}

}  // namespace pdnav::pdr
