// Online hard-iron sphere fit (docs/pdr.md, "Hard-iron calibration").
#include "pdnav/pdr/mag_calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "rotation_increment.h"

namespace pdnav::pdr {

void MagCalibration::clear_sums() {
  w_ = sy_ = syy_ = 0.0;
  sm_.setZero();
  sym_.setZero();
  smm_.setZero();
  pn_.setZero();
  pr_.setZero();
  pyy_ = pw_ = 0.0;
}

void MagCalibration::restart_pairs() {
  if (gyro_live_) clear_sums();  // the sphere fit's sums hold no attitude
  readings_.clear();
  gyro_history_.clear();
  pair_solved_ = false;
  ++pair_restarts_;
}

MagCalibration::MagCalibration(const MagCalibrationOptions& options) : opt_(options) {
  for (double lag = 1.0; lag <= opt_.max_lag_s + 1e-9; lag *= 2.0) lags_ns_.push_back(s_to_ns(lag));
}

void MagCalibration::add_gyro(TimeNs t_ns, const Eigen::Vector3d& rate_radps) {
  if (!opt_.enabled || !opt_.gyro_aided || !rate_radps.allFinite()) return;
  if (gyro_ns_ >= 0) {
    if (t_ns <= gyro_ns_) return;  // duplicate or backwards
    const double dt_s = ns_to_s(t_ns - gyro_ns_);
    if (dt_s > opt_.max_gyro_gap_s) {
      // the attitude over the gap is unknown: no pair across it
      readings_.clear();
      gyro_history_.clear();
    } else {
      const Eigen::Matrix3d r0 = r_;
      q_ = (q_ * detail::rotation_increment(0.5 * (rate_ + rate_radps), dt_s)).normalized();  // trapezoid
      r_ = q_.toRotationMatrix();
      s_ += 0.5 * dt_s * (r0 + r_);
    }
  }
  rate_ = rate_radps;
  gyro_ns_ = t_ns;
  gyro_history_.push_back({t_ns, q_, r_, s_, rate_radps});
  while (gyro_history_.size() > 2 && gyro_history_.front().t_ns < t_ns - s_to_ns(opt_.gyro_history_s))
    gyro_history_.pop_front();
}

bool MagCalibration::attitude_at(TimeNs t_ns, Eigen::Matrix3d* r, Eigen::Matrix3d* s) const {
  if (gyro_history_.empty()) return false;
  // the last gyro state at or before t_ns, carried to t_ns with its rate (at most max_gyro_gap_s)
  auto it = std::upper_bound(gyro_history_.begin(), gyro_history_.end(), t_ns,
                             [](TimeNs v, const Attitude& a) { return v < a.t_ns; });
  if (it == gyro_history_.begin()) return false;  // older than the history
  const Attitude& a = *(it - 1);
  const double ahead_s = ns_to_s(t_ns - a.t_ns);
  if (ahead_s > opt_.max_gyro_gap_s) return false;
  *r = (a.q * detail::rotation_increment(a.rate, ahead_s)).normalized().toRotationMatrix();
  *s = a.s + ahead_s * 0.5 * (a.r + *r);
  return true;
}

void MagCalibration::add(TimeNs t_ns, const Eigen::Vector3d& field_ut) {
  if (!opt_.enabled || !field_ut.allFinite()) return;
  if (have_last_ && t_ns < last_ns_ + s_to_ns(opt_.sample_interval_s)) return;  // backwards or too close
  const double dt_s = have_last_ ? ns_to_s(t_ns - last_ns_) : opt_.sample_interval_s;
  have_last_ = true;
  last_ns_ = t_ns;
  // a gyro is live when one of its samples is within the history span of this reading, before
  // or after it (a batched stream may run ahead of the magnetometer's)
  const bool live = opt_.gyro_aided && gyro_ns_ >= 0 &&
                    std::abs(ns_to_s(t_ns - gyro_ns_)) <= opt_.gyro_history_s;
  if (live != gyro_live_) {  // the other fit starts afresh (the bias in use stays)
    clear_sums();
    readings_.clear();
    gyro_live_ = live;
  }
  if (!live) {
    add_sphere(t_ns, field_ut, dt_s);
    return;
  }
  Eigen::Matrix3d r, s;
  if (!attitude_at(t_ns, &r, &s)) return;  // no attitude at this reading's time: not paired
  add_pairs(t_ns, field_ut, dt_s, r, s);
}

void MagCalibration::add_pairs(TimeNs t_ns, const Eigen::Vector3d& m, double dt_s, const Eigen::Matrix3d& r,
                               const Eigen::Matrix3d& s_now) {
  const double decay = std::exp(-dt_s / opt_.tau_s);
  pn_ *= decay, pr_ *= decay, pyy_ *= decay, pw_ *= decay;
  const Eigen::Vector3d rm = r * m;
  const double w = std::min(dt_s, opt_.max_weight_s) / static_cast<double>(std::max<std::size_t>(1, lags_ns_.size()));
  const double min_cos = std::cos(opt_.min_pair_rotation_rad);
  for (const TimeNs lag_ns : lags_ns_) {
    const TimeNs target = t_ns - lag_ns;
    auto it = std::lower_bound(readings_.begin(), readings_.end(), target,
                               [](const Reading& x, TimeNs v) { return x.t_ns < v; });
    if (it == readings_.end() || (it != readings_.begin() && target - (it - 1)->t_ns < it->t_ns - target)) {
      if (it == readings_.begin()) continue;
      --it;
    }
    if (std::llabs(it->t_ns - target) > s_to_ns(opt_.sample_interval_s)) continue;
    // rotation between the two readings: cos = (trace(R_i^T R_j) - 1) / 2
    if (0.5 * ((r.transpose() * it->r).trace() - 1.0) > min_cos) continue;
    // the field in the world-fixed frame at the linearisation point (the latest b)
    const Eigen::Vector3d h = 0.5 * (rm + it->r * it->m - (r + it->r) * pair_b_);
    Eigen::Matrix3d hx;
    hx << 0.0, -h.z(), h.y(), h.z(), 0.0, -h.x(), -h.y(), h.x(), 0.0;
    Eigen::Matrix<double, 3, 6> a;
    a << r - it->r, -hx * (s_now - it->s);
    const Eigen::Vector3d y = rm - it->r * it->m;
    if (pair_solved_) {
      Vec6 x_prev;
      x_prev << pair_b_, gyro_bias_radps_;
      const double gate = opt_.pair_gate_sigma * std::max(pair_residual_ut_, opt_.pair_noise_ut);
      if ((y - a * x_prev).norm() > gate) {
        ++pairs_gated_;
        continue;
      }
    }
    pn_ += w * a.transpose() * a;
    pr_ += w * a.transpose() * y;
    pyy_ += w * y.squaredNorm();
    pw_ += w;
  }
  readings_.push_back({t_ns, m, r, s_now});
  while (!readings_.empty() && readings_.front().t_ns < t_ns - s_to_ns(opt_.max_lag_s + 1.0)) readings_.pop_front();
  if (pw_ < opt_.min_pair_time_s) return;

  // weighted least squares with the priors b ~ N(0, prior^2), d ~ N(0, prior_gyro^2): the ridge
  // of each is N_eff noise^2 / prior^2
  const double n2 = opt_.correlation_time_s * opt_.pair_noise_ut * opt_.pair_noise_ut;
  Vec6 ridge;
  ridge.head<3>().setConstant(n2 / (opt_.prior_bias_ut * opt_.prior_bias_ut));
  ridge.tail<3>().setConstant(n2 / (opt_.prior_gyro_bias_radps * opt_.prior_gyro_bias_radps));
  const Mat6 info = pn_ + Mat6(ridge.asDiagonal());
  const Eigen::LDLT<Mat6> ldlt(info);
  const Vec6 x = ldlt.solve(pr_);
  const Eigen::Vector3d b = x.head<3>();
  pair_b_ = b;
  gyro_bias_radps_ = x.tail<3>();
  pair_solved_ = true;
  const double chi2 = std::max(0.0, pyy_ - 2.0 * x.dot(pr_) + x.dot(pn_ * x));
  pair_residual_ut_ = std::sqrt(chi2 / pw_);
  // the fraction of the pairs' differences the hard iron (and gyro bias) account for
  last_explained_ = pyy_ > 0.0 ? 1.0 - chi2 / pyy_ : 0.0;
  const double radius = (m - b).norm();
  last_residual_ = radius > 0.0 ? pair_residual_ut_ / radius : kNaN;
  const bool fits = pair_residual_ut_ <= opt_.max_pair_residual_ut || last_explained_ >= opt_.min_pair_explained;
  if (!b.allFinite() || !fits || b.norm() > opt_.max_bias_ut) {
    ++refusals_;  // the field changes from place to place: forget the window (the bias in use stays)
    clear_sums();
    pair_solved_ = false;
    return;
  }
  // covariance of b (the gyro bias marginalised): noise^2 N_eff times the b block of info^-1
  const double noise_ut = std::max(pair_residual_ut_, opt_.pair_noise_ut);
  const Eigen::Matrix3d cov_b = noise_ut * noise_ut * opt_.correlation_time_s *
                                ldlt.solve(Mat6::Identity()).topLeftCorner<3, 3>();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov_b, Eigen::EigenvaluesOnly);
  // ascending variances: the second is the second best-determined direction
  bias_sigma_ut_ = std::sqrt(std::max(0.0, eig.eigenvalues()[1]));
  if (!(bias_sigma_ut_ <= opt_.max_bias_sigma_ut)) return;  // not turned enough yet
  // every direction at its posterior mean: one the phone never turns about stays at the prior (0)
  // and, being the vertical of that phone, does not move the heading
  if (!active_) active_from_ns_ = t_ns;
  active_ = true;
  ++accepted_;
  bias_ut_ = b;
  radius_ut_ = radius;
  residual_ = last_residual_;
}

void MagCalibration::add_sphere(TimeNs t_ns, const Eigen::Vector3d& field_ut, double dt_s) {
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
  if (!active_) active_from_ns_ = t_ns;
  active_ = true;
  ++accepted_;
  bias_ut_ = b;
  radius_ut_ = std::sqrt(r2);
  residual_ = residual;
}

}  // namespace pdnav::pdr
