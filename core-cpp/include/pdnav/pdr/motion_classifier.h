// Motion classifier that gates the step detector (issue 16): walking / standing / phone
// handled or waved. Window features after Susi, Renaudin, Lachapelle, "Motion mode recognition
// and step detection algorithms for mobile phone users", Sensors 13(2), 2013 (variance of
// the acceleration norm, energy of the angular rate), plus the spread of the rotation axis:
// walking rotates a carried phone about one axis (arm or thigh swing, gait sway), a waved
// phone (the figure-eight compass calibration, turning it over, picking it up) about several.
// Without a gyroscope nothing is called handling (no evidence), so accelerometer-only data
// (the Oxford walks) are gated exactly as before.
// Vehicle (car, bus, train): sustained vibration with no gait periodicity. Gait makes |a|
// periodic at the step (0.35-0.75 s) or stride (0.7-1.5 s) lag (autocorrelation as in Rai et
// al., "Zee", MobiCom 2012, which finds the walking period from the normalised
// autocorrelation of the acceleration); a road vehicle's body bounce is a damped random
// response (suspension mode ~1-1.5 Hz, damping ratio 0.2-0.4) whose autocorrelation has
// decayed by one period, plus broadband road and engine vibration. Evidence is accumulated
// over a leaky score so that a real walk's irregular stretches (turns, pauses, fidgeting:
// at most 5 s of evidence in a row on the 49 real walks) never reach it.
#pragma once
#include <cstdint>
#include <deque>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/samples.h"
#include "pdnav/geo/units.h"
#include "pdnav/pdr/time_window.h"

namespace pdnav::pdr {

enum class MotionState { kStanding, kWalking, kHandling, kVehicle };
const char* to_string(MotionState m);

struct MotionClassifierOptions {
  double window_s = 1.0;              // about one stride (Susi et al. use 1-2 s windows); short so
                                      // waving is caught before the bout gate confirms 4 steps
  double standing_sigma_mps2 = 0.3;   // sigma |a| below this and ...
  double standing_rate_radps = 0.3;   // ... RMS |omega| below this: standing
  // Handling: RMS |omega| above handling_rate_radps with a rotation-axis spread (second /
  // largest eigenvalue of sum omega omega^T) above axis_spread_min, or any RMS above
  // extreme_rate_radps. Measured on the 43 hand-held ILC walks (1 s windows): walking and
  // turning reach 1.97 rad/s RMS at most with a spread > 0.25 (median walk 1.22), 4.3 rad/s
  // at most at any spread; figure-eight waving at 0.6-1.2 Hz, +-35-70 deg is 4-9 rad/s.
  // A swinging hand: ~2.4 rad/s RMS about one axis (spread < 0.15).
  double handling_rate_radps = 2.5;
  double axis_spread_min = 0.25;
  double extreme_rate_radps = 6.0;
  double hold_s = 1.0;                // handling lasts this long after the features drop
  // Running (issue 27) turns a hand-held or pocket phone at 3-7 rad/s RMS (TYREX runs, 1 s
  // windows, p10-p90), as fast as waving; a vigorously swinging arm can too. What handling lacks
  // is gait coherence: in gait the limb and trunk rotation repeats with the foot strikes' rhythm
  // (Moe-Nilssen & Helbostad, J. Biomech. 2004: one gait cycle in every body segment). A window
  // is gait, never handling, when |a| is periodic at a gait lag (vehicle window autocorrelation
  // >= gait_exit_min), moves (sigma |a| >= running_min_sigma_mps2 over the 1 s window: a phone
  // held still while the body turns has no strikes) and the angular-rate vector repeats at that
  // lag or twice it (autocorrelation, leaky mean over running_coherence_tau_s >=
  // running_min_coherence). Measured (4 s windows): runs 0.44-0.90 p10-p90 (hand 0.70-0.90);
  // the synthesised figure-eight waving on three ILC walks, 6 seeds and amplitudes, -0.24-0.58
  // p10-p90, median <= 0.20 (its sigma |a| 1-2 m/s^2 alone, > 3 with the walk's own residuals
  // added, so sigma cannot separate). 0 = off. Hysteresis (as any two-threshold activity
  // detector): the strikes' periodicity is needed to enter a run, not to stay in it; a run lasts
  // while the phone moves and its rotation keeps the gait rhythm (a turn in a run breaks the 4 s
  // periodicity of |a| for a few seconds, TYREX hand 30.5-34.5 s: 0.29-0.59, coherence 0.81-0.84),
  // and, like handling, for hold_s after it ends.
  double running_min_sigma_mps2 = 1.0;
  double running_min_coherence = 0.5;
  double running_coherence_tau_s = 2.0;
  // Suspicion: the same tests at this fraction of the rates. A step taken while the phone turns
  // this much, or in a session's first window (no evidence yet), waits one window and while the
  // suspicion lasts (at most three windows); handling that begins meanwhile refuses it. Waving
  // that starts gently (the first second of a figure eight, one dominant axis) otherwise leaks
  // the steps the bout gate releases at the second step (docs/pdr.md "Waving that starts gently").
  double suspect_fraction = 0.6;
  double gyro_timeout_s = 0.5;        // no gyro sample for this long: no handling evidence
  // Without a gyroscope the magnetometer's turning gives the rate square to the Earth's field
  // (PlacementEstimator::feed(MagSample), feed_field_rate): its axis is not the rotation's (the
  // part along the field is missing and moves with the phone), so no spread test; its RMS is
  // tested against extreme_rate_radps x field_rate_fraction, sqrt(2/3) (the mean share of a
  // rotation's power square to the field over axis directions). Measured (1 s windows): the
  // synthesised figure-eight waving on the 43 ILC walks 4.9 / 6.4 rad/s p5 / p50; the walks
  // (TYREX, every carry and both runs; ILC; ETH) <= 4.7 (the hand run). The running exit holds
  // as with the gyroscope (the rate's coherence with the strikes); no suspicion (the hand run is
  // above suspect_fraction of the test in 20 % of its windows: steps held back, its heading 5
  // deg worse). 0 = off.
  double field_rate_fraction = 0.816496580927726;
  // Vehicle (docs/pdr.md, "Vehicle class"). One evaluation every vehicle_eval_s over the last
  // vehicle_window_s of |a| averaged into vehicle_bin_s bins (20 Hz: keeps the gait band).
  bool vehicle = true;
  double vehicle_window_s = 4.0;        // >= 2.6 x the longest gait lag
  double vehicle_bin_s = 0.05;
  double vehicle_eval_s = 0.25;
  double gait_lag_min_s = 0.35;         // fastest step (cadence ~2.9 Hz)
  double gait_lag_max_s = 1.5;          // slowest stride (pocket / swinging hand see strides)
  // evidence: max normalised autocorrelation over the gait lags below aperiodic_max, every 1 s
  // of the window with sigma |a| in [vehicle_min_sigma, vehicle_max_sigma] (vibration present,
  // below gait's 1-4 m/s^2; passenger seats see 0.2-1 m/s^2 RMS), and RMS |omega| over the
  // window below vehicle_max_rate (a held phone in a vehicle turns with the vehicle, <= 0.35
  // rad/s, plus the hand's wander; walking hand-held 0.4-1.2 rad/s). On the real walks (43 ILC
  // + 6 Oxford, 4 s windows) the autocorrelation's 5th percentile is 0.24-0.9 per walk, so no
  // single feature separates: the leaky score below does.
  double aperiodic_max = 0.6;
  double vehicle_min_sigma_mps2 = 0.05;
  double vehicle_max_sigma_mps2 = 1.5;
  double vehicle_max_rate_radps = 0.4;
  // leaky score (s): + vehicle_eval_s per evidence window, - vehicle_decay x that per other
  // window; vehicle once it reaches vehicle_enter_s. Highest score on the 49 real walks: 5.0 s
  // (also 5.0 s on the ILC walks with their gyroscope ignored); a ride lasts minutes. The span
  // is dated back to the evidence's start (minus one window).
  double vehicle_enter_s = 10.0;
  double vehicle_decay = 2.0;
  // exit: a window with gait: autocorrelation >= gait_exit_min, every 1 s sigma >=
  // gait_exit_sigma, and (gyro live) RMS |omega| >= gait_exit_rate. No window of the four
  // synthesised rides meets it; 88 % of the real walks' windows do (median walk). The span
  // ends vehicle_exit_lookback_s earlier (the walk had to fill part of the window).
  double gait_exit_min = 0.6;
  double gait_exit_sigma_mps2 = 0.5;
  double gait_exit_rate_radps = 0.3;
  double vehicle_exit_lookback_s = 1.5;
  // Kinematic evidence (with a gyroscope): a motorised vehicle changes speed (pulling away,
  // braking, turning) at rates no walker reaches: Hemminki, Nurmi, Tarkoma, "Accelerometer-based
  // transportation mode detection on smartphones", SenSys 2013, find motorised periods from
  // their acceleration and braking segments. Evidence: the mean horizontal acceleration of the
  // phone (the specific force less its part along a gyro-propagated gravity, in phone axes, which
  // ride with the vehicle) over kinematic_window_s reaches kinematic_min_mps2 while the phone
  // turns slower than vehicle_max_rate_radps: a speed change of >= 2.4 m/s in 3 s (car and bus
  // service accelerations 0.9-1.5 m/s^2, braking 1.2-2), or a turn's v x yaw rate. A walker
  // changes speed by <= 1.5 m/s (standstill to a brisk walk) and turns at <= 0.4 rad/s x 1.5 m/s =
  // 0.6 m/s^2 under that rate. The vehicle is entered only when such evidence lies within
  // kinematic_memory_s (a ride's stops and turns recur within minutes). Without a gyroscope
  // there is no such evidence, and the score alone took the slow shuffles of TYREX (texting,
  // phoning, the phone held up) for rides from start to end (20-76 % of their steps lost), so a
  // phone without one is never classed vehicle (its rides count steps). Measured (docs/pdr.md): the
  // synthesised rides reach 1.01-1.76 m/s^2, the shared real walks <= 0.73 but one ILC walk at 1.01
  // (accelerometer bias and scale leak into the horizontal as a phone is turned). 0 = off (the
  // vibration score alone decides, with or without a gyroscope).
  double kinematic_min_mps2 = 0.8;
  double kinematic_window_s = 3.0;
  double kinematic_tilt_tau_s = 10.0;  // gravity's pull toward the accelerometer (gyro drift <= tau x bias)
  double kinematic_memory_s = 300.0;
};

struct MotionSpan {
  TimeNs t_start_ns = 0, t_end_ns = 0;
  MotionState state = MotionState::kStanding;
};

class MotionClassifier {
 public:
  explicit MotionClassifier(const MotionClassifierOptions& options = {});
  void feed(const AccelSample& s);
  void feed(const GyroSample& s);
  /// Without a gyroscope: the angular rate square to the Earth's field from the magnetometer's
  /// turning (MotionClassifierOptions::field_rate_fraction). Ignored while a gyroscope is live.
  void feed_field_rate(TimeNs t_ns, const Eigen::Vector3d& rate_radps);
  MotionState state() const { return state_; }
  /// In a vehicle (may be true while the state says handling: waving in a bus).
  bool in_vehicle() const { return vehicle_; }
  /// Vehicle evidence is accumulating but has not reached vehicle_enter_s: steps should wait.
  bool vehicle_suspect() const { return !vehicle_ && vehicle_score_s_ > 0.0; }
  /// True when t_ns lies inside a vehicle span (closed, or the open one).
  bool vehicle_at(TimeNs t_ns) const;
  const std::deque<MotionSpan>& vehicle_spans() const { return vehicle_spans_; }
  /// Latest vehicle-window features: max gait autocorrelation, min / max 1 s sigma |a|.
  double gait_autocorrelation() const { return gait_corr_; }
  double vehicle_score_s() const { return vehicle_score_s_; }
  /// Largest mean horizontal acceleration over kinematic_window_s seen so far outside a vehicle
  /// span while the phone turned slowly (m/s^2; MotionClassifierOptions::kinematic_min_mps2), and
  /// the last time it reached the threshold (-1: never).
  double kinematic_max_mps2() const { return kinematic_max_mps2_; }
  /// Highest vehicle score reached outside a vehicle span (s).
  double vehicle_max_score_s() const { return vehicle_max_score_s_; }
  TimeNs kinematic_last_ns() const { return kinematic_last_ns_; }
  /// Vigorous gait (running, a swinging arm): the phone turns like handling, but the gait
  /// coherence test passes (true for hold_s after).
  bool running() const { return ran_within_hold(last_acc_ns_); }
  /// Rotation repeating with the gait (running_min_coherence): leaky mean, -1..1.
  double gait_coherence() const { return gait_coherence_; }
  /// True when t_ns lies inside a handling span (closed, or the open one).
  bool handling_at(TimeNs t_ns) const;
  /// The latest window turns like handling (the features themselves, without the hold_s
  /// hang-over that keeps state() at kHandling after they drop).
  bool handling_features() const { return handling_raw_; }
  /// Time of the latest window whose features turned like handling (-1: none yet).
  TimeNs handling_features_last_ns() const { return handling_last_ns_; }
  /// Handling spans so far (bounded to the last 256).
  const std::deque<MotionSpan>& handling_spans() const { return spans_; }
  /// The rotation looks like the start or end of handling (MotionClassifierOptions::suspect_fraction).
  bool handling_suspect() const { return suspect_; }
  /// The gyro window is not full yet (the first second of a session): no handling evidence.
  bool evidence_young() const { return young_; }
  double rate_rms_radps() const { return rate_rms_; }
  double axis_spread() const { return spread_; }

 private:
  void update(TimeNs t_ns);
  struct Bin {
    int n = 0;
    double sum = 0.0, sq = 0.0;
    int gyro_n = 0;
    double gyro_sq = 0.0;
    Eigen::Vector3d gyro_sum = Eigen::Vector3d::Zero();
  };
  void vehicle_sample(TimeNs t_ns, double acc_norm, const Eigen::Vector3d* gyro);
  void vehicle_evaluate(TimeNs t_ns);
  void kinematic_accel(const AccelSample& s);
  void kinematic_gyro(const GyroSample& s);
  bool kinematic_recent(TimeNs t_ns) const;

  /// A stream whose last sample (last_ns) is within gyro_timeout_s of t_ns.
  bool live(TimeNs last_ns, TimeNs t_ns) const {
    return last_ns >= 0 && ns_to_s(t_ns - last_ns) <= opt_.gyro_timeout_s;
  }

  MotionClassifierOptions opt_;
  TimeWindowMoments acc_;                 // |a| over window_s
  TimeWindowSum<Eigen::Matrix3d> gyro_;   // omega omega^T over window_s
  TimeNs last_gyro_ns_ = -1;
  TimeNs last_acc_ns_ = -1;
  TimeWindowSum<double> field_rate_sq_;  // |rate square to the field|^2 over window_s
  TimeNs last_field_rate_ns_ = -1;
  double rate_rms_ = 0.0, spread_ = 0.0;
  MotionState state_ = MotionState::kStanding;
  bool handling_raw_ = false;
  bool suspect_ = false, young_ = false;
  TimeNs handling_last_ns_ = -1;
  std::deque<MotionSpan> spans_;
  bool span_open_ = false;
  // vehicle
  std::deque<Bin> bins_;           // completed bins, oldest first (window / bin of them)
  Bin cur_bin_;
  std::int64_t cur_bin_index_ = -1;
  TimeNs bin_origin_ns_ = -1;
  std::int64_t bins_since_eval_ = 0;
  bool vehicle_ = false;
  double vehicle_score_s_ = 0.0;
  TimeNs evidence_start_ns_ = -1;
  double gait_corr_ = 0.0;
  double gait_coherence_ = 0.0;  // leaky mean of the rotation's autocorrelation at the gait lag
  bool running_state_ = false;   // in a run: entered on periodic strikes, kept while the rhythm lasts
  TimeNs running_last_ns_ = -1;  // last time running while turning like handling
  /// Running while turning like handling within hold_s before t_ns.
  bool ran_within_hold(TimeNs t_ns) const {
    return running_last_ns_ >= 0 && t_ns - running_last_ns_ <= s_to_ns(opt_.hold_s);
  }
  std::deque<MotionSpan> vehicle_spans_;
  // kinematic evidence: gyro-propagated gravity (phone axes) and the horizontal specific force
  Eigen::Vector3d kin_up_ = Eigen::Vector3d::UnitZ();
  bool kin_have_up_ = false;
  TimeNs kin_acc_ns_ = -1;  // previous accelerometer sample the filter took (the gyro's: last_gyro_ns_)
  TimeWindowSum<Eigen::Vector3d> kin_h_;  // over kinematic_window_s
  TimeNs kinematic_last_ns_ = -1;
  double kinematic_max_mps2_ = 0.0;
  double vehicle_max_score_s_ = 0.0;
};

}  // namespace pdnav::pdr
