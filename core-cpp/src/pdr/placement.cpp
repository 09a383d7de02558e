// Placement and walking direction from the motion (docs/pdr.md, "Placement").
#include "pdnav/pdr/placement.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "lowpass.h"

namespace pdnav::pdr {

const char* to_string(Placement p) {
  switch (p) {
    case Placement::kFlat: return "flat";
    case Placement::kUpright: return "upright";
    case Placement::kOther: return "other";
    case Placement::kUnknown: break;
  }
  return "unknown";
}

PlacementEstimator::PlacementEstimator(const PlacementOptions& options)
    : opt_(options), win_(options.gravity_window_s, Eigen::Vector3d::Zero()) {}

void PlacementEstimator::end_bout() {
  if (in_bout_) closed_.push_back(bout_);
  in_bout_ = false;
  moved_since_ns_ = -1;
}

void PlacementEstimator::start_bout(TimeNs t_ns) {
  in_bout_ = true;
  bout_ = PlacementBout{};
  bout_.t_start_ns = bout_.t_end_ns = t_ns;
  bout_up_ = up_;
  corr_.setZero();
  cov_h_.setZero();
  corr_band_.setZero();
  cov_h_band_.setZero();
  var_v_band_ = band_walking_s_ = 0.0;
  cov_w_.setZero();
  sum_up_walk_.setZero();
  var_v_ = n_corr_ = walking_s_ = swing_sq_ = swing_n_ = 0.0;
  prior_supported_ = reversed_ = prior_rejected_ = bout_levelled_ = false;
  flat_axis_ = Eigen::Vector3d::UnitY();
  // placement from the dominant gravity axis; the reference axis is the placement's prior
  // walking axis (flat: +Y, upright: -Z), else the most horizontal of +X, +Y, -Z
  const double ax = std::abs(up_.x()), ay = std::abs(up_.y()), az = std::abs(up_.z());
  const bool held_in_front = up_.z() >= std::cos(opt_.held_front_max_pitch_rad) && up_.y() >= 0.0 &&
                             ax <= std::sin(opt_.held_front_max_roll_rad);
  if ((az >= ax && az >= ay && az >= opt_.flat_min) || held_in_front) {
    bout_.placement = Placement::kFlat;
    reference_ = Eigen::Vector3d::UnitY();
  } else if (ay >= ax && ay >= az && ay >= opt_.upright_min) {
    bout_.placement = Placement::kUpright;
    reference_ = -Eigen::Vector3d::UnitZ();
  } else {
    bout_.placement = Placement::kOther;
    reference_ = (az <= ax && az <= ay) ? Eigen::Vector3d(-Eigen::Vector3d::UnitZ())
                 : (ay <= ax)           ? Eigen::Vector3d(Eigen::Vector3d::UnitY())
                                        : Eigen::Vector3d(Eigen::Vector3d::UnitX());
  }
  ++revision_;
  update_forward();
}

void PlacementEstimator::feed(const GyroSample& s) {
  if (!s.rate_radps.allFinite()) return;
  have_gyro_ = true;
  feed_rate(s.t_ns, s.rate_radps);
}

std::optional<Eigen::Vector3d> PlacementEstimator::feed(const MagSample& s) {
  const double n = s.field_ut.norm();
  if (!(opt_.mag_rate_lowpass_hz > 0.0) || !s.field_ut.allFinite() || !(n > 1e-6)) return std::nullopt;
  // a phone with a gyroscope: it gives the rate (its first sample may come a little after the field's)
  if (have_gyro_) return std::nullopt;
  if (first_mag_ns_ < 0) first_mag_ns_ = s.t_ns;
  const double dt = mag_ns_ >= 0 ? ns_to_s(s.t_ns - mag_ns_) : -1.0;
  if (mag_ns_ >= 0 && !(dt > 0.0)) return std::nullopt;  // a duplicate or backwards sample
  mag_ns_ = s.t_ns;
  const bool gap = dt < 0.0 || dt > 0.5;  // first sample or after a gap: both filters restart
  // the steadiness of the field's magnitude
  if (gap) mag_norm_mean_ut_ = n;
  else mag_norm_mean_ut_ += std::min(1.0, dt / opt_.mag_steady_tau_s) * (n - mag_norm_mean_ut_);
  const bool steady = std::abs(n / mag_norm_mean_ut_ - 1.0) <= opt_.mag_steady_tolerance;
  if (!steady || ns_to_s(s.t_ns - first_mag_ns_) <= opt_.mag_rate_start_s) {
    mag_lp_running_ = false;  // the direction filter restarts with the next steady reading
    return std::nullopt;
  }
  const Eigen::Vector3d m = s.field_ut / n;
  if (gap || !mag_lp_running_) {
    mag_lp1_ = mag_lp2_ = m;
    mag_lp_running_ = true;
    return std::nullopt;
  }
  const Eigen::Vector3d before = mag_lp2_;
  detail::lowpass2(mag_lp1_, mag_lp2_, m, detail::lowpass_gain(dt, opt_.mag_rate_lowpass_hz));
  const double n2 = before.squaredNorm() * mag_lp2_.squaredNorm();
  if (!(n2 > 1e-12)) return std::nullopt;
  // dm/dt = m x w: the rate square to the field is -(m x dm/dt) / |m|^2
  const Eigen::Vector3d rate_radps = -before.cross(mag_lp2_) / (std::sqrt(n2) * dt);
  feed_rate(s.t_ns, rate_radps);
  return rate_radps;
}

void PlacementEstimator::feed_rate(TimeNs t_ns, const Eigen::Vector3d& rate_radps) {
  // the gait band of the angular rate (the same first-order high-pass as the acceleration's)
  const double dt = w_hp_ns_ >= 0 ? ns_to_s(t_ns - w_hp_ns_) : -1.0;
  if (dt > 0.0 && dt <= 0.5 && opt_.gait_highpass_hz > 0.0) {
    const double a = 1.0 / (1.0 + 2.0 * kPi * opt_.gait_highpass_hz * dt);
    w_hp_out_ = a * (w_hp_out_ + rate_radps - w_hp_in_);
    w_hp_in_ = rate_radps;
    w_hp_ns_ = t_ns;
  } else if (w_hp_ns_ < 0 || dt > 0.5) {  // first sample or after a gap: the filter restarts
    w_hp_in_ = rate_radps;
    w_hp_out_.setZero();
    w_hp_ns_ = t_ns;
  }  // a duplicate or backwards sample leaves the filter as it is
  gyro_radps_ = rate_radps;
  gyro_ns_ = t_ns;
}

void PlacementEstimator::feed(const AccelSample& s, bool walking) {
  if (!s.acc_mps2.allFinite()) return;
  if (have_last_ && s.t_ns <= last_ns_) return;
  const double dt = have_last_ ? ns_to_s(s.t_ns - last_ns_) : 0.0;
  // tilt filter: gravity propagated with the gyro (a world-fixed vector moves as u x w in
  // phone axes), pulled toward the measured specific force with time constant tilt_tau_s
  const double a_norm = s.acc_mps2.norm();
  const bool gyro_fresh = gyro_ns_ >= 0 && std::abs(ns_to_s(s.t_ns - gyro_ns_)) <= opt_.gyro_max_age_s;
  const double dt_tilt = tilt_ns_ >= 0 ? ns_to_s(s.t_ns - tilt_ns_) : -1.0;
  if (!gyro_fresh || a_norm < 1e-6) {
    tilt_ok_ = false;
  } else if (!tilt_ok_ || !(dt_tilt > 0.0) || dt_tilt > 0.5) {  // (re)start from the specific force
    tilt_up_ = s.acc_mps2 / a_norm;
    tilt_ok_ = true;
  } else {
    tilt_up_ += tilt_up_.cross(gyro_radps_) * dt_tilt;
    tilt_up_ += std::min(1.0, dt_tilt / opt_.tilt_tau_s) * (s.acc_mps2 / a_norm - tilt_up_);
    tilt_up_.normalize();
  }
  tilt_ns_ = s.t_ns;
  if (have_last_ && dt > 0.5) {  // a gap: statistics restart, the bout goes on
    win_.clear();
    hist_.clear();
  }
  have_last_ = true;
  last_ns_ = s.t_ns;
  win_.push(s.t_ns, s.acc_mps2);
  const Eigen::Vector3d mean = win_.sum() / static_cast<double>(win_.size());
  if (win_.size() < 2 || win_.covered_s() < 0.5 * opt_.gravity_window_s ||
      mean.norm() < 0.3 * kStandardGravity_mps2)
    return;
  up_ = mean.normalized();
  have_up_ = true;
  if (!in_bout_) start_bout(s.t_ns);
  bout_.t_end_ns = s.t_ns;
  // placement change: gravity moved in phone axes and stayed moved
  if (std::acos(std::clamp(up_.dot(bout_up_), -1.0, 1.0)) > opt_.change_angle_rad) {
    if (moved_since_ns_ < 0) moved_since_ns_ = s.t_ns;
    if (ns_to_s(s.t_ns - moved_since_ns_) >= opt_.change_hold_s) {
      end_bout();
      start_bout(s.t_ns);
      return;
    }
  } else {
    moved_since_ns_ = -1;
  }
  // vertical and horizontal linear acceleration; horizontal kept for the lagged product
  // linear acceleration, high-passed so that only the gait (>= ~1 Hz) enters the phase
  // correlation: a phone being tilted or lowered leaves a slow ramp in (a - 2 s mean) that
  // correlates with itself at any lag
  // with the tilt filter: split about the instantaneous gravity (no tilt leaks into it); a
  // flat phone keeps the 2 s mean: there the hand's pitch at the step frequency is part of the
  // forward-phase signature (levelled, the sign of 3 of the 43 ILC walks flips, 2.44 -> 2.68 m)
  const bool level = tilt_ok_ && bout_.placement != Placement::kFlat;
  if (walking) bout_levelled_ = level;
  const Eigen::Vector3d& u = level ? tilt_up_ : up_;
  const Eigen::Vector3d raw_lin = level ? Eigen::Vector3d(s.acc_mps2 - mean.norm() * u) : Eigen::Vector3d(s.acc_mps2 - mean);
  const Eigen::Vector3d lin = gait_band(raw_lin, dt);
  const double av = lin.dot(u);
  const Eigen::Vector3d h = lin - av * u;
  // the same about the step frequency, once the cadence is known and the band has settled
  const Eigen::Vector3d lin_band = step_band(raw_lin, dt);
  const double f_step = step_frequency_hz();
  const bool band = f_step > 0.0 && bp_settle_s_ >= 2.0 / f_step;
  const double av_band = lin_band.dot(u);
  hist_.push_back({s.t_ns, h, lin_band - av_band * u, band});
  const TimeNs lag_t = s.t_ns - s_to_ns(opt_.phase_lag_s);
  while (hist_.size() > 1 && hist_[1].t_ns <= lag_t) hist_.pop_front();
  if (walking && hist_.front().t_ns <= lag_t && ns_to_s(lag_t - hist_.front().t_ns) < 0.05) {
    const Eigen::Vector3d& hl = hist_.front().h;
    corr_ += av * hl;
    cov_h_ += hl * hl.transpose();
    if (band && hist_.front().band) {
      const Eigen::Vector3d& bl = hist_.front().h_band;
      corr_band_ += av_band * bl;
      cov_h_band_ += bl * bl.transpose();
      var_v_band_ += av_band * av_band;
      band_walking_s_ += dt;
    }
    // the horizontal part of the gait-band angular rate about the instantaneous gravity (a flat
    // phone's too: the hand pitches it about the body's lateral axis, which tells portrait from
    // landscape, flat_square_axis)
    if (level || (tilt_ok_ && have_gyro_ && bout_.placement == Placement::kFlat)) {
      const Eigen::Vector3d w_h = w_hp_out_ - w_hp_out_.dot(tilt_up_) * tilt_up_;
      cov_w_ += w_h * w_h.transpose();
      sum_up_walk_ += tilt_up_;
    }
    if (tilt_ok_) {
      const double ang = std::acos(std::clamp(tilt_up_.dot(up_), -1.0, 1.0));
      swing_sq_ += ang * ang;
      swing_n_ += 1.0;
      bout_.tilt_swing_deg = std::sqrt(swing_sq_ / swing_n_) / kDegToRad;
    }
    var_v_ += av * av;
    n_corr_ += 1.0;
    walking_s_ += dt;
    update_forward();
  }
}

double PlacementEstimator::flip_threshold() const {
  // the correlation of T seconds of gait scatters as 1/sqrt(T): a reversal of the prior needs
  // flip_corr at flip_settle_s of walking, proportionally more before
  const double t = std::max(walking_s_, 1e-3);
  // a levelled bout (gyro-propagated tilt: pockets, at the ear) has no tilt leakage that could
  // fake the phase: once settled the correlation's sign itself decides (its magnitude is
  // 0.2-0.3 there, near flip_corr, against 0.25-0.5 for the unlevelled texting correlation)
  if (bout_levelled_ && walking_s_ >= opt_.flip_settle_s) return 0.0;
  return opt_.flip_corr * std::max(1.0, std::sqrt(opt_.flip_settle_s / t));
}

Eigen::Vector3d PlacementEstimator::gait_band(const Eigen::Vector3d& lin, double dt_s) {
  if (!(opt_.gait_highpass_hz > 0.0)) return lin;
  if (!(dt_s > 0.0) || dt_s > 0.5) {  // first sample or after a gap: the filter restarts
    hp_in_ = lin;
    hp_out_.setZero();
    return hp_out_;
  }
  const double a = 1.0 / (1.0 + 2.0 * kPi * opt_.gait_highpass_hz * dt_s);  // first-order high-pass
  hp_out_ = a * (hp_out_ + lin - hp_in_);
  hp_in_ = lin;
  return hp_out_;
}

void PlacementEstimator::set_step_interval(double interval_s) {
  if (!(opt_.step_band_q > 0.0) || !(interval_s >= 0.2 && interval_s <= 1.2)) return;
  step_intervals_s_.push_back(interval_s);
  if (step_intervals_s_.size() > 5) step_intervals_s_.pop_front();
  // the band's frequency changes only here: the median interval, once per step
  std::vector<double> v(step_intervals_s_.begin(), step_intervals_s_.end());
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  step_frequency_hz_ = 1.0 / *mid;
}

Eigen::Vector3d PlacementEstimator::step_band(const Eigen::Vector3d& x, double dt_s) {
  const double f0 = step_frequency_hz();
  // no cadence yet, first sample or a gap, or the step frequency near Nyquist: restart
  if (!(f0 > 0.0) || !(dt_s > 0.0) || dt_s > 0.5 || f0 * dt_s >= 0.25) {
    bp_x1_ = bp_x2_ = x;
    bp_y1_.setZero();
    bp_y2_.setZero();
    bp_settle_s_ = 0.0;
    return Eigen::Vector3d::Zero();
  }
  // RBJ audio-EQ cookbook band-pass, 0 dB peak gain, at the sample's own interval
  const double w0 = 2.0 * kPi * f0 * dt_s;
  const double alpha = std::sin(w0) / (2.0 * opt_.step_band_q);
  const double a0 = 1.0 + alpha;
  const Eigen::Vector3d y = (alpha * x - alpha * bp_x2_ + 2.0 * std::cos(w0) * bp_y1_ - (1.0 - alpha) * bp_y2_) / a0;
  bp_x2_ = bp_x1_;
  bp_x1_ = x;
  bp_y2_ = bp_y1_;
  bp_y1_ = y;
  bp_settle_s_ += dt_s;
  return y;
}

void PlacementEstimator::update_forward() {
  const bool trusted = walking_s_ >= opt_.min_bout_s && var_v_ > 0.0;
  // the motion's direction (horizontal): from the step band once it has min_bout_s of walking
  // (the medio-lateral sway at the stride frequency filtered out), else the broadband correlation
  const bool band = band_walking_s_ >= opt_.min_bout_s && var_v_band_ > 0.0;
  const Eigen::Vector3d& c_dir = band ? corr_band_ : corr_;
  Eigen::Vector3d d = c_dir - c_dir.dot(up_) * up_;
  // the limb-carry evidence, once per update (an eigen-decomposition, per walking sample)
  const std::optional<Eigen::Vector3d> axis_forward = trusted ? rotation_axis_forward() : std::nullopt;
  if (bout_.placement == Placement::kUpright) {
    // the upright prior's line against the motion's (levelled) direction, once the correlation
    // has settled; the flat prior stands (hand-held texting: the phone is held square to the
    // body, and the unlevelled correlation's direction scatters 32 deg around it on ILC)
    const Eigen::Vector3d prior_axis = -Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d ph = prior_axis - prior_axis.dot(up_) * up_;
    // A dominant horizontal rotation axis (a limb carry: trouser pocket, swinging hand) is direct
    // evidence of the walking direction and replaces the prior too
    if (trusted && walking_s_ >= opt_.prior_check_s && axis_forward) {
      prior_rejected_ = true;
    } else if (trusted && walking_s_ >= opt_.prior_check_s && d.norm() > 1e-9 && ph.norm() > 0.2) {
      const double cos_line = std::abs(d.normalized().dot(ph.normalized()));
      prior_rejected_ = cos_line < std::cos(opt_.prior_max_angle_rad);
    }
  }
  if (bout_.placement == Placement::kFlat && trusted && walking_s_ >= opt_.prior_check_s) flat_axis_ = flat_square_axis();
  if (prior_applies()) {
    const Eigen::Vector3d prior = bout_.placement == Placement::kFlat ? flat_axis_ : Eigen::Vector3d(-Eigen::Vector3d::UnitZ());
    double c = 0.0;
    const double vf = prior.dot(cov_h_ * prior);
    prior_supported_ = var_v_ > 0.0 && vf > 0.0 && prior.dot(corr_) > 0.0;
    if (trusted && vf > 0.0) c = prior.dot(corr_) / std::sqrt(var_v_ * vf);
    bout_.phase_corr = c;
    reversed_ = trusted && c < flip_threshold();
    bout_.forward_phone = reversed_ ? Eigen::Vector3d(-prior) : prior;
    return;
  }
  // other placements (and a rejected prior): the perpendicular of the dominant rotation axis
  // signed by the lagged correlation, else the correlation vector itself (horizontal parts)
  if (trusted && d.norm() > 1e-9) {
    d.normalize();
    if (axis_forward) d = axis_forward->dot(d) >= 0.0 ? *axis_forward : Eigen::Vector3d(-*axis_forward);
    bout_.forward_phone = d;
    const double vf = d.dot((band ? cov_h_band_ : cov_h_) * d);
    bout_.phase_corr = vf > 0.0 ? d.dot(c_dir) / std::sqrt((band ? var_v_band_ : var_v_) * vf) : 0.0;
  } else {
    bout_.forward_phone = reference_;
    bout_.phase_corr = 0.0;
  }
}

// A flat phone is held square to the body, in portrait (+Y ahead) or in landscape (+-X ahead):
// the walking line is the square axis across the dominant horizontal gait rotation (the hand
// pitching the phone about the body's lateral axis: within 16 deg of +-X on every ILC walk held
// in portrait, eigenvalue ratio <= 0.26), portrait unless that axis lies nearer +-Y and the
// lagged correlation nearer +-X. Landscape's sign (left or right edge ahead: no prior prefers
// one) is the phase correlation's; the flip test then treats it as the portrait prior. Gyroscope
// only: the magnetometer's rate misses the turning about the field (ILC without a gyroscope: 3
// walks turned to landscape, ETH 51 -> 115 m).
Eigen::Vector3d PlacementEstimator::flat_square_axis() const {
  const Eigen::Vector3d portrait = Eigen::Vector3d::UnitY();
  const std::optional<Eigen::Vector3d> dominant = dominant_rotation_axis();
  if (!dominant) return portrait;  // no dominant axis: the prior stands
  const Eigen::Vector3d& axis = *dominant;
  if (std::abs(axis.y()) <= std::abs(axis.x())) return portrait;  // pitched about +-X: portrait
  // ... and the forward acceleration must agree (the lagged correlation nearer +-X than +-Y):
  // two independent cues, so a hand that rolls the phone more than it pitches stays in portrait
  if (std::abs(corr_.x()) <= std::abs(corr_.y())) return portrait;
  return corr_.x() >= 0.0 ? Eigen::Vector3d(Eigen::Vector3d::UnitX()) : Eigen::Vector3d(-Eigen::Vector3d::UnitX());
}

// The gait rotation's dominant horizontal axis (phone axes, unsigned): the principal axis of the
// walking samples' gait-band angular rate when the second eigenvalue is below
// rotation_axis_max_ratio of the largest, else none.
std::optional<Eigen::Vector3d> PlacementEstimator::dominant_rotation_axis() const {
  if (!(opt_.rotation_axis_max_ratio > 0.0) || !(cov_w_.trace() > 0.0)) return std::nullopt;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(cov_w_);  // closed form (called per walking sample); ascending eigenvalues
  if (es.info() != Eigen::Success || !(es.eigenvalues()(2) > 0.0) ||
      es.eigenvalues()(1) > opt_.rotation_axis_max_ratio * es.eigenvalues()(2))
    return std::nullopt;
  return Eigen::Vector3d(es.eigenvectors().col(2));
}

std::optional<Eigen::Vector3d> PlacementEstimator::rotation_axis_forward() const {
  if (!bout_levelled_ || !(sum_up_walk_.norm() > 0.0)) return std::nullopt;
  const std::optional<Eigen::Vector3d> axis = dominant_rotation_axis();
  if (!axis) return std::nullopt;
  const Eigen::Vector3d f = sum_up_walk_.normalized().cross(*axis);
  if (f.norm() < 0.5) return std::nullopt;  // (the axis is horizontal by construction)
  return Eigen::Vector3d(f.normalized());
}

double PlacementEstimator::forward_offset_rad() const {
  const Eigen::Vector3d r = reference_ - reference_.dot(up_) * up_;
  const Eigen::Vector3d f = bout_.forward_phone - bout_.forward_phone.dot(up_) * up_;
  if (r.norm() < 0.2 || f.norm() < 0.2) return 0.0;
  const double ccw = std::atan2(r.cross(f).dot(up_), r.dot(f));
  return -ccw;  // clockwise seen from above
}

std::vector<PlacementBout> PlacementEstimator::bouts() const {
  std::vector<PlacementBout> out = closed_;
  if (in_bout_) out.push_back(bout_);
  return out;
}

}  // namespace pdnav::pdr
