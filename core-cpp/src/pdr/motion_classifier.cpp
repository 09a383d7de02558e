// Motion classifier (docs/pdr.md, "Motion classifier").
#include "pdnav/pdr/motion_classifier.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace pdnav::pdr {

const char* to_string(MotionState m) {
  switch (m) {
    case MotionState::kWalking: return "walking";
    case MotionState::kHandling: return "handling";
    case MotionState::kStanding: break;
  }
  return "standing";
}

MotionClassifier::MotionClassifier(const MotionClassifierOptions& options) : opt_(options) {}

void MotionClassifier::feed(const AccelSample& s) {
  const double m = s.acc_mps2.norm();
  if (!std::isfinite(m) || (last_acc_ns_ >= 0 && s.t_ns <= last_acc_ns_)) return;
  last_acc_ns_ = s.t_ns;
  acc_.emplace_back(s.t_ns, m);
  acc_sum_ += m;
  acc_sq_ += m * m;
  const TimeNs horizon = s.t_ns - s_to_ns(opt_.window_s);
  while (!acc_.empty() && acc_.front().first <= horizon) {
    acc_sum_ -= acc_.front().second;
    acc_sq_ -= acc_.front().second * acc_.front().second;
    acc_.pop_front();
  }
  if (acc_.size() < 4) return;  // sums re-derived now and then below keep rounding bounded
  if (acc_.size() % 512 == 0) {
    acc_sum_ = acc_sq_ = 0.0;
    for (const auto& [t, v] : acc_) acc_sum_ += v, acc_sq_ += v * v;
  }
  update(s.t_ns);
}

void MotionClassifier::feed(const GyroSample& s) {
  if (!s.rate_radps.allFinite() || (last_gyro_ns_ >= 0 && s.t_ns <= last_gyro_ns_)) return;
  last_gyro_ns_ = s.t_ns;
  gyro_.emplace_back(s.t_ns, s.rate_radps);
  gyro_outer_ += s.rate_radps * s.rate_radps.transpose();
  const TimeNs horizon = s.t_ns - s_to_ns(opt_.window_s);
  while (!gyro_.empty() && gyro_.front().first <= horizon) {
    gyro_outer_ -= gyro_.front().second * gyro_.front().second.transpose();
    gyro_.pop_front();
  }
  if (gyro_.size() % 512 == 0) {
    gyro_outer_.setZero();
    for (const auto& [t, w] : gyro_) gyro_outer_ += w * w.transpose();
  }
  const double n = static_cast<double>(gyro_.size());
  const Eigen::Matrix3d c = gyro_outer_ / n;
  rate_rms_ = std::sqrt(std::max(0.0, c.trace()));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(c, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d ev = es.eigenvalues();  // ascending
  spread_ = ev[2] > 1e-12 ? std::max(0.0, ev[1]) / ev[2] : 0.0;
  update(s.t_ns);
}

void MotionClassifier::update(TimeNs t_ns) {
  const bool gyro_live = last_gyro_ns_ >= 0 && ns_to_s(t_ns - last_gyro_ns_) <= opt_.gyro_timeout_s &&
                         gyro_.size() >= 4;
  handling_raw_ = gyro_live && ((rate_rms_ > opt_.handling_rate_radps && spread_ > opt_.axis_spread_min) ||
                                rate_rms_ > opt_.extreme_rate_radps);
  if (handling_raw_) handling_last_ns_ = t_ns;
  const bool handling = handling_last_ns_ >= 0 && ns_to_s(t_ns - handling_last_ns_) <= opt_.hold_s;
  if (handling) {
    state_ = MotionState::kHandling;
    if (!span_open_) {
      // the features look back one window: the motion began up to a window earlier
      spans_.push_back(MotionSpan{t_ns - s_to_ns(opt_.window_s), t_ns, MotionState::kHandling});
      if (spans_.size() > 256) spans_.pop_front();
      span_open_ = true;
    }
    spans_.back().t_end_ns = t_ns;
    return;
  }
  span_open_ = false;
  double sigma = 0.0;
  if (acc_.size() >= 4) {
    const double n = static_cast<double>(acc_.size());
    const double mu = acc_sum_ / n;
    sigma = std::sqrt(std::max(0.0, acc_sq_ / n - mu * mu));
  }
  const bool still = sigma < opt_.standing_sigma_mps2 && (!gyro_live || rate_rms_ < opt_.standing_rate_radps);
  state_ = still ? MotionState::kStanding : MotionState::kWalking;
}

bool MotionClassifier::handling_at(TimeNs t_ns) const {
  for (auto it = spans_.rbegin(); it != spans_.rend(); ++it) {
    if (t_ns >= it->t_start_ns && t_ns <= it->t_end_ns) return true;
    if (it->t_end_ns < t_ns) break;
  }
  return false;
}

}  // namespace pdnav::pdr
