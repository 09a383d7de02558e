#include "pdnav/gnss/kalman.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace pdnav::gnss {
namespace {

/// Symmetrise and floor the diagonal so rounding never makes P indefinite.
RobustKalman::Matrix tidy(const RobustKalman::Matrix& p) {
  RobustKalman::Matrix s = 0.5 * (p + p.transpose());
  for (int i = 0; i < RobustKalman::kStates; ++i) s(i, i) = std::max(s(i, i), 1e-12);
  return s;
}

}  // namespace

bool parse_kf_dynamics(const std::string& s, KfDynamics& out) {
  if (s == "pedestrian") { out = KfDynamics::kPedestrian; return true; }
  if (s == "vehicle") { out = KfDynamics::kVehicle; return true; }
  return false;
}

const char* kf_dynamics_name(KfDynamics d) { return d == KfDynamics::kPedestrian ? "pedestrian" : "vehicle"; }

double kf_accel_psd_m2ps3(KfDynamics d) { return d == KfDynamics::kPedestrian ? 1.0 : 10.0; }

double fix_variance_scale_for(const KalmanOptions& opt, double dt_s, double gain) {
  const double s1 = opt.fix_variance_scale;
  if (!(s1 > 1.0)) return std::max(s1, 1e-3);  // no correlation model (or a deliberate shrink)
  const double rho1 = (s1 - 1.0) / (s1 + 1.0);
  const double dt = std::isfinite(dt_s) && dt_s > 0.0 ? dt_s : 1.0;
  const double g = std::isfinite(gain) ? std::clamp(gain, 0.0, 1.0) : 0.0;
  const double a = std::pow(rho1, dt) * (1.0 - g);
  return (1.0 + a) / (1.0 - a);
}

double igg3_weight(double t, double k0, double k1) {
  const double a = std::fabs(t);
  if (!std::isfinite(a)) return 0.0;
  if (a <= k0) return 1.0;
  if (a > k1 || !(k1 > k0)) return 0.0;
  const double f = (k1 - a) / (k1 - k0);
  return k0 / a * f * f;
}

RobustKalman::RobustKalman(KalmanOptions opt) : opt_(opt) {
  if (!std::isfinite(opt_.accel_psd_h_m2ps3)) opt_.accel_psd_h_m2ps3 = kf_accel_psd_m2ps3(opt_.dynamics);
}

Eigen::Matrix3d RobustKalman::accel_psd_ecef() const {
  const Eigen::Vector3d d(opt_.accel_psd_h_m2ps3, opt_.accel_psd_h_m2ps3,
                          opt_.accel_psd_h_m2ps3 * opt_.vertical_psd_fraction);
  if (!(x_.head<3>().norm() > 1e6)) return Eigen::Matrix3d::Identity() * opt_.accel_psd_h_m2ps3;
  const Eigen::Matrix3d rot = geo::ecef_to_enu_rotation(geo::to_geodetic(position()));  // ENU = rot * ECEF
  return rot.transpose() * d.asDiagonal() * rot;
}

void RobustKalman::reset(const geo::Ecef& pos, const Eigen::Matrix3d& pos_cov, double clock_m, double clock_var_m2) {
  x_.setZero();
  x_.head<3>() = pos.p_m;
  x_(6) = clock_m;
  p_.setZero();
  p_.topLeftCorner<3, 3>() = pos_cov;
  p_.block<3, 3>(3, 3) = Eigen::Matrix3d::Identity() * opt_.initial_velocity_var_m2ps2;
  p_(6, 6) = clock_var_m2;
  p_(7, 7) = 1e6;  // drift unknown: (1 km/s)^2
  p_ = tidy(p_);
  initialized_ = x_.allFinite() && p_.allFinite();
  rejections_in_row_ = 0;
  rejected_span_s_ = 0.0;
  fix_gain_ = 0.0;
}

void RobustKalman::predict(const Eigen::Vector3d& disp_m, const Eigen::Matrix3d& disp_cov, double clock_change_m,
                           double clock_change_var_m2, double dt_s) {
  if (!initialized_ || !disp_m.allFinite() || !disp_cov.allFinite()) return;
  const double dt = dt_s > 0.0 && std::isfinite(dt_s) ? dt_s : 1.0;
  // r_k = r_{k-1} + d (measured); v and drift random-walk: F = I, Q = blockdiag(Sigma_d + q, S_a dt, ...)
  x_.head<3>() += disp_m;
  p_.topLeftCorner<3, 3>() += disp_cov + Eigen::Matrix3d::Identity() * opt_.displacement_q_m2;
  p_.block<3, 3>(3, 3) += accel_psd_ecef() * dt;
  if (std::isfinite(clock_change_m) && std::isfinite(clock_change_var_m2)) {
    x_(6) += clock_change_m;
    p_(6, 6) += clock_change_var_m2;
  } else {
    x_(6) += x_(7) * dt;
    p_(6, 6) += opt_.clock_q_m2ps * dt + p_(7, 7) * dt * dt;
  }
  p_(7, 7) += opt_.drift_q_m2ps3 * dt;
  p_ = tidy(p_);
}

double RobustKalman::displacement_mahalanobis2(const Eigen::Vector3d& disp_m, const Eigen::Matrix3d& disp_cov,
                                               double dt_s) const {
  if (!initialized_ || !disp_m.allFinite() || !disp_cov.allFinite() || !(dt_s > 0.0)) return kNaN;
  const Eigen::Vector3d nu = disp_m - x_.segment<3>(3) * dt_s;
  const Eigen::Matrix3d s = p_.block<3, 3>(3, 3) * dt_s * dt_s + accel_psd_ecef() * (dt_s * dt_s * dt_s / 3.0) + disp_cov;
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(s);
  if (ldlt.info() != Eigen::Success) return kNaN;
  return nu.dot(ldlt.solve(nu));
}

void RobustKalman::coast(double dt_s) {
  if (!initialized_ || !(dt_s > 0.0) || !std::isfinite(dt_s)) return;
  Matrix f = Matrix::Identity();
  f.block<3, 3>(0, 3) = Eigen::Matrix3d::Identity() * dt_s;
  f(6, 7) = dt_s;
  // white acceleration (Bar-Shalom, Li & Kirubarajan 2001, Sec. 6.2.2): Q = S [dt^3/3 dt^2/2; dt^2/2 dt]
  const Eigen::Matrix3d s = accel_psd_ecef();
  Matrix q = Matrix::Zero();
  const double t2 = dt_s * dt_s, t3 = t2 * dt_s;
  q.topLeftCorner<3, 3>() = s * (t3 / 3.0);
  q.block<3, 3>(0, 3) = s * (t2 / 2.0);
  q.block<3, 3>(3, 0) = s * (t2 / 2.0);
  q.block<3, 3>(3, 3) = s * dt_s;
  // clock phase and frequency random walks (Groves 2013, Sec. 9.4.2.2 form)
  q(6, 6) = opt_.clock_q_m2ps * dt_s + opt_.drift_q_m2ps3 * t3 / 3.0;
  q(6, 7) = q(7, 6) = opt_.drift_q_m2ps3 * t2 / 2.0;
  q(7, 7) = opt_.drift_q_m2ps3 * dt_s;
  x_ = f * x_;
  p_ = tidy(f * p_ * f.transpose() + q);
}

void RobustKalman::shift_clock(double delta_m) {
  if (initialized_ && std::isfinite(delta_m)) x_(6) += delta_m;
}

void RobustKalman::reset_clock(double clock_m, double clock_var_m2) {
  if (!initialized_) return;
  x_(6) = std::isfinite(clock_m) ? clock_m : 0.0;
  p_.row(6).setZero();
  p_.col(6).setZero();
  p_(6, 6) = std::isfinite(clock_var_m2) ? clock_var_m2 : 1e12;
  p_ = tidy(p_);
}

template <int M>
KalmanUpdateResult RobustKalman::robust_update(const Eigen::Matrix<double, M, 1>& z,
                                               const Eigen::Matrix<double, M, kStates>& h,
                                               const Eigen::Matrix<double, M, M>& r_in, bool allow_reset,
                                               double span_s) {
  KalmanUpdateResult out;
  const Eigen::Matrix<double, M, 1> nu = z - h * x_;
  const Eigen::Matrix<double, M, M> s0 = h * p_ * h.transpose() + r_in;
  const Eigen::LDLT<Eigen::Matrix<double, M, M>> ldlt0(s0);
  const double m2 = nu.dot(ldlt0.solve(nu));
  out.standardised_innovation = std::sqrt(std::max(m2, 0.0) / M);
  Eigen::Matrix<double, M, M> r = r_in;
  bool reject = !std::isfinite(m2);
  if (opt_.robust_igg3 && !reject) {
    out.robust_weight = igg3_weight(out.standardised_innovation, opt_.igg_k0, opt_.igg_k1);
    if (out.robust_weight <= 0.0) reject = true;
    else r /= out.robust_weight;
  }
  Vector x_post = x_;
  Matrix p_post = p_;
  if (!reject) {
    const Eigen::Matrix<double, M, M> s = h * p_ * h.transpose() + r;
    const Eigen::Matrix<double, kStates, M> k = p_ * h.transpose() * s.inverse();
    x_post = x_ + k * nu;
    const Matrix ikh = Matrix::Identity() - k * h;
    p_post = tidy(ikh * p_ * ikh.transpose() + k * r * k.transpose());  // Joseph form
    // Walker's posterior residual test: e = z - H x+, C = R - H P+ H'
    const Eigen::Matrix<double, M, 1> e = z - h * x_post;
    const Eigen::Matrix<double, M, M> c = r - h * p_post * h.transpose();
    for (int i = 0; i < M; ++i) {
      const double var = std::max(c(i, i), 1e-9);
      out.max_normalised_residual = std::max(out.max_normalised_residual, e(i) * e(i) / var);
    }
    reject = !x_post.allFinite() || out.max_normalised_residual > opt_.residual_threshold;
  }
  if (reject) {
    if (allow_reset) {
      rejected_span_s_ += span_s;
      if (++rejections_in_row_ > opt_.max_consecutive_rejections || rejected_span_s_ > opt_.max_rejected_span_s)
        out.reset = true;
    }
    return out;
  }
  if (allow_reset) {
    rejections_in_row_ = 0;
    rejected_span_s_ = 0.0;
  }
  x_ = x_post;
  p_ = p_post;
  out.accepted = true;
  return out;
}

KalmanUpdateResult RobustKalman::update(const geo::Ecef& fix, const Eigen::Matrix3d& fix_cov, double clock_m,
                                        double clock_var_m2, double since_last_fix_s) {
  KalmanUpdateResult out;
  if (!fix.p_m.allFinite() || !fix_cov.allFinite() || !std::isfinite(clock_m) || !std::isfinite(clock_var_m2)) return out;
  Eigen::Matrix4d r = Eigen::Matrix4d::Zero();
  const double scale = fix_variance_scale_for(opt_, since_last_fix_s, fix_gain_);
  r.topLeftCorner<3, 3>() = fix_cov * scale;
  for (int i = 0; i < 3; ++i) r(i, i) = std::max(r(i, i), opt_.min_fix_variance_m2);
  r(3, 3) = std::max(clock_var_m2 * scale, opt_.min_fix_variance_m2);
  if (!initialized_) {
    reset(fix, r.topLeftCorner<3, 3>(), clock_m, r(3, 3));
    out.accepted = initialized_;
    out.reset = true;
    return out;
  }
  Eigen::Vector4d z;
  z << fix.p_m, clock_m;
  Eigen::Matrix<double, 4, kStates> h = Eigen::Matrix<double, 4, kStates>::Zero();
  h.block<3, 3>(0, 0).setIdentity();
  h(3, 6) = 1.0;
  const Eigen::Vector3d prior_var = p_.topLeftCorner<3, 3>().diagonal();
  out = robust_update<4>(z, h, r, true, std::isfinite(since_last_fix_s) && since_last_fix_s > 0.0 ? since_last_fix_s : 1.0);
  if (out.accepted) {  // scalar form per axis: P+ = (1 - K) P-
    double g = 0.0;
    for (int i = 0; i < 3; ++i) g += (1.0 - p_(i, i) / prior_var(i)) / 3.0;
    fix_gain_ = std::isfinite(g) ? std::clamp(g, 0.0, 1.0) : 0.0;
  }
  if (out.reset) {
    // the filter diverged (persistent rejections): restart from the fix, keep the velocity
    const Eigen::Vector3d v = x_.segment<3>(3);
    const Eigen::Matrix3d pv = p_.block<3, 3>(3, 3);
    reset(fix, r.topLeftCorner<3, 3>(), clock_m, r(3, 3));
    x_.segment<3>(3) = v;
    p_.block<3, 3>(3, 3) = pv;
    out.accepted = true;
  }
  return out;
}

KalmanUpdateResult RobustKalman::update_velocity(const Eigen::Vector3d& vel_mps, const Eigen::Matrix3d& vel_cov,
                                                 double drift_mps, double drift_var_m2ps2) {
  KalmanUpdateResult out;
  if (!initialized_ || !vel_mps.allFinite() || !vel_cov.allFinite()) return out;
  Eigen::Matrix3d r = vel_cov;
  for (int i = 0; i < 3; ++i) r(i, i) = std::max(r(i, i), opt_.min_velocity_variance_m2ps2);
  if (std::isfinite(drift_mps) && std::isfinite(drift_var_m2ps2)) {
    Eigen::Vector4d z;
    z << vel_mps, drift_mps;
    Eigen::Matrix<double, 4, kStates> h = Eigen::Matrix<double, 4, kStates>::Zero();
    h.block<3, 3>(0, 3).setIdentity();
    h(3, 7) = 1.0;
    Eigen::Matrix4d r4 = Eigen::Matrix4d::Zero();
    r4.topLeftCorner<3, 3>() = r;
    r4(3, 3) = std::max(drift_var_m2ps2, opt_.min_velocity_variance_m2ps2);
    return robust_update<4>(z, h, r4, false, 0.0);
  }
  Eigen::Matrix<double, 3, kStates> h = Eigen::Matrix<double, 3, kStates>::Zero();
  h.block<3, 3>(0, 3).setIdentity();
  return robust_update<3>(vel_mps, h, r, false, 0.0);
}

void RobustKalman::set_velocity(const Eigen::Vector3d& vel_mps, const Eigen::Matrix3d& vel_cov, double drift_mps,
                                double drift_var_m2ps2) {
  if (!initialized_ || !vel_mps.allFinite() || !vel_cov.allFinite()) return;
  x_.segment<3>(3) = vel_mps;
  p_.middleRows<3>(3).setZero();
  p_.middleCols<3>(3).setZero();
  p_.block<3, 3>(3, 3) = vel_cov;
  for (int i = 3; i < 6; ++i) p_(i, i) = std::max(p_(i, i), opt_.min_velocity_variance_m2ps2);
  if (std::isfinite(drift_mps) && std::isfinite(drift_var_m2ps2)) {
    x_(7) = drift_mps;
    p_.row(7).setZero();
    p_.col(7).setZero();
    p_(7, 7) = std::max(drift_var_m2ps2, opt_.min_velocity_variance_m2ps2);
  }
  p_ = tidy(p_);
}

Eigen::Matrix3d RobustKalman::position_cov_enu() const {
  const Eigen::Matrix3d rot = geo::ecef_to_enu_rotation(geo::to_geodetic(position()));
  return rot * position_cov_ecef() * rot.transpose();
}

}  // namespace pdnav::gnss
