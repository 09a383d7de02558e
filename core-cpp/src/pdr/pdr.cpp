// The PDR engine: step detector + bout gate, step length, heading (rotation vector / compass /
// gyro) and APT turn reports.
#include "pdnav/pdr/pdr.h"

#include <algorithm>
#include <cmath>

#include "pdnav/geo/wmm.h"

namespace pdnav::pdr {

Pdr::Pdr(const PdrOptions& options)
    : opt_(options),
      detector_(options.detector),
      gate_(options.detector.bout_min_steps, options.detector.max_step_interval_s,
            options.detector.short_walk_min_steps),
      tracker_(options.heading.turn) {}

void Pdr::set_location(const geo::Geodetic& where, std::int64_t utc_ms) {
  const geo::Declination d = geo::declination_at(where, utc_ms);
  if (!std::isfinite(d.declination_rad)) return;
  declination_ = d;
  declination_rad_ = d.declination_rad;
  has_location_ = true;
}

void Pdr::feed(const AccelSample& s) {
  tracker_.feed(s);
  const auto candidates = detector_.feed(s);
  if (detector_.counters().gaps != gaps_seen_) {  // a gap resets the detector and the bout
    gaps_seen_ = detector_.counters().gaps;
    release(gate_.end_bout(), s.t_ns);
  }
  latest_ns_ = std::max(latest_ns_, s.t_ns);
  release(gate_.expire(s.t_ns), s.t_ns);
  for (const auto& c : candidates) release(gate_.push(c.t_ns, hold(c.t_ns, c.swing_mps2)), s.t_ns);
  trim_consistency(s.t_ns);
}

Pdr::HeldStep Pdr::hold(TimeNs t_ns, double swing_mps2) const {
  HeldStep h;
  h.candidate.t_ns = t_ns;
  h.candidate.swing_mps2 = swing_mps2;
  // The heading at the step's own time (issue 20.2): magnetic when referenced to the rotation
  // vector or compass (declination added when the step is taken), true when gyro-only from
  // the configured initial heading.
  h.magnetic = have_heading_;
  h.heading_rad = wrap_two_pi(heading_rad() - (have_heading_ ? declination_rad_ : 0.0));
  h.heading_sigma_rad = heading_sigma_rad();
  return h;
}

void Pdr::release(const std::vector<HeldStep>& steps, TimeNs now_ns) {
  for (const auto& h : steps) {
    accel_step_times_.push_back(h.candidate.t_ns);
    const bool use = opt_.source == StepSource::kAccelerometer ||
                     (opt_.source == StepSource::kAuto && !android_active(now_ns));
    if (use) emit_step(h);
  }
}

void Pdr::finish() { release(gate_.finish(), latest_ns_); }

void Pdr::feed(const GyroSample& s) {
  tracker_.feed(s);
  latest_ns_ = std::max(latest_ns_, s.t_ns);
}

void Pdr::feed(const MagSample& s) {
  const SampleCheck c = check_sample(s.t_ns, s.field_ut.allFinite(), mag_last_ns_, have_mag_last_,
                                     opt_.heading.turn.gap_reset_s, counters_.mag);
  if (c == SampleCheck::kNonFinite || c == SampleCheck::kDuplicate || c == SampleCheck::kBackwards) return;
  const double dt_s = (have_mag_last_ && c != SampleCheck::kGap) ? ns_to_s(s.t_ns - mag_last_ns_) : 0.0;
  have_mag_last_ = true;
  mag_last_ns_ = s.t_ns;
  latest_ns_ = std::max(latest_ns_, s.t_ns);
  if (!tracker_.has_gravity()) return;
  if (have_rv_ && ns_to_s(s.t_ns - last_rv_ns_) <= opt_.heading.rv_max_age_s) return;  // RV wins
  const auto compass = compass_heading_rad(s.field_ut, tracker_.up_phone(), forward_axis(opt_.heading.mount),
                                           opt_.heading.min_horizontal);
  if (!compass) return;
  const double yaw = tracker_.yaw_rad();
  if (!have_heading_ || ref_from_rv_) {
    ref_heading_mag_rad_ = *compass;
    ref_sigma_rad_ = opt_.heading.compass_sigma_rad;
  } else {
    // Complementary filter: gyro-propagated heading pulled toward the compass.
    const double current = ref_heading_mag_rad_ - (yaw - ref_yaw_rad_);
    const double alpha = dt_s / (opt_.heading.compass_tau_s + dt_s);
    ref_heading_mag_rad_ = current + alpha * wrap_pi(*compass - current);
    ref_sigma_rad_ = std::min(heading_sigma_rad(), opt_.heading.compass_sigma_rad);
  }
  ref_yaw_rad_ = yaw;
  ref_t_ns_ = s.t_ns;
  ref_from_rv_ = false;
  have_heading_ = true;
}

void Pdr::feed(const RotationVectorSample& s) {
  const SampleCheck c = check_sample(s.t_ns, s.quat_xyzw.allFinite(), last_rv_check_ns_, have_rv_,
                                     opt_.heading.turn.gap_reset_s, counters_.rotation_vector);
  if (c == SampleCheck::kNonFinite || c == SampleCheck::kDuplicate || c == SampleCheck::kBackwards) return;
  last_rv_check_ns_ = s.t_ns;
  latest_ns_ = std::max(latest_ns_, s.t_ns);
  const auto h = rotation_vector_heading_rad(s.quat_xyzw, forward_axis(opt_.heading.mount),
                                             opt_.heading.min_horizontal);
  have_rv_ = true;
  if (!h) return;  // forward axis near vertical: keep propagating with the gyro
  last_rv_ns_ = s.t_ns;
  ref_heading_mag_rad_ = *h;
  ref_yaw_rad_ = tracker_.yaw_rad();
  ref_sigma_rad_ = (std::isfinite(s.heading_accuracy_rad) && s.heading_accuracy_rad > 0.0)
                       ? s.heading_accuracy_rad
                       : opt_.heading.rv_sigma_rad;
  ref_t_ns_ = s.t_ns;
  ref_from_rv_ = true;
  have_heading_ = true;
}

void Pdr::feed(const StepDetectorSample& s) {
  const SampleCheck c = check_sample(s.t_ns, true, sd_last_ns_, have_sd_last_, 1e9, counters_.step_detector);
  if (c == SampleCheck::kDuplicate || c == SampleCheck::kBackwards) return;
  have_sd_last_ = true;
  sd_last_ns_ = s.t_ns;
  latest_ns_ = std::max(latest_ns_, s.t_ns);
  android_step_times_.push_back(s.t_ns);
  have_android_ = true;
  last_android_ns_ = s.t_ns;
  if (opt_.source == StepSource::kAndroid || opt_.source == StepSource::kAuto) {
    emit_step(hold(s.t_ns, kNaN));
  }
  trim_consistency(s.t_ns);
}

bool Pdr::android_active(TimeNs t_ns) const {
  return have_android_ && ns_to_s(t_ns - last_android_ns_) <= opt_.android_timeout_s;
}

double Pdr::heading_rad() const {
  const double yaw = tracker_.yaw_rad();
  if (!have_heading_) return wrap_two_pi(opt_.heading.initial_heading_rad - yaw);
  return wrap_two_pi(ref_heading_mag_rad_ - (yaw - ref_yaw_rad_) + declination_rad_);
}

double Pdr::heading_sigma_rad() const {
  const TimeNs since = have_heading_ ? latest_ns_ - ref_t_ns_ : latest_ns_;
  const double base = have_heading_ ? ref_sigma_rad_ : opt_.heading.initial_sigma_rad;
  return std::min(kPi, base + opt_.heading.gyro_drift_radps * std::max(0.0, ns_to_s(since)));
}

void Pdr::emit_step(const HeldStep& h) {
  PdrStep st;
  st.t_ns = h.candidate.t_ns;
  st.length_m = opt_.length.length_m(h.candidate.swing_mps2);
  st.length_sigma_m = opt_.length.sigma_m(st.length_m);
  st.heading_rad = h.heading_rad;
  st.heading_sigma_rad = h.heading_sigma_rad;
  steps_.push_back(st);
  steps_magnetic_.push_back(h.magnetic ? 1 : 0);
  ++step_count_;
}

void Pdr::trim_consistency(TimeNs t_ns) {
  const TimeNs horizon = t_ns - s_to_ns(opt_.consistency_window_s);
  while (!accel_step_times_.empty() && accel_step_times_.front() < horizon) accel_step_times_.pop_front();
  while (!android_step_times_.empty() && android_step_times_.front() < horizon) android_step_times_.pop_front();
}

StepConsistency Pdr::consistency() const {
  StepConsistency c;
  c.accel_steps = static_cast<std::int64_t>(accel_step_times_.size());
  c.android_steps = static_cast<std::int64_t>(android_step_times_.size());
  const double a = static_cast<double>(c.accel_steps), b = static_cast<double>(c.android_steps);
  const double mx = std::max(a, b);
  c.relative_difference = mx > 0.0 ? std::abs(a - b) / mx : 0.0;
  constexpr double kMinStepsToJudge = 10.0;
  c.consistent = mx < kMinStepsToJudge || c.relative_difference <= opt_.consistency_tolerance;
  return c;
}

std::vector<PdrStep> Pdr::take_steps() {
  std::vector<PdrStep> out;
  out.swap(steps_);
  for (std::size_t i = 0; i < out.size() && i < steps_magnetic_.size(); ++i) {
    if (steps_magnetic_[i]) out[i].heading_rad = wrap_two_pi(out[i].heading_rad + declination_rad_);
  }
  steps_magnetic_.clear();
  return out;
}

std::vector<PdrTurn> Pdr::take_turns() { return tracker_.take_turns(); }

PdrCounters Pdr::counters() const {
  PdrCounters c = counters_;
  c.accel = detector_.counters();
  c.gyro = tracker_.gyro_counters();
  c.steps_discarded_by_bout_gate = gate_.discarded();
  return c;
}

}  // namespace pdnav::pdr
