// The PDR engine: step detector + bout gate, step length, heading (rotation vector / compass /
// gyro) and APT turn reports.
#include "pdnav/pdr/pdr.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "pdnav/geo/wmm.h"

namespace pdnav::pdr {

namespace {
/// The forward channel's detector: the accelerometer's options without stride splitting (a
/// stride is an |a| notion).
StepDetectorOptions forward_options(StepDetectorOptions o) {
  o.stride_harmonic_ratio = 0.0;
  return o;
}
}  // namespace

Pdr::Pdr(const PdrOptions& options)
    : opt_(options),
      gyro_rest_(options.gyro_bias),
      detector_(options.detector),
      forward_detector_(forward_options(options.detector)),
      gate_(options.detector.bout_min_steps, options.detector.max_step_interval_s,
            options.detector.short_walk_min_steps),
      tracker_(options.heading.turn),
      classifier_(options.motion),
      placement_(options.placement),
      fusion_(options.fusion),
      qsf_(options.fusion),
      magcal_(options.magcal),
      fusion_reference_(placement_.reference_phone()) {  // readings before the first bout use it
  tracker_.set_yaw_axis(reference_axis());
}

void Pdr::set_location(const geo::Geodetic& where, std::int64_t utc_ms) {
  const geo::Declination d = geo::declination_at(where, utc_ms);
  if (!std::isfinite(d.declination_rad)) return;
  declination_ = d;
  declination_rad_ = d.declination_rad;
  has_location_ = true;
  // expected field for the magnitude/dip tests (WMM2025, date clamped to its validity)
  const geo::WmmModel& model = geo::WmmModel::wmm2025();
  const double year = utc_ms == kMissingInt ? model.epoch_year
                                            : std::clamp(geo::decimal_year_from_unix_ms(utc_ms), model.epoch_year,
                                                         model.epoch_year + 5.0);
  const geo::MagneticField f = geo::wmm_field(model, where, year);
  fusion_.set_reference_field(f.f_nt * 1e-3, f.inclination_rad);
}

Eigen::Vector3d Pdr::reference_axis() const {
  if (opt_.heading.mount != Mount::kAuto) return forward_axis(opt_.heading.mount);
  if (!have_accel_ && have_rv_up_) return rv_reference_axis();  // no accelerometer: the RV's gravity
  return placement_.reference_phone();
}

Eigen::Vector3d Pdr::rv_reference_axis() const {
  // the placement estimator's priors (placement.h) from the rotation vector's gravity: screen
  // up/down = held flat, top ahead (+Y); otherwise the more horizontal of +Y and -Z (upright:
  // chest, shirt pocket, at the ear: camera ahead)
  const Eigen::Vector3d& u = rv_up_phone_;
  if (std::abs(u.z()) >= std::abs(u.x()) && std::abs(u.z()) >= std::abs(u.y())) return Eigen::Vector3d::UnitY();
  return std::abs(u.y()) > std::abs(u.z()) ? Eigen::Vector3d(0, 0, -1) : Eigen::Vector3d::UnitY();
}

std::string PdrSensorSet::name() const {
  std::string out;
  const auto add = [&out](std::int64_t n, const char* what) {
    if (n > 0) out += (out.empty() ? "" : "+") + std::string(what);
  };
  add(accel, "accel");
  add(uncal_accel, "uncal accel");
  add(gyro, "gyro");
  add(uncal_gyro, "uncal gyro");
  add(mag, "mag");
  add(uncal_mag, "uncal mag");
  add(rotation_vector, "rv");
  add(step_detector, "steps");
  return out.empty() ? "none" : out;
}

std::string PdrSensorSet::heading_reference() const {
  if (rotation_vector > 0) return "rotation vector";
  if ((mag > 0 || uncal_mag > 0) && (accel > 0 || uncal_accel > 0)) return "magnetometer";
  if (gyro > 0 || uncal_gyro > 0) return "none (gyro-relative from the initial heading)";
  return "none";
}

void Pdr::sync_placement() {
  if (placement_.revision() == placement_revision_) return;
  placement_revision_ = placement_.revision();
  // A new placement bout: the offset refers to the reference axis, so it restarts when the axis
  // changed (auto only). About the same axis it is kept: a handling span in between already
  // restarted it (track_handling), and a re-grip does not move the gyro frame.
  if (opt_.heading.mount == Mount::kAuto && placement_.reference_phone() != fusion_reference_) {
    fusion_.reset();
    qsf_.reset();  // the offset refers to the reference axis
  }
  fusion_reference_ = placement_.reference_phone();
  tracker_.set_yaw_axis(reference_axis());
}

const char* to_string(HeadingSource s) {
  switch (s) {
    case HeadingSource::kGyro: return "gyro";
    case HeadingSource::kCompass: return "compass";
    case HeadingSource::kRotationVector: return "rotation-vector";
    case HeadingSource::kInitial: break;
  }
  return "initial";
}

HeadingSource Pdr::heading_source(TimeNs t_ns) const {
  if (!fusion_.valid() || abs_weight_ns_ < 0) return HeadingSource::kInitial;
  // without a live gyroscope the heading follows the absolute stream whatever its weight
  // (HeadingFusionOptions::no_gyro_tau_s): that stream is the source, never "gyro"
  if (!gyro_live(t_ns)) return abs_kind_;
  // the mean weight decays toward 0 while no reading arrives: the gyro alone carries it then
  const double age_s = std::max(0.0, ns_to_s(t_ns - abs_weight_ns_));
  const double w = abs_weight_mean_ * std::exp(-age_s / opt_.source_tau_s);
  return w >= opt_.trusted_source_weight ? abs_kind_ : HeadingSource::kGyro;
}

void Pdr::absolute_heading(TimeNs t_ns, double heading_mag_rad, double weight, HeadingSource kind,
                           double deflection_sigma_rad) {
  if (handling_reset_) return;  // handled: no offset is learned (track_handling)
  // decayed mean of the readings' weights (source report only)
  if (kind != abs_kind_ || abs_weight_ns_ < 0) {
    abs_kind_ = kind;
    abs_weight_mean_ = weight;
  } else {
    const double a = std::exp(-std::max(0.0, ns_to_s(t_ns - abs_weight_ns_)) / opt_.source_tau_s);
    abs_weight_mean_ = a * abs_weight_mean_ + (1.0 - a) * weight;
  }
  abs_weight_ns_ = t_ns;
  fusion_.add(t_ns, heading_mag_rad, tracker_.axis_yaw_rad(), weight, gyro_live(t_ns) && tracker_.has_gravity(),
              deflection_sigma_rad);
  have_heading_ = true;
  ref_t_ns_ = t_ns;
}

void Pdr::track_handling() {
  // While the phone is handled (waved, turned over) the gyro yaw is integrated about a gravity
  // that is not known: the offset learned then would be wrong afterwards. It restarts when the
  // handling begins and learns again from the first absolute reading after it.
  const bool handled = opt_.gate_handling && classifier_.state() == MotionState::kHandling;
  if (handled && !handling_reset_) fusion_.reset(), qsf_.reset();
  handling_reset_ = handled;
}

namespace {
/// The platform's bias estimate of an uncalibrated reading, 0 where it is not given (NaN: a
/// logger that exports values[0..2] only, e.g. Sensor Logger's *Uncalibrated.csv): such a
/// reading is used raw, and the hard-iron calibration (mag_calibration.h) and the gyro-aided
/// pairs' drift estimate take the bias out as they would from any raw stream.
Eigen::Vector3d stated_bias(const Eigen::Vector3d& b) {
  return Eigen::Vector3d(std::isfinite(b.x()) ? b.x() : 0.0, std::isfinite(b.y()) ? b.y() : 0.0,
                         std::isfinite(b.z()) ? b.z() : 0.0);
}
}  // namespace

void Pdr::feed(const UncalAccelSample& s) {
  gyro_rest_.feed_accel(s.t_ns, s.acc_mps2);
  feed_uncal(AccelSample{s.t_ns, s.utc_ms, s.acc_mps2 - stated_bias(s.bias_mps2)}, sensors_.uncal_accel,
             sensors_.accel, last_cal_accel_ns_, first_uncal_accel_ns_);
}

void Pdr::feed(const UncalGyroSample& s) {
  Eigen::Vector3d drift = stated_bias(s.drift_radps);
  bool drift_known = true;
  if (uncal_allowed(s.t_ns, last_cal_gyro_ns_, first_uncal_gyro_ns_) && s.rate_radps.allFinite()) {
    if (!s.drift_radps.allFinite()) {
      // the logger did not export the platform's drift: ours, learned while the phone lies still
      gyro_rest_used_ = true;
      gyro_rest_.feed_gyro(s.t_ns, s.rate_radps);
      drift = gyro_rest_.bias_radps();
      drift_known = gyro_rest_.known();
    }
    if (drift_known) {
      const bool moved = magcal_drift_set_ && (drift - magcal_drift_radps_).norm() > opt_.magcal.prior_gyro_bias_radps;
      if (moved) magcal_.restart_pairs();
      if (moved || !magcal_drift_set_) magcal_drift_radps_ = drift, magcal_drift_set_ = true;
    }
  }
  // a raw rate integrates its drift (degrees per second) into the hard-iron fit's attitude, which
  // its gyro-bias state (a residual of tenths of a degree per second) cannot absorb: until the
  // drift is known the rate gives the fit no attitude
  feed_uncal(GyroSample{s.t_ns, s.utc_ms, s.rate_radps - drift}, sensors_.uncal_gyro, sensors_.gyro,
             last_cal_gyro_ns_, first_uncal_gyro_ns_,
             [this, drift_known](const GyroSample& g) { feed_gyro(g, drift_known); });
}

void Pdr::feed(const UncalMagSample& s) {
  feed_uncal(MagSample{s.t_ns, s.utc_ms, s.field_ut - stated_bias(s.bias_ut)}, sensors_.uncal_mag, sensors_.mag,
             last_cal_mag_ns_, first_uncal_mag_ns_);
}

void Pdr::feed(const AccelSample& s) {
  ++sensors_.accel;
  gyro_rest_.feed_accel(s.t_ns, s.acc_mps2);
  // the first accelerometer sample after rotation-vector headings about the RV's own axis: the
  // placement's axis takes over, the offset learned about the other one must not mix in
  if (!have_accel_ && have_rv_up_ && opt_.heading.mount == Mount::kAuto &&
      rv_reference_axis() != placement_.reference_phone()) {
    fusion_.reset();
    qsf_.reset();
  }
  have_accel_ = true;
  if (first_accel_ns_ < 0) first_accel_ns_ = s.t_ns;
  last_accel_ns_ = std::max(last_accel_ns_, s.t_ns);
  last_cal_accel_ns_ = s.t_ns;
  latest_ns_ = std::max(latest_ns_, s.t_ns);  // "now" for the steps the waits below release
  tracker_.feed(s);
  classifier_.feed(s);
  track_handling();
  const bool handling = opt_.gate_handling && classifier_.state() == MotionState::kHandling;
  const bool riding = opt_.gate_vehicle && classifier_.in_vehicle();
  if (handling || riding) placement_.end_bout();  // the phone is being moved: re-estimate afterwards
  else placement_.feed(s, gate_.in_bout() || gate_.pending() > 0);  // first steps teach it too
  sync_placement();
  flush_undecided(s.t_ns, false);
  settle_handling_wait(s.t_ns, false);
  settle_vehicle_wait(s.t_ns, false);
  // two steps between pauses count as a walk only while the handling gate can refuse jolts
  const bool gyro_gate = opt_.gate_handling && gyro_live(s.t_ns);
  gate_.set_short_walk_min_steps(gyro_gate ? opt_.detector.short_walk_min_steps_gyro : opt_.detector.short_walk_min_steps);
  gate_.set_min_steps(gyro_gate && opt_.detector.bout_min_steps_gyro > 0 ? opt_.detector.bout_min_steps_gyro
                                                                         : opt_.detector.bout_min_steps);
  detector_.set_running(opt_.gate_handling && classifier_.running());
  auto candidates = detector_.feed(s);
  forward_candidates(s, candidates);
  for (const auto& c : candidates) placement_.set_step_interval(c.interval_s);  // the step band's cadence
  if (detector_.counters().gaps != gaps_seen_) {  // a gap resets the detector and the bout
    gaps_seen_ = detector_.counters().gaps;
    release(gate_.end_bout(), s.t_ns);
  }
  latest_ns_ = std::max(latest_ns_, s.t_ns);
  release(gate_.expire(s.t_ns), s.t_ns);
  expire_held(hangover_, s.t_ns);
  expire_held(android_hangover_, s.t_ns);
  for (const auto& c : candidates) {
    if (opt_.gate_handling && (handling || classifier_.handling_at(c.t_ns))) {
      // In the hang-over the step waits for the walk after it; otherwise a waved/handled
      // phone: no step, and the bout must start again after it.
      if (in_handling_hangover(c.t_ns)) {
        hangover_.push_back(hold(c));
        continue;
      }
      drop_held(hangover_);
      ++counters_.steps_discarded_by_motion;
      (void)gate_.end_bout();
      continue;
    }
    HeldStep h = hold(c);
    for (HeldStep& held : settle_held(hangover_, h, true)) release(gate_.push(held.candidate.t_ns, std::move(held)), s.t_ns);
    last_swing_mps2_ = c.swing_mps2;
    last_swing_ns_ = c.t_ns;
    release(gate_.push(c.t_ns, std::move(h)), s.t_ns);
  }
  trim_consistency(s.t_ns);
}

void Pdr::forward_candidates(const AccelSample& s, std::vector<StepCandidate>& candidates) {
  // One step is one cycle of |a| and one of the forward acceleration, a fraction of a step
  // apart: across a change of channel a candidate within forward_same_step of the other
  // channel's latest, in units of the forward channel's step interval, is that same step.
  const double same = opt_.forward_same_step;
  const double period_s = fwd_interval_s_ > 0.0 ? fwd_interval_s_ : opt_.detector.min_step_interval_s / same;
  const TimeNs same_ns = s_to_ns(same * period_s);
  std::vector<StepCandidate> kept;
  for (const auto& c : candidates) {
    if (last_forward_used_ns_ >= 0 && c.t_ns - last_forward_used_ns_ < same_ns && c.t_ns > last_forward_used_ns_) continue;
    last_main_ns_ = c.t_ns;
    last_candidate_ns_ = std::max(last_candidate_ns_, c.t_ns);
    kept.push_back(c);
  }
  candidates.swap(kept);
  if (!opt_.forward_steps || !placement_.ready() || !placement_.direction_known()) return;
  // the levelled acceleration along the walking direction (phone axes), once the bout's direction
  // is decided: its sign sets when a cycle completes, and a phone held the other way round must
  // count the same steps
  const Eigen::Vector3d up = placement_.up_phone();
  Eigen::Vector3d fwd = placement_.forward_phone() - placement_.forward_phone().dot(up) * up;
  if (fwd.norm() < 0.2) return;  // the walking axis within 12 deg of the vertical: no forward channel (as forward_offset_rad)
  fwd.normalize();
  const Eigen::Vector3d a = s.acc_mps2 - s.acc_mps2.dot(up) * up;
  for (StepCandidate c : forward_detector_.feed_value(s.t_ns, a.dot(fwd))) {
    if (c.interval_s > 0.0 && c.interval_s <= opt_.detector.max_step_interval_s) fwd_interval_s_ = c.interval_s;
    if (detector_.gate_open()) continue;  // |a| walks: its own candidates count
    if (last_main_ns_ >= 0 && c.t_ns - last_main_ns_ < same_ns) continue;
    if (last_candidate_ns_ >= 0 && ns_to_s(c.t_ns - last_candidate_ns_) < opt_.detector.min_step_interval_s) continue;
    c.interval_s = last_candidate_ns_ >= 0 ? ns_to_s(c.t_ns - last_candidate_ns_) : 0.0;
    const double span_s = std::min(c.interval_s > 0.0 ? c.interval_s : opt_.detector.max_step_interval_s,
                                   opt_.detector.max_step_interval_s);
    c.swing_mps2 = detector_.swing_between(c.t_ns - s_to_ns(span_s), c.t_ns);  // |a|'s, for Weinberg
    if (!(c.swing_mps2 > 0.0)) c.swing_mps2 = kNaN;  // no |a| history: the length model's fallback
    last_candidate_ns_ = last_forward_used_ns_ = c.t_ns;
    candidates.push_back(c);
    ++counters_.forward_channel_candidates;
  }
}

void Pdr::drop_held(std::vector<HeldStep>& held) {
  counters_.steps_discarded_by_motion += static_cast<std::int64_t>(held.size());
  held.clear();
}

bool Pdr::in_handling_hangover(TimeNs t_ns) const {
  // after the last window whose rotation turned like handling, while state() still holds it
  const TimeNs last_features_ns = classifier_.handling_features_last_ns();
  return opt_.hangover_steps_wait && !classifier_.handling_features() && last_features_ns >= 0 &&
         t_ns > last_features_ns;
}

void Pdr::expire_held(std::vector<HeldStep>& held, TimeNs now_ns) {
  // handling again, or no step followed (the next one, due within max_step_interval_s, is
  // reported up to one more interval later): the held ones were not a walk
  if (!held.empty() && (classifier_.handling_features() ||
                        now_ns - held.back().candidate.t_ns > 2 * s_to_ns(opt_.detector.max_step_interval_s)))
    drop_held(held);
}

std::vector<Pdr::HeldStep> Pdr::settle_held(std::vector<HeldStep>& held, const HeldStep& next, bool own_candidate) {
  std::vector<HeldStep> out;
  if (held.empty()) return out;
  // the rhythm: every interval, from the first held step to the next step, within a step's
  const TimeNs lo = s_to_ns(opt_.detector.min_step_interval_s), hi = s_to_ns(opt_.detector.max_step_interval_s);
  for (std::size_t i = 0; i < held.size(); ++i) {
    const TimeNs dt = (i + 1 < held.size() ? held[i + 1].candidate.t_ns : next.candidate.t_ns) - held[i].candidate.t_ns;
    if (dt < lo || dt > hi) {
      drop_held(held);
      return out;
    }
  }
  for (const HeldStep& x : held) {
    // Taken while the heading offset restarted and the placement bout had ended (handling): the
    // walk's direction is the next step's (a second or less later), turned back by the gyro's
    // yaw about the vertical between the two steps (left positive).
    HeldStep h = next;
    if (own_candidate) h.candidate = x.candidate;  // its own swing and interval
    h.candidate.t_ns = x.candidate.t_ns;
    h.heading_rad = wrap_two_pi(next.heading_rad + (next.vertical_yaw_rad - x.vertical_yaw_rad));
    ++counters_.steps_from_handling_hangover;
    out.push_back(std::move(h));
  }
  held.clear();
  return out;
}

Pdr::HeldStep Pdr::hold(const StepCandidate& c) const {
  HeldStep h;
  h.candidate = c;
  h.vertical_yaw_rad = tracker_.yaw_rad();
  // The heading at the step's own time (issue 20.2): magnetic when referenced to the rotation
  // vector or compass (declination added when the step is taken), true when gyro-only from
  // the configured initial heading (heading_rad() adds the declination only in the first case).
  h.magnetic = fusion_.valid();
  h.heading_rad = wrap_two_pi(heading_rad() - (h.magnetic ? declination_rad_ : 0.0));
  // A step placed inside a longer interval (a stride's midpoint, a run's missed steps) is
  // behind the heading now by its share of the turn over that interval: the reference axis'
  // yaw at the interval's two ends (candidates both, at the same phase of the gait, so that an
  // arm's or a thigh's swing cancels) interpolated to the step's time (heading = - yaw + const).
  if (c.placed_from_ns > 0 && c.placed_from_ns < c.t_ns && c.t_ns < latest_ns_) {
    if (const std::optional<double> from = tracker_.axis_yaw_rad_at(c.placed_from_ns)) {
      const double share = static_cast<double>(latest_ns_ - c.t_ns) / static_cast<double>(latest_ns_ - c.placed_from_ns);
      h.heading_rad = wrap_two_pi(h.heading_rad + share * (tracker_.axis_yaw_rad() - *from));
    }
  }
  h.heading_sigma_rad = heading_sigma_rad();
  h.source = heading_source(c.t_ns);
  if (opt_.heading.mount == Mount::kAuto) {
    h.offset_rad = placement_.forward_offset_rad();
    // a step before the bout's gravity is known belongs to the bout that starts next
    h.placement_revision = placement_.revision() + (placement_.in_bout() ? 0 : 1);
    h.reference_phone = placement_.reference_phone();
  }
  return h;
}

Pdr::HeldStep Pdr::reprojected(HeldStep h) const {
  // same placement bout: the reference axis' heading stays, the walking offset is the latest
  if (opt_.heading.mount != Mount::kAuto || h.placement_revision != placement_.revision() ||
      !placement_.in_bout() || h.reference_phone != placement_.reference_phone())
    return h;
  const double now = placement_.forward_offset_rad();
  h.heading_rad = wrap_two_pi(h.heading_rad + now - h.offset_rad);
  h.offset_rad = now;
  return h;
}

void Pdr::deliver(HeldStep h, TimeNs now_ns) {
  const bool suspect = classifier_.handling_suspect() || classifier_.evidence_young();
  if (opt_.gate_handling && (suspect || !handling_wait_.empty())) {
    h.handling_suspect = suspect;
    handling_wait_.push_back(h);
    return;
  }
  deliver_after_handling(h, now_ns);
}

void Pdr::settle_handling_wait(TimeNs now_ns, bool force) {
  if (handling_wait_.empty()) return;
  // handling followed the suspicion: the waiting steps were its onset
  if (classifier_.state() == MotionState::kHandling) {
    counters_.steps_discarded_by_motion += static_cast<std::int64_t>(handling_wait_.size());
    handling_wait_.clear();
    return;
  }
  const TimeNs window_ns = s_to_ns(opt_.motion.window_s), max_ns = 3 * window_ns;
  while (!handling_wait_.empty()) {
    const HeldStep& h = handling_wait_.front();
    if (classifier_.handling_at(h.candidate.t_ns)) {
      ++counters_.steps_discarded_by_motion;
      handling_wait_.pop_front();
      continue;
    }
    const TimeNs age = now_ns - h.candidate.t_ns;
    // a full window of evidence, one window after a step taken under suspicion, and the
    // suspicion gone (at most three windows)
    const bool wait = classifier_.evidence_young() || (h.handling_suspect && age < window_ns) ||
                      (classifier_.handling_suspect() && age < max_ns);
    if (!force && wait) return;
    const HeldStep out = h;
    handling_wait_.pop_front();
    deliver_after_handling(out, now_ns);
  }
}

void Pdr::deliver_after_handling(HeldStep h, TimeNs now_ns) {
  if (vehicle_gated() || !vehicle_wait_.empty()) {  // in order behind the steps already waiting
    vehicle_wait_.push_back(h);
    settle_vehicle_wait(now_ns, false);
    return;
  }
  deliver_walking(h, now_ns);
}

bool Pdr::vehicle_decision_possible(TimeNs step_ns, TimeNs now_ns) const {
  // The score rises at most one second per second of evidence: a step waits only while the
  // vehicle could still be declared before it is vehicle_max_wait_s old.
  const MotionClassifierOptions& m = opt_.motion;
  const double left_s = opt_.vehicle_max_wait_s - ns_to_s(now_ns - step_ns);
  return classifier_.vehicle_suspect() && left_s > 0.0 && classifier_.vehicle_score_s() + left_s >= m.vehicle_enter_s;
}

void Pdr::settle_vehicle_wait(TimeNs now_ns, bool force) {
  if (vehicle_wait_.empty()) return;
  if (classifier_.in_vehicle()) {
    // a step older than the exit look-back will be inside the span whenever it ends
    const TimeNs keep_ns = now_ns - s_to_ns(opt_.motion.vehicle_exit_lookback_s);
    while (!vehicle_wait_.empty() && (force || vehicle_wait_.front().candidate.t_ns < keep_ns)) {
      ++counters_.steps_discarded_by_vehicle;
      vehicle_wait_.pop_front();
    }
    return;
  }
  // oldest first: a younger step can wait whenever an older one can
  while (!vehicle_wait_.empty()) {
    const HeldStep h = vehicle_wait_.front();
    if (!force && vehicle_decision_possible(h.candidate.t_ns, now_ns)) return;
    vehicle_wait_.pop_front();
    if (classifier_.vehicle_at(h.candidate.t_ns)) {
      ++counters_.steps_discarded_by_vehicle;
    } else if (h.android) {
      emit_step(h);
    } else {
      deliver_walking(h, now_ns);
    }
  }
}

bool Pdr::direction_pending(const HeldStep& h) const {
  return opt_.heading.mount == Mount::kAuto &&
         (h.placement_revision > placement_.revision() ||
          (h.placement_revision == placement_.revision() && !placement_.direction_known()));
}

void Pdr::deliver_walking(HeldStep h, TimeNs now_ns) {
  // A step of the current bout waits for the bout's walking direction, and so does a step taken
  // before its bout started (hold(): it belongs to the next bout): going out now it would take
  // the previous bout's direction, which the phone moved since (a handling ends a bout).
  if (opt_.placement.max_direction_wait_s > 0.0 && direction_pending(h)) {
    undecided_.push_back(h);
    return;
  }
  flush_undecided(now_ns, true);
  emit_walking(h);
}

void Pdr::emit_walking(const HeldStep& h) {
  // out before its own bout began (the wait ran out): it carries the previous bout's direction
  if (opt_.heading.mount == Mount::kAuto && h.placement_revision > placement_.revision())
    ++counters_.steps_before_their_bouts_direction;
  HeldStep out = reprojected(h);
  // out before its bout's walking direction is decided (the wait ran out): the direction is the
  // placement's prior or the previous bout's, and the step's heading sigma says so
  if (direction_pending(h)) {
    out.heading_sigma_rad = std::max(out.heading_sigma_rad, opt_.placement.undecided_direction_sigma_rad);
    ++counters_.steps_with_undecided_direction;
  }
  emit_step(out);
}

void Pdr::flush_undecided(TimeNs now_ns, bool force) {
  if (undecided_.empty()) return;
  // decided: the step's bout knows its direction, or it has ended (its last estimate is all there is)
  const std::int64_t rev = undecided_.front().placement_revision;
  const bool decided = rev < placement_.revision() || (rev == placement_.revision() && placement_.direction_known());
  const bool too_old = ns_to_s(now_ns - undecided_.front().candidate.t_ns) > opt_.placement.max_direction_wait_s;
  if (!force && !decided && !too_old) return;
  while (!undecided_.empty()) {
    emit_walking(undecided_.front());
    undecided_.pop_front();
  }
}

void Pdr::release(const std::vector<HeldStep>& steps, TimeNs now_ns) {
  for (const auto& h : steps) {
    accel_step_times_.push_back(h.candidate.t_ns);
    const bool use = opt_.source == StepSource::kAccelerometer ||
                     (opt_.source == StepSource::kAuto && !android_active(now_ns));
    if (use) deliver(h, now_ns);
  }
}

void Pdr::finish() {
  drop_held(hangover_);  // no walk followed
  drop_held(android_hangover_);
  release(gate_.finish(), latest_ns_);
  settle_handling_wait(latest_ns_, true);
  settle_vehicle_wait(latest_ns_, true);
  flush_undecided(latest_ns_, true);
}

void Pdr::feed(const GyroSample& s) { feed_gyro(s, true); }

void Pdr::feed_gyro(const GyroSample& s, bool attitude_for_magcal) {
  ++sensors_.gyro;
  last_cal_gyro_ns_ = s.t_ns;
  tracker_.feed(s);
  if (attitude_for_magcal) magcal_.add_gyro(s.t_ns, s.rate_radps);  // the gyro-aided hard-iron fit's attitude
  placement_.feed(s);  // the tilt filter levels the walking-direction correlation
  classifier_.feed(s);
  detector_.feed(s);   // the stride test reads the swing from the angular rate
  track_handling();
  if (s.rate_radps.allFinite() && s.t_ns >= last_gyro_ns_) last_gyro_ns_ = s.t_ns;
  latest_ns_ = std::max(latest_ns_, s.t_ns);
}

void Pdr::feed(const MagSample& s) {
  ++sensors_.mag;
  last_cal_mag_ns_ = s.t_ns;
  const SampleCheck c = check_sample(s.t_ns, s.field_ut.allFinite(), mag_last_ns_, have_mag_last_,
                                     opt_.heading.turn.gap_reset_s, counters_.mag);
  if (c == SampleCheck::kNonFinite || c == SampleCheck::kDuplicate || c == SampleCheck::kBackwards) return;
  have_mag_last_ = true;
  mag_last_ns_ = s.t_ns;
  last_field_ut_ = s.field_ut;  // the rotation vector's weight tests the field it used: raw
  latest_ns_ = std::max(latest_ns_, s.t_ns);
  magcal_.add(s.t_ns, s.field_ut);
  const Eigen::Vector3d field_ut = magcal_.corrected(s.field_ut);  // hard iron removed
  // without a gyroscope, the field's turning is the rate of the placement and the stride test
  if (const auto rate_radps = placement_.feed(MagSample{s.t_ns, s.utc_ms, field_ut})) {
    detector_.feed(GyroSample{s.t_ns, s.utc_ms, *rate_radps});
    classifier_.feed_field_rate(s.t_ns, *rate_radps);  // the handling test: waving counts no steps
    track_handling();
  }
  const bool rv_fresh = have_rv_ && ns_to_s(s.t_ns - last_rv_ns_) <= opt_.heading.rv_max_age_s;
  if (!rv_fresh && hard_iron_moved(compass_bias_ut_, opt_.magcal.restart_change_ut)) {
    // the compass offset was learned from readings with another bias: it restarts from these
    fusion_.reset();
    qsf_.reset();
  }
  if (!rv_fresh && hard_iron_moved(drift_bias_ut_, opt_.magcal.drift_restart_change_ut)) {
    // a new hard iron (its first activation included): the compass readings before it measured
    // another offset, and a line through both would take the calibration's step for gyro drift
    fusion_.restart_drift();
  }
  if (!tracker_.has_gravity()) return;
  const auto compass =
      compass_heading_rad(field_ut, tracker_.up_phone(), reference_axis(), opt_.heading.min_horizontal);
  if (compass && gyro_live(s.t_ns)) {
    qsf_.add(s.t_ns, *compass + tracker_.axis_yaw_rad(), field_ut.norm());
    ++counters_.mag_readings_qsf_tested;
    counters_.mag_readings_quasi_static += qsf_.quasi_static();
  } else {
    qsf_.reset();
  }  // no gyro frame to test the field's stationarity in
  if (rv_fresh) return;  // RV wins
  if (!compass) return;
  absolute_heading(s.t_ns, *compass,
                   qsf_weight() * mag_accuracy_weight_ * fusion_.field_weight(field_ut, tracker_.up_phone()),
                   HeadingSource::kCompass, fusion_.field_deflection_sigma_rad(field_ut, tracker_.up_phone()));
}

bool Pdr::hard_iron_moved(Eigen::Vector3d& since_ut, double change_ut) {
  if (!(change_ut > 0.0) || (magcal_.bias_ut() - since_ut).norm() < change_ut) return false;
  since_ut = magcal_.bias_ut();
  return true;
}

void Pdr::feed(const SensorAccuracySample& s) {
  constexpr int kTypeMagneticField = 2, kTypeMagneticFieldUncalibrated = 14;  // android.hardware.Sensor
  if (s.sensor_type == kTypeMagneticField || s.sensor_type == kTypeMagneticFieldUncalibrated)
    mag_accuracy_weight_ = fusion_.accuracy_weight(s.accuracy);
}

void Pdr::feed(const RotationVectorSample& s) {
  const SampleCheck c = check_sample(s.t_ns, s.quat_xyzw.allFinite(), last_rv_check_ns_, have_rv_,
                                     opt_.heading.turn.gap_reset_s, counters_.rotation_vector);
  if (c == SampleCheck::kNonFinite || c == SampleCheck::kDuplicate || c == SampleCheck::kBackwards) return;
  last_rv_check_ns_ = s.t_ns;
  latest_ns_ = std::max(latest_ns_, s.t_ns);
  ++sensors_.rotation_vector;
  if (!have_accel_ && s.quat_xyzw.norm() > 0.5) {  // gravity in phone axes = R^T e_z (R: phone -> ENU)
    const Eigen::Quaterniond q(s.quat_xyzw[3], s.quat_xyzw[0], s.quat_xyzw[1], s.quat_xyzw[2]);
    rv_up_phone_ = q.normalized().conjugate() * Eigen::Vector3d::UnitZ();
    have_rv_up_ = true;
  }
  const auto h = rotation_vector_heading_rad(s.quat_xyzw, reference_axis(), opt_.heading.min_horizontal);
  have_rv_ = true;
  if (!h) return;  // reference axis near vertical: keep propagating with the gyro
  last_rv_ns_ = s.t_ns;
  // The rotation vector is the phone's own gyro+magnetometer fusion: it is as disturbed as
  // the field it used, so it is weighted by the latest magnetometer reading's tests.
  const bool mag_fresh = have_mag_last_ && ns_to_s(s.t_ns - mag_last_ns_) <= opt_.heading.rv_max_age_s;
  const bool field_tested = mag_fresh && tracker_.has_gravity();
  double w = field_tested ? fusion_.field_weight(last_field_ut_, tracker_.up_phone()) : 1.0;
  w *= mag_accuracy_weight_;
  if (mag_fresh) w *= qsf_weight();  // the RV used this field: trusted only while it is quasi-static
  // the sensor's own heading accuracy (when it reports one): inverse-variance relative to one
  // nominal reading, never above it
  if (std::isfinite(s.heading_accuracy_rad) && s.heading_accuracy_rad > 0.0)
    w *= std::clamp(std::pow(opt_.fusion.base_sigma_rad / s.heading_accuracy_rad, 2), opt_.fusion.disturbed_weight, 1.0);
  absolute_heading(s.t_ns, *h, w, HeadingSource::kRotationVector,
                   field_tested ? fusion_.field_deflection_sigma_rad(last_field_ut_, tracker_.up_phone()) : 0.0);
}

void Pdr::feed(const StepDetectorSample& s) {
  const SampleCheck c = check_sample(s.t_ns, true, sd_last_ns_, have_sd_last_, 1e9, counters_.step_detector);
  if (c == SampleCheck::kDuplicate || c == SampleCheck::kBackwards) return;
  have_sd_last_ = true;
  sd_last_ns_ = s.t_ns;
  ++sensors_.step_detector;
  latest_ns_ = std::max(latest_ns_, s.t_ns);
  android_step_times_.push_back(s.t_ns);
  have_android_ = true;
  last_android_ns_ = s.t_ns;
  if (opt_.gate_handling && (classifier_.state() == MotionState::kHandling || classifier_.handling_at(s.t_ns))) {
    // in the hang-over the event waits for the walk after it, as the accelerometer's steps do
    if (in_handling_hangover(s.t_ns)) {
      HeldStep held;  // its time and the gyro's vertical yaw then are all settle_held needs
      held.candidate.t_ns = s.t_ns;
      held.vertical_yaw_rad = tracker_.yaw_rad();
      android_hangover_.push_back(held);
    } else {
      drop_held(android_hangover_);
      ++counters_.steps_discarded_by_motion;  // the phone's own detector counts waving too
    }
    trim_consistency(s.t_ns);
    return;
  }
  if (opt_.gate_vehicle && classifier_.in_vehicle()) {
    ++counters_.steps_discarded_by_vehicle;  // a phone's step detector fires on bumps too
    return;
  }
  if (opt_.source == StepSource::kAndroid || opt_.source == StepSource::kAuto) {
    // the swing of the accelerometer's own latest step (within 2 s), else the model's fallback
    const bool fresh = last_swing_ns_ >= 0 && std::abs(ns_to_s(s.t_ns - last_swing_ns_)) <= 2.0;
    StepCandidate event;
    event.t_ns = s.t_ns;
    event.swing_mps2 = fresh ? last_swing_mps2_ : kNaN;
    event.interval_s = 0.0;  // unknown: the length model's cadence fallback
    HeldStep h = hold(event);
    h.android = true;
    const auto emit_android = [&](const HeldStep& x) {
      if (vehicle_gated() || !vehicle_wait_.empty()) {
        vehicle_wait_.push_back(x);
        settle_vehicle_wait(s.t_ns, false);
      } else {
        emit_step(x);
      }
    };
    // the hang-over's events count when this one follows in their rhythm, as the accelerometer's
    for (const HeldStep& held : settle_held(android_hangover_, h, false)) emit_android(held);
    emit_android(h);
  }
  trim_consistency(s.t_ns);
}

bool Pdr::android_active(TimeNs t_ns) const {
  return have_android_ && ns_to_s(t_ns - last_android_ns_) <= opt_.android_timeout_s;
}

double Pdr::heading_rad() const {
  const double yaw = tracker_.axis_yaw_rad();
  const double offset = opt_.heading.mount == Mount::kAuto ? placement_.forward_offset_rad() : 0.0;
  if (!fusion_.valid()) return wrap_two_pi(opt_.heading.initial_heading_rad - yaw + offset);
  return wrap_two_pi(fusion_.heading_mag_rad(yaw, latest_ns_) + offset + declination_rad_);
}

bool Pdr::gyro_live(TimeNs t_ns) const {
  return last_gyro_ns_ >= 0 && ns_to_s(t_ns - last_gyro_ns_) <= opt_.heading.turn.gap_reset_s;
}

double Pdr::accel_rate_hz() const {
  // every sample through feed(AccelSample): calibrated, or bias-removed in place of it
  const std::int64_t fed = sensors_.accel + sensors_.uncal_accel;
  if (fed < 2 || first_accel_ns_ < 0 || last_accel_ns_ <= first_accel_ns_) return kNaN;
  return static_cast<double>(fed - 1) / ns_to_s(last_accel_ns_ - first_accel_ns_);
}

double Pdr::heading_sigma_rad() const {
  const TimeNs since = have_heading_ ? latest_ns_ - ref_t_ns_ : latest_ns_;
  const double base = fusion_.valid() ? fusion_.sigma_rad() : opt_.heading.initial_sigma_rad;
  return std::min(kPi, base + opt_.heading.gyro_drift_radps * std::max(0.0, ns_to_s(since)));
}

void Pdr::emit_step(const HeldStep& h) {
  PdrStep st;
  st.t_ns = h.candidate.t_ns;
  const double delay_s = ns_to_s(latest_ns_ - st.t_ns);
  if (delay_s > counters_.max_step_delay_s) {
    counters_.max_step_delay_s = delay_s;
    counters_.max_step_delay_at_ns = st.t_ns;
  }
  const double interval_s = h.candidate.interval_s;
  st.length_m = opt_.length.length_m(h.candidate.swing_mps2, interval_s > 0.0 ? 1.0 / interval_s : kNaN);
  st.length_sigma_m = opt_.length.sigma_m(st.length_m);
  st.heading_rad = h.heading_rad;
  st.heading_sigma_rad = h.heading_sigma_rad;
  distance_m_ += st.length_m;
  steps_.push_back(st);
  steps_magnetic_.push_back(h.magnetic ? 1 : 0);
  if (source_spans_.empty() || source_spans_.back().source != h.source)
    source_spans_.push_back({st.t_ns, st.t_ns, h.source, 0});
  source_spans_.back().t_end_ns = std::max(source_spans_.back().t_end_ns, st.t_ns);
  ++source_spans_.back().steps;
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
  c.steps_added_at_stride_midpoints = detector_.stride_steps_added();
  c.vehicle_max_score_s = classifier_.vehicle_max_score_s();
  c.vehicle_kinematic_max_mps2 = classifier_.kinematic_max_mps2();
  c.mag_readings_trusted = fusion_.accepted();
  c.mag_readings_disturbed = fusion_.disturbed();
  return c;
}

}  // namespace pdnav::pdr
