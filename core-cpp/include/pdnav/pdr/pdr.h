// The PDR engine face: raw inertial samples in, steps (time, length, true-north heading,
// sigmas) and turns out. Deterministic (no random component, so no seed).
#pragma once
#include <cmath>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "pdnav/geo/events.h"
#include "pdnav/geo/frames.h"
#include "pdnav/geo/samples.h"
#include "pdnav/geo/wmm.h"
#include "pdnav/pdr/heading.h"
#include "pdnav/pdr/heading_fusion.h"
#include "pdnav/pdr/gyro_bias.h"
#include "pdnav/pdr/mag_calibration.h"
#include "pdnav/pdr/motion_classifier.h"
#include "pdnav/pdr/placement.h"
#include "pdnav/pdr/step_detector.h"
#include "pdnav/pdr/step_length.h"

namespace pdnav::pdr {

/// Which step events drive the output.
enum class StepSource {
  kAccelerometer,  // APT level-crossing detector (default)
  kAndroid,        // Android TYPE_STEP_DETECTOR events (as the terrain paper does)
  kAuto,           // Android events while they arrive (within android_timeout_s), else accelerometer
};

/// Where a step's heading came from (issue 27, reported per segment in replay's summary.json):
/// the heading filter (HeadingFusion) is always gyro-propagated; this names the absolute
/// reference that set its offset around the step. kRotationVector / kCompass: readings of that
/// stream passed the field tests (recent mean weight >= PdrOptions::trusted_source_weight);
/// kGyro: the field was disturbed around the step, the gyro carried the heading from earlier
/// readings; kInitial: no absolute reading yet (the configured initial heading, gyro-propagated).
enum class HeadingSource { kInitial, kGyro, kCompass, kRotationVector };
const char* to_string(HeadingSource s);

/// Consecutive emitted steps with one heading source.
struct HeadingSourceSpan {
  TimeNs t_start_ns = 0;
  TimeNs t_end_ns = 0;
  HeadingSource source = HeadingSource::kInitial;
  std::int64_t steps = 0;
};

struct PdrOptions {
  StepDetectorOptions detector;  // APT Sec. V-A (+ gates)
  StepLengthModel length;        // APT Sec. V-A: l = c1 * height
  HeadingOptions heading;        // mount; APT Sec. V-B gyro re-orientation; fallbacks
  HeadingFusionOptions fusion;   // gyro-dominant heading, magnetic readings gated against WMM
  MagCalibrationOptions magcal;  // online hard-iron sphere fit (Vasconcelos et al. 2011)
  GyroBiasOptions gyro_bias;     // an uncalibrated gyro without its drift: bias at rest (ZARU)
  PlacementOptions placement;    // placement + walking direction when heading.mount == kAuto
  MotionClassifierOptions motion;  // walking / standing / handling
  bool gate_handling = true;     // no steps while the phone is handled or waved
  /// Gentle steps from the forward acceleration (docs/pdr.md "Forward channel"): while |a| is
  /// below the walking gate, the same level-crossing detector runs on the levelled acceleration
  /// along the walking direction, whose oscillation marks each step (Zijlstra & Hof, Gait &
  /// Posture 18(2) 2003: initial contact from the anterior-posterior trunk acceleration).
  bool forward_steps = true;
  /// A candidate of one channel within this fraction of the forward channel's step interval
  /// after the other channel's latest is the same step (the heel strike's |a| peak and the
  /// forward cycle are less than a step apart): counted once.
  double forward_same_step = 0.75;
  /// A step taken in handling's hang-over (MotionClassifierOptions::hold_s after the rotation
  /// stopped looking like handling) waits for the walk after it: it counts when the next step
  /// outside handling follows in the walk's rhythm (every interval within the detector's
  /// min_step_interval_s .. max_step_interval_s), and is refused if handling resumes or no
  /// step follows (an Android step event likewise waits for the next event). A walker who
  /// starts walking as the compass-calibration wave ends used to lose the first 2-3 steps
  /// (docs/pdr.md stage 1). false = every hang-over step refused.
  bool hangover_steps_wait = true;
  bool gate_vehicle = true;      // no steps while riding (motion.vehicle must be on); steps
                                 // wait while vehicle evidence accumulates (docs/pdr.md)
  /// Bounded latency of that wait (issue 27): a step waits for the vehicle decision only while
  /// the decision could still come before the step is this old (the score rises at most 1 s
  /// per s, so with score S a step of age a waits while S + (max - a) >= vehicle_enter_s).
  /// One vehicle window (the evidence's own span, MotionClassifierOptions::vehicle_window_s);
  /// before, a step waited while the score was > 0: up to 18.5 s on the ETH walk.
  double vehicle_max_wait_s = 4.0;
  StepSource source = StepSource::kAccelerometer;
  double android_timeout_s = 3.0;
  /// Consistency check: the two step sources agree when their counts differ by at most this
  /// fraction over the window below.
  double consistency_tolerance = 0.10;
  double consistency_window_s = 30.0;
  // Heading source report: mean weight of the absolute readings over the last source_tau_s
  // (HeadingFusionOptions::decorrelation_s) at or above this = that stream is the source, below =
  // the gyro (the weight is 1 for a reading passing the field tests, disturbed_weight otherwise).
  double source_tau_s = 5.0;
  double trusted_source_weight = 0.5;
  /// An uncalibrated stream stands in for its calibrated twin once it has run this long without
  /// it (GnssLogger logs carry both: the calibrated one is used, never a mix; some loggers
  /// write only the uncalibrated ones).
  double uncal_fallback_s = 1.0;
};

/// Sample counters by sensor and reason (skipped or reset).
struct PdrCounters {
  SampleCounters accel;
  SampleCounters gyro;
  SampleCounters mag;
  SampleCounters rotation_vector;
  SampleCounters step_detector;
  std::int64_t steps_discarded_by_bout_gate = 0;
  std::int64_t steps_discarded_by_motion = 0;  // candidates while the phone was handled/waved
  std::int64_t steps_discarded_by_vehicle = 0;  // steps inside a vehicle span (car, bus, train)
  /// The vehicle evidence at its highest outside a vehicle span: the leaky score (s, entered at
  /// MotionClassifierOptions::vehicle_enter_s) and the mean horizontal acceleration while the
  /// phone turned slowly (m/s^2, kinematic_min_mps2; 0 without a gyroscope).
  double vehicle_max_score_s = 0.0;
  double vehicle_kinematic_max_mps2 = 0.0;
  std::int64_t steps_added_at_stride_midpoints = 0;  // swinging hand / running strides split (stage 4)
  std::int64_t forward_channel_candidates = 0;  // candidates of the forward acceleration (forward_steps)
  std::int64_t steps_from_handling_hangover = 0;  // hang-over candidates and Android events the walk after them kept (hangover_steps_wait)
  /// Steps emitted before the placement bout they belong to had begun (its walking direction
  /// was waited for max_direction_wait_s in vain): they carry the previous bout's direction.
  std::int64_t steps_before_their_bouts_direction = 0;
  // steps out before their bout's walking direction was decided (the wait ran out): heading sigma
  // at least PlacementOptions::undecided_direction_sigma_rad
  std::int64_t steps_with_undecided_direction = 0;
  std::int64_t mag_readings_trusted = 0;       // absolute headings that passed the WMM tests
  std::int64_t mag_readings_disturbed = 0;     // ... and that failed them (down-weighted)
  std::int64_t mag_readings_qsf_tested = 0;    // magnetometer readings tested for a quasi-static field
  std::int64_t mag_readings_quasi_static = 0;  // ... and found quasi-static (full weight)
  /// Latency of the emitted steps: the longest time from a step to its emission (newest
  /// sample time then minus the step's own time; the bout gate, handling, vehicle and
  /// walking-direction waits all add to it) and the time of that step.
  double max_step_delay_s = 0.0;
  TimeNs max_step_delay_at_ns = 0;
  std::int64_t total_skipped() const {
    return accel.skipped() + gyro.skipped() + mag.skipped() + rotation_vector.skipped() + step_detector.skipped();
  }
};

/// The sensors the PDR has been fed so far (issue 27, "every sensor set"): each stream counts
/// when it was used. An uncalibrated stream (UncalAccel/UncalGyro/UncalMag, the stated bias
/// removed; a bias the logger did not export is taken as 0) is used only while its calibrated
/// twin is absent (PdrOptions::uncal_fallback_s).
struct PdrSensorSet {
  std::int64_t accel = 0, gyro = 0, mag = 0, rotation_vector = 0, step_detector = 0;
  std::int64_t uncal_accel = 0, uncal_gyro = 0, uncal_mag = 0;  // used in place of the calibrated ones
  /// e.g. "accel+gyro+mag+rv", "rv+steps", "uncal accel+uncal gyro+uncal mag", "accel".
  std::string name() const;
  /// The absolute heading it can have: "rotation vector", "magnetometer", "none (gyro-relative
  /// from the initial heading)" or "none".
  std::string heading_reference() const;
};

/// Accelerometer detector vs Android step-detector events over the last consistency window.
struct StepConsistency {
  std::int64_t accel_steps = 0;    // accelerometer steps in the window
  std::int64_t android_steps = 0;  // Android events in the window
  double relative_difference = 0.0;  // |a - b| / max(a, b), 0 when both are 0
  bool consistent = true;          // relative_difference <= tolerance (or too few steps to tell)
};

class Pdr {
 public:
  explicit Pdr(const PdrOptions& options = {});

  void feed(const AccelSample& s);
  void feed(const GyroSample& s);
  void feed(const MagSample& s);
  void feed(const RotationVectorSample& s);
  void feed(const StepDetectorSample& s);
  /// Uncalibrated streams (bias / drift removed): used only without the calibrated twin.
  void feed(const UncalAccelSample& s);
  void feed(const UncalGyroSample& s);
  void feed(const UncalMagSample& s);
  /// Android sensor accuracy events: the magnetometer's (TYPE_MAGNETIC_FIELD 2 and its
  /// uncalibrated form 14) scales the weight of compass and rotation-vector headings
  /// (HeadingFusionOptions::accuracy_weight); other sensors' events are ignored.
  void feed(const SensorAccuracySample& s);
  /// Position and UTC time (Unix ms) for the WMM declination; may be called again at any time.
  void set_location(const geo::Geodetic& where, std::int64_t utc_ms);
  /// Replace the step-length model (e.g. the user's height read from a recorded session);
  /// applies to the steps detected from now on.
  void set_length_model(const StepLengthModel& model) {
    const double keep = opt_.length.scale;
    opt_.length = model;
    opt_.length.scale = keep;
  }
  /// The walker's step-length scale (multiplies whatever model is in use; 1 = as published).
  /// Fusion learns it online from GNSS or the map; applies from the next step. Non-finite or
  /// non-positive values are ignored (returns false).
  bool set_length_scale(double scale) {
    if (!(std::isfinite(scale) && scale > 0.0)) return false;
    opt_.length.scale = scale;
    return true;
  }
  double length_scale() const { return opt_.length.scale; }

  /// End of the input: a walk too short for the bout gate is released if it qualifies
  /// (StepDetectorOptions::short_walk_min_steps). Take the steps afterwards.
  void finish();
  /// Steps since the last call (time, length, TRUE-north heading, sigmas). Each step carries
  /// its own time and the heading at that time; the declination known at this call is applied
  /// to every step whose heading came from a magnetic reference (one frame for all steps).
  std::vector<PdrStep> take_steps();
  /// Turns since the last call (APT Sec. V-B, positive = left).
  std::vector<PdrTurn> take_turns();
  /// Steps emitted so far (from the selected source).
  std::int64_t step_count() const { return step_count_; }
  /// Current true heading (clockwise from north, [0, 2pi)) and its 1-sigma. Before any rotation
  /// vector or compass reading it is the gyro-propagated options.heading.initial_heading_rad.
  double heading_rad() const;
  double heading_sigma_rad() const;
  double declination_rad() const { return declination_rad_; }
  /// The declination in use, its WMM model and any warning (date outside every model's span,
  /// no UTC time); `has_location()` is false while headings are still magnetic.
  const geo::Declination& declination() const { return declination_; }
  bool has_location() const { return has_location_; }
  PdrCounters counters() const;
  const PdrSensorSet& sensor_set() const { return sensors_; }
  /// The accelerometer's mean sample rate so far (Hz; NaN before two samples). The step detector
  /// is measured at 50-200 Hz: below kMinAccelRateHz it misses steps (docs/pdr.md "Sample rate").
  double accel_rate_hz() const;
  static constexpr double kMinAccelRateHz = 40.0;
  StepConsistency consistency() const;
  const PdrOptions& options() const { return opt_; }
  /// Placement bouts so far (time spans, placement, walking direction in phone axes); with a
  /// declared mount one bout per gravity-stable span, walking direction = the mount's axis.
  std::vector<PlacementBout> placements() const { return placement_.bouts(); }
  /// Vehicle spans found by the motion classifier (the latest 256; the open one included).
  std::vector<MotionSpan> vehicle_spans() const {
    return {classifier_.vehicle_spans().begin(), classifier_.vehicle_spans().end()};
  }
  /// Handling spans found by the motion classifier (the latest 256; the open one included).
  std::vector<MotionSpan> handling_spans() const {
    return {classifier_.handling_spans().begin(), classifier_.handling_spans().end()};
  }
  MotionState motion_state() const { return classifier_.state(); }
  /// Online hard-iron calibration of the magnetometer feeding the compass (bias in use, active).
  const MagCalibration& mag_calibration() const { return magcal_; }
  /// The bias of an uncalibrated gyro stream that came without the platform's drift estimate,
  /// learned while the phone lay still (gyro_bias.h); gyro_bias_at_rest_used() is false when no
  /// such stream came.
  const GyroBiasAtRest& gyro_bias_at_rest() const { return gyro_rest_; }
  bool gyro_bias_at_rest_used() const { return gyro_rest_used_; }
  /// The heading source of the emitted steps, as spans of consecutive steps.
  const std::vector<HeadingSourceSpan>& heading_sources() const { return source_spans_; }
  /// Sum of the emitted step lengths (m).
  double distance_m() const { return distance_m_; }

 private:
  /// A step candidate with the heading at its own time (before the bout gate releases it).
  struct HeldStep {
    StepCandidate candidate;
    double heading_rad = 0.0;  // magnetic if `magnetic`, else true
    double heading_sigma_rad = 0.0;
    bool magnetic = false;
    double offset_rad = 0.0;               // placement offset (reference axis -> walking) used
    std::int64_t placement_revision = -1;  // placement bout it was taken in (or the next one)
    Eigen::Vector3d reference_phone = Eigen::Vector3d::Zero();  // axis its heading refers to
    bool android = false;  // an Android step-detector event (emitted directly, no placement wait)
    bool handling_suspect = false;  // delivered while the rotation looked like handling starting
    HeadingSource source = HeadingSource::kInitial;
    double vertical_yaw_rad = 0.0;  // the gyro's integrated yaw about the vertical at the step
  };
  HeldStep hold(const StepCandidate& c) const;
  void release(const std::vector<HeldStep>& steps, TimeNs now_ns);
  /// Emits a released step, or holds it while its placement bout's walking direction is
  /// still the prior (first steps); the held ones are re-projected when it is decided.
  void deliver(HeldStep h, TimeNs now_ns);
  void deliver_walking(HeldStep h, TimeNs now_ns);
  /// The step's placement bout has not decided its walking direction yet (auto mount): it began
  /// after the step's (the step is ahead of its bout) or it is the current one, undecided.
  bool direction_pending(const HeldStep& h) const;
  /// Steps held while vehicle evidence accumulates: dropped inside a vehicle span, delivered
  /// once the evidence is gone (or at the end of the input).
  void settle_vehicle_wait(TimeNs now_ns, bool force);
  /// The vehicle could still be declared before a step taken at step_ns is
  /// PdrOptions::vehicle_max_wait_s old (the score rises at most 1 s per s).
  bool vehicle_decision_possible(TimeNs step_ns, TimeNs now_ns) const;
  /// Steps held one classifier window while handling is suspected: dropped if a handling span
  /// covers them by then, else delivered.
  void settle_handling_wait(TimeNs now_ns, bool force);
  void deliver_after_handling(HeldStep h, TimeNs now_ns);
  bool vehicle_gated() const {
    return opt_.gate_vehicle && (classifier_.in_vehicle() || classifier_.vehicle_suspect());
  }
  void flush_undecided(TimeNs now_ns, bool force);
  HeldStep reprojected(HeldStep h) const;
  /// Emits a walking step with its bout's latest direction (reprojected), counting one that goes
  /// out before its bout began (PdrCounters::steps_before_their_bouts_direction).
  void emit_walking(const HeldStep& h);
  void emit_step(const HeldStep& h);
  bool android_active(TimeNs t_ns) const;
  void trim_consistency(TimeNs t_ns);
  Eigen::Vector3d reference_axis() const;
  void absolute_heading(TimeNs t_ns, double heading_mag_rad, double weight, HeadingSource kind,
                        double deflection_sigma_rad);
  /// A gyroscope sample arrived within the turn tracker's gap (heading.turn.gap_reset_s) of t_ns.
  bool gyro_live(TimeNs t_ns) const;
  HeadingSource heading_source(TimeNs t_ns) const;
  void sync_placement();
  /// Without an accelerometer (a log of the fused sensors only): the reference axis from the
  /// rotation vector's own gravity, the placement's prior (flat: +Y, upright: -Z).
  Eigen::Vector3d rv_reference_axis() const;
  PdrSensorSet sensors_;
  bool have_accel_ = false;
  bool have_rv_up_ = false;
  Eigen::Vector3d rv_up_phone_ = Eigen::Vector3d::UnitZ();
  TimeNs last_cal_accel_ns_ = -1, last_cal_gyro_ns_ = -1, last_cal_mag_ns_ = -1;
  TimeNs first_accel_ns_ = -1, last_accel_ns_ = -1;  // the accelerometer's rate (accel_rate_hz)
  TimeNs first_uncal_accel_ns_ = -1, first_uncal_gyro_ns_ = -1, first_uncal_mag_ns_ = -1;
  /// An uncalibrated sample is used once its stream has run uncal_fallback_s without its
  /// calibrated twin (never mixed with it: a log with both uses the calibrated one only).
  bool uncal_allowed(TimeNs t_ns, TimeNs last_calibrated_ns, TimeNs& first_uncal_ns) {
    if (first_uncal_ns < 0) first_uncal_ns = t_ns;
    const TimeNs since = last_calibrated_ns < 0 ? t_ns - first_uncal_ns : t_ns - last_calibrated_ns;
    return ns_to_s(since) > opt_.uncal_fallback_s;
  }
  /// An allowed uncalibrated sample, bias removed, goes through its calibrated twin's feed,
  /// counted once (as uncalibrated) and without counting as a calibrated reading.
  template <class Calibrated>
  void feed_uncal(const Calibrated& bias_removed, std::int64_t& uncal_count, std::int64_t& cal_count,
                  TimeNs& last_cal_ns, TimeNs& first_uncal_ns) {
    feed_uncal(bias_removed, uncal_count, cal_count, last_cal_ns, first_uncal_ns,
               [this](const Calibrated& c) { feed(c); });
  }
  /// ... through `feed_calibrated` (a feed with more to say, e.g. feed_gyro's attitude flag).
  template <class Calibrated, class Feed>
  void feed_uncal(const Calibrated& bias_removed, std::int64_t& uncal_count, std::int64_t& cal_count,
                  TimeNs& last_cal_ns, TimeNs& first_uncal_ns, Feed&& feed_calibrated) {
    if (!uncal_allowed(bias_removed.t_ns, last_cal_ns, first_uncal_ns)) return;
    ++uncal_count;
    --cal_count;
    const TimeNs keep = last_cal_ns;
    feed_calibrated(bias_removed);
    last_cal_ns = keep;
  }
  /// A gyroscope sample; attitude_for_magcal: its rate is the gyro-aided hard-iron fit's attitude
  /// (false for a raw rate whose drift is not known yet).
  void feed_gyro(const GyroSample& s, bool attitude_for_magcal);

  PdrOptions opt_;
  GyroBiasAtRest gyro_rest_;
  bool gyro_rest_used_ = false;
  // the hard-iron fit's gyro attitude (mag_calibration.h): a drift correction that moved by more
  // than the fit's gyro-bias prior since the pairs began restarts them
  bool magcal_drift_set_ = false;
  Eigen::Vector3d magcal_drift_radps_ = Eigen::Vector3d::Zero();
  StepDetector detector_;
  StepDetector forward_detector_;  // forward_steps: the forward acceleration channel
  TimeNs last_candidate_ns_ = -1;  // the latest step candidate of either channel
  TimeNs last_main_ns_ = -1;       // ... of the |a| channel
  TimeNs last_forward_used_ns_ = -1;  // ... of the forward channel, counted
  double fwd_interval_s_ = 0.0;    // the forward channel's latest step interval (its cadence)
  BoutGate<HeldStep> gate_;
  GyroTurnTracker tracker_;
  MotionClassifier classifier_;
  std::deque<HeldStep> vehicle_wait_;
  std::deque<HeldStep> handling_wait_;
  /// Steps of the handling hang-over waiting for the walk after it (hangover_steps_wait): the
  /// accelerometer's candidates, and Android step events (their time and vertical yaw only).
  std::vector<HeldStep> hangover_, android_hangover_;
  /// Held steps refused (counted as discarded by motion).
  void drop_held(std::vector<HeldStep>& held);
  /// The |a| candidates of this sample less those that are the forward channel's latest step
  /// again (forward_same_step), then (forward_steps) the forward channel's own while |a| is
  /// below its walking gate, appended.
  void forward_candidates(const AccelSample& s, std::vector<StepCandidate>& candidates);
  /// ... refused once handling resumes or no step followed by now_ns.
  void expire_held(std::vector<HeldStep>& held, TimeNs now_ns);
  /// The next step outside handling: the held steps count (returned, `held` emptied) if every
  /// interval from the first to it is within the detector's min / max step interval, each the
  /// next step at its own time with the heading turned back by the gyro's vertical yaw between
  /// (and its own candidate, swing and interval, with own_candidate); else they are refused.
  std::vector<HeldStep> settle_held(std::vector<HeldStep>& held, const HeldStep& next, bool own_candidate);
  /// A step at t_ns falls in handling's hang-over and may wait (hangover_steps_wait).
  bool in_handling_hangover(TimeNs t_ns) const;
  PlacementEstimator placement_;
  HeadingFusion fusion_;
  QuasiStaticField qsf_;
  MagCalibration magcal_;
  Eigen::Vector3d compass_bias_ut_ = Eigen::Vector3d::Zero();  // hard iron the compass offset was learned with
  Eigen::Vector3d drift_bias_ut_ = Eigen::Vector3d::Zero();    // hard iron the gyro drift was learned with
  /// The hard iron in use moved at least change_ut (0 = never) from since_ut, which then takes it.
  bool hard_iron_moved(Eigen::Vector3d& since_ut, double change_ut);
  Eigen::Vector3d fusion_reference_;  // the reference axis fusion_'s offset refers to
  double qsf_weight() const { return qsf_.quasi_static() ? 1.0 : opt_.fusion.non_qsf_weight; }
  std::int64_t placement_revision_ = 0;
  bool handling_reset_ = false;  // in a handling span, whose start restarted the heading offset
  void track_handling();
  Eigen::Vector3d last_field_ut_ = Eigen::Vector3d::Zero();
  double mag_accuracy_weight_ = 1.0;  // no accuracy event yet: readings keep their own weight
  TimeNs last_gyro_ns_ = -1;
  double distance_m_ = 0.0;
  // the latest accelerometer step's swing, lent to Android step events (Weinberg needs one)
  double last_swing_mps2_ = kNaN;
  TimeNs last_swing_ns_ = -1;
  std::int64_t gaps_seen_ = 0;
  PdrCounters counters_;
  // heading state: time of the last absolute heading (fusion_ holds the offset)
  bool have_heading_ = false;
  TimeNs ref_t_ns_ = 0;
  TimeNs last_rv_ns_ = 0;
  bool have_rv_ = false;
  TimeNs last_rv_check_ns_ = 0;
  bool have_mag_last_ = false;
  TimeNs mag_last_ns_ = 0;
  bool have_sd_last_ = false;
  TimeNs sd_last_ns_ = 0;
  double declination_rad_ = 0.0;
  geo::Declination declination_;
  bool has_location_ = false;
  TimeNs latest_ns_ = 0;
  // outputs
  std::vector<PdrStep> steps_;
  std::deque<HeldStep> undecided_;  // released, waiting for the walking direction
  std::vector<char> steps_magnetic_;  // per steps_ entry: heading still magnetic
  // heading source: the latest absolute stream and the decayed mean weight of its readings
  HeadingSource abs_kind_ = HeadingSource::kInitial;
  double abs_weight_mean_ = 0.0;
  TimeNs abs_weight_ns_ = -1;
  std::vector<HeadingSourceSpan> source_spans_;
  std::int64_t step_count_ = 0;
  std::deque<TimeNs> accel_step_times_, android_step_times_;
  TimeNs last_android_ns_ = 0;
  bool have_android_ = false;
};

}  // namespace pdnav::pdr
