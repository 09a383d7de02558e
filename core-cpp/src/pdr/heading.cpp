// Rotation-vector / compass heading and APT's gyro re-orientation (Zhu/Li/Chen 2013, Sec. V-B).
#include "pdnav/pdr/heading.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "rotation_increment.h"

namespace pdnav::pdr {

Eigen::Vector3d forward_axis(Mount mount) {
  switch (mount) {
    case Mount::kChestScreenOut:
      return Eigen::Vector3d::UnitZ();
    case Mount::kHandheld:
    case Mount::kAuto:
      return Eigen::Vector3d::UnitY();
    case Mount::kChestCameraOut:
    default:
      return -Eigen::Vector3d::UnitZ();
  }
}

Mount mount_from_string(const std::string& s) {
  if (s == "auto") return Mount::kAuto;
  if (s == "chest" || s == "chest-camera-out") return Mount::kChestCameraOut;
  if (s == "chest-screen-out") return Mount::kChestScreenOut;
  if (s == "hand" || s == "handheld") return Mount::kHandheld;
  throw std::invalid_argument("mount '" + s + "': expected auto, chest, chest-camera-out, chest-screen-out, hand, handheld");
}

const char* to_string(Mount m) {
  switch (m) {
    case Mount::kAuto: return "auto";
    case Mount::kChestCameraOut: return "chest-camera-out";
    case Mount::kChestScreenOut: return "chest-screen-out";
    case Mount::kHandheld: return "handheld";
  }
  return "unknown";
}

namespace {
std::optional<double> horizontal_heading(double east, double north, double min_horizontal) {
  if (!std::isfinite(east) || !std::isfinite(north) || std::hypot(east, north) < min_horizontal) {
    return std::nullopt;
  }
  return wrap_two_pi(std::atan2(east, north));
}
}  // namespace

std::optional<double> rotation_vector_heading_rad(const Eigen::Vector4d& quat_xyzw,
                                                  const Eigen::Vector3d& forward_phone, double min_horizontal) {
  if (!quat_xyzw.allFinite() || quat_xyzw.norm() < 0.5) return std::nullopt;
  const Eigen::Quaterniond q(quat_xyzw[3], quat_xyzw[0], quat_xyzw[1], quat_xyzw[2]);
  const Eigen::Vector3d f = q.normalized() * forward_phone.normalized();  // ENU
  return horizontal_heading(f.x(), f.y(), min_horizontal);
}

std::optional<double> compass_heading_rad(const Eigen::Vector3d& field_phone, const Eigen::Vector3d& up_phone,
                                          const Eigen::Vector3d& forward_phone, double min_horizontal) {
  if (!field_phone.allFinite() || !up_phone.allFinite() || up_phone.norm() < 1e-6) return std::nullopt;
  const Eigen::Vector3d up = up_phone.normalized();
  const Eigen::Vector3d east_raw = field_phone.cross(up);
  if (east_raw.norm() < 1e-6) return std::nullopt;
  const Eigen::Vector3d east = east_raw.normalized();
  const Eigen::Vector3d north = up.cross(east);
  const Eigen::Vector3d f = forward_phone.normalized();
  return horizontal_heading(f.dot(east), f.dot(north), min_horizontal);
}

GyroTurnTracker::GyroTurnTracker(const TurnOptions& options)
    : opt_(options), acc_window_(options.window_s, Eigen::Vector3d::Zero()) {}

void GyroTurnTracker::feed(const AccelSample& s) {
  const SampleCheck c = check_sample(s.t_ns, s.acc_mps2.allFinite(), acc_last_ns_, have_acc_last_,
                                     opt_.gap_reset_s, accel_counters_);
  if (c == SampleCheck::kNonFinite || c == SampleCheck::kDuplicate || c == SampleCheck::kBackwards) return;
  if (c == SampleCheck::kGap) {
    acc_window_.clear();
  }
  const double dt_acc = have_acc_last_ ? ns_to_s(s.t_ns - acc_last_ns_) : 0.0;
  const double a_norm = s.acc_mps2.norm();
  if (tilt_ok_ && dt_acc > 0.0 && a_norm > 1e-6) {
    // the attitude's up pulled toward the specific force (Mahony): the smallest rotation of the
    // phone that moves it there, about a horizontal axis (the yaw is left to the gyro)
    const Eigen::Vector3d target =
        (tilt_up_ + std::min(1.0, dt_acc / opt_.tilt_tau_s) * (s.acc_mps2 / a_norm - tilt_up_)).normalized();
    attitude_ = (attitude_ * Eigen::Quaterniond::FromTwoVectors(target, tilt_up_)).normalized();
    tilt_up_ = attitude_.conjugate() * Eigen::Vector3d::UnitZ();
  }
  have_acc_last_ = true;
  acc_last_ns_ = s.t_ns;
  acc_window_.push(s.t_ns, s.acc_mps2);
  const bool window_full = acc_window_.size() >= 2 && acc_window_.covered_s() >= 0.8 * opt_.window_s;
  // APT: average the acceleration while walking straight to estimate gravity; hold it in turns.
  if (window_full && (state_ == State::kStraight || !have_gravity_)) {
    const Eigen::Vector3d mean = acc_window_.sum() / static_cast<double>(acc_window_.size());
    if (mean.norm() > 0.3 * kStandardGravity_mps2) {
      up_ = mean.normalized();
      have_gravity_ = true;
    }
  }
  if (!tilt_ok_ && have_gravity_ && window_full && opt_.tilt_tau_s > 0.0) {  // starts level from the mean, once
    attitude_ = Eigen::Quaterniond::FromTwoVectors(up_, Eigen::Vector3d::UnitZ());
    // the gyro frame's "north" is the yaw axis' start direction: its yaw starts at 0, as the
    // vertical-rate integral does (initial_heading_rad is the reference axis' heading then)
    const Eigen::Vector3d v = attitude_ * yaw_axis_;
    if (std::hypot(v.x(), v.y()) >= 0.2)
      attitude_ = (Eigen::Quaterniond(Eigen::AngleAxisd(std::atan2(v.x(), v.y()), Eigen::Vector3d::UnitZ())) * attitude_).normalized();
    tilt_up_ = up_;
    tilt_ok_ = true;
    update_axis_yaw();
  }
}

void GyroTurnTracker::set_yaw_axis(const Eigen::Vector3d& axis_phone) {
  if (!axis_phone.allFinite() || axis_phone.norm() < 1e-9) return;
  if ((axis_phone.normalized() - yaw_axis_).norm() < 1e-12) return;
  yaw_axis_ = axis_phone.normalized();
  axis_yaw_init_ = false;  // another axis: its yaw starts from its own heading in the gyro frame
  update_axis_yaw();
}

void GyroTurnTracker::update_axis_yaw() {
  if (!tilt_ok_) return;
  const Eigen::Vector3d v = attitude_ * yaw_axis_;
  if (std::hypot(v.x(), v.y()) < 0.2) return;  // near vertical: held
  const double yaw = -std::atan2(v.x(), v.y());  // heading clockwise from the frame's +y; yaw = -heading
  axis_yaw_rad_ = axis_yaw_init_ ? axis_yaw_rad_ + wrap_pi(yaw - axis_yaw_wrapped_) : yaw;
  axis_yaw_init_ = true;
  axis_yaw_wrapped_ = yaw;
}

void GyroTurnTracker::feed(const GyroSample& s) {
  const SampleCheck c = check_sample(s.t_ns, s.rate_radps.allFinite(), gyro_last_ns_, have_gyro_last_,
                                     opt_.gap_reset_s, gyro_counters_);
  if (c == SampleCheck::kNonFinite || c == SampleCheck::kDuplicate || c == SampleCheck::kBackwards) return;
  const bool integrate = have_gyro_last_ && c != SampleCheck::kGap && have_gravity_;
  if (c == SampleCheck::kGap) {
    // Heading across the gap is unknown: restart the windows (no turn spans a gap).
    history_.clear();
    state_ = State::kStraight;
  }
  if (integrate) {
    // Trapezoidal angular displacement, projected on the vertical (APT Sec. V-B): about the
    // attitude's instantaneous gravity (the same rotation carries the attitude), else about the
    // held mean
    const double dt = ns_to_s(s.t_ns - gyro_last_ns_);
    const Eigen::Vector3d w = 0.5 * (s.rate_radps + gyro_last_);
    if (tilt_ok_) {
      const Eigen::Vector3d before = tilt_up_;
      if (w.norm() * dt > 0.0) attitude_ = (attitude_ * detail::rotation_increment(w, dt)).normalized();
      tilt_up_ = attitude_.conjugate() * Eigen::Vector3d::UnitZ();
      yaw_rad_ += w.dot(0.5 * (before + tilt_up_)) * dt;
      update_axis_yaw();
    } else {
      yaw_rad_ += w.dot(up_) * dt;
    }
  }
  have_gyro_last_ = true;
  gyro_last_ns_ = s.t_ns;
  gyro_last_ = s.rate_radps;
  if (!have_gravity_) return;
  history_.push_back({s.t_ns, yaw_rad_, axis_yaw_rad()});
  trim_history(s.t_ns);
  update_turn_state(s.t_ns);
}

void GyroTurnTracker::trim_history(TimeNs t_ns) {
  const TimeNs keep = s_to_ns(3.0 * opt_.window_s);
  while (!history_.empty() && history_.front().t_ns < t_ns - keep) history_.pop_front();
}

std::optional<double> GyroTurnTracker::axis_yaw_rad_at(TimeNs t_ns) const {
  if (history_.empty() || t_ns < history_.front().t_ns || t_ns > history_.back().t_ns) return std::nullopt;
  const auto after = std::lower_bound(history_.begin(), history_.end(), t_ns,
                                      [](const YawAt& y, TimeNs t) { return y.t_ns < t; });
  if (after == history_.begin() || after->t_ns == t_ns) return after->axis_yaw;
  const auto before = after - 1;
  const double f = static_cast<double>(t_ns - before->t_ns) / static_cast<double>(after->t_ns - before->t_ns);
  return before->axis_yaw + f * (after->axis_yaw - before->axis_yaw);
}

bool GyroTurnTracker::window_straight() const {
  const TimeNs t = history_.back().t_ns;
  const TimeNs w = s_to_ns(opt_.window_s);
  // yaw at the start of the window: latest sample at or before t - w
  const YawAt* start = nullptr;
  for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
    if (it->t_ns <= t - w) {
      start = &*it;
      break;
    }
  }
  if (!start) start = &history_.front();
  double lo = start->yaw, hi = start->yaw;
  for (auto it = history_.rbegin(); it != history_.rend() && it->t_ns >= start->t_ns; ++it) {
    lo = std::min(lo, it->yaw);
    hi = std::max(hi, it->yaw);
  }
  return std::abs(history_.back().yaw - start->yaw) < opt_.straight_threshold_rad &&
         hi - lo < 2.0 * opt_.straight_threshold_rad;
}

double GyroTurnTracker::mean_yaw(TimeNs from_ns, TimeNs to_ns) const {
  double sum = 0.0;
  int n = 0;
  for (const auto& h : history_) {
    if (h.t_ns >= from_ns && h.t_ns <= to_ns) {
      sum += h.yaw;
      ++n;
    }
  }
  if (n == 0) return history_.empty() ? yaw_rad_ : history_.front().yaw;
  return sum / n;
}

void GyroTurnTracker::update_turn_state(TimeNs t_ns) {
  const TimeNs w = s_to_ns(opt_.window_s);
  const bool straight_now = window_straight();
  switch (state_) {
    case State::kStraight:
      if (!straight_now) {
        // Onset lies within the last window: the anchor is the mean yaw of the window before it.
        const TimeNs from = std::max(t_ns - 2 * w, last_turn_end_ns_);
        anchor_yaw_ = mean_yaw(from, std::max(from, t_ns - w));
        turn_start_ns_ = t_ns - w;
        state_ = State::kTurning;
      }
      break;
    case State::kTurning:
      if (straight_now) {
        state_ = State::kSettling;
        settle_since_ns_ = t_ns;
      }
      break;
    case State::kSettling:
      if (!straight_now) {
        state_ = State::kTurning;
      } else if (t_ns - settle_since_ns_ >= w) {
        // A whole straight window after the turn: its mean yaw is the new direction.
        const double angle = mean_yaw(t_ns - w, t_ns) - anchor_yaw_;
        const TimeNs end_ns = settle_since_ns_;
        if (std::abs(angle) >= opt_.report_threshold_rad) {
          turns_.push_back(PdrTurn{end_ns, turn_start_ns_, angle});
        }
        last_turn_end_ns_ = end_ns;
        state_ = State::kStraight;
      }
      break;
  }
}

std::vector<PdrTurn> GyroTurnTracker::take_turns() {
  std::vector<PdrTurn> out;
  out.swap(turns_);
  return out;
}

}  // namespace pdnav::pdr
