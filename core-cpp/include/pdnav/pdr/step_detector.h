// Step detection from the accelerometer: the level-crossing detector of APT (Zhu, Li, Chen,
// "APT: Accurate Outdoor Pedestrian Tracking with Smartphones", INFOCOM 2013, Sec. V-A)
// plus the gates real data needs (low-pass, minimum step interval, walking gate, bout gate).
#pragma once
#include <algorithm>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/samples.h"
#include "pdnav/pdr/time_window.h"

namespace pdnav::pdr {

/// Counters of input samples that were skipped or that reset the detector, by reason.
struct SampleCounters {
  std::int64_t accepted = 0;
  std::int64_t non_finite = 0;      // NaN/Inf value: skipped
  std::int64_t duplicate_time = 0;  // same t_ns as the previous sample: skipped
  std::int64_t backwards_time = 0;  // t_ns before the previous sample: skipped
  std::int64_t gaps = 0;            // time gap > gap_reset_s: detector reset, sample kept
  std::int64_t skipped() const { return non_finite + duplicate_time + backwards_time; }
};

/// Why an input sample is rejected (or kOk). Shared by the step detector and heading code.
enum class SampleCheck { kOk, kNonFinite, kDuplicate, kBackwards, kGap };

/// Classifies a timestamp against the previous accepted one and counts it.
SampleCheck check_sample(TimeNs t_ns, bool finite, TimeNs last_t_ns, bool have_last, double gap_reset_s,
                         SampleCounters& counters);

struct StepDetectorOptions {
  // --- APT Sec. V-A: running mean/std of |a| over a window, symbols against mu +- k*sigma.
  // Tuned on the Oxford walks (docs/pdr.md): the window must span one stride (two steps) at
  // the slowest cadence (1.2 Hz -> 1.7 s) so a pocket phone's weak other-leg step still
  // crosses mu + k*sigma; k in 0.2-0.5 all give < 1 % error, 0.3 is the middle.
  double window_s = 1.5;   // running-statistics window (APT: a window of N samples)
  double k_sigma = 0.3;    // symbol thresholds mu +- k*sigma (APT's k)
  // --- Improvements for real data (set to 0 to get the paper's form).
  // 2x first-order low-pass of |a| before quantising (0 = off), discretised exactly (alpha =
  // 1 - exp(-dt / tau)) so the cut-off does not move with the sampling rate. The former
  // dt / (tau + dt) form of a nominal 3 Hz cut 2.55 Hz at 50 Hz, 2.75 at 100 and 2.86 at
  // 200: the same TYREX walk gave 89 steps at 200 Hz and 71 block-averaged to 50 Hz. 2.75 Hz
  // is what the app (accelerometer at 100 Hz) ran; measured against 2.55 / 2.86 / 3.0 on every
  // shared set in docs/pdr.md (Step detector).
  double lowpass_hz = 2.75;
  double min_step_interval_s = 0.25;   // refractory time after a step: cadence <= 3 Hz + jitter
  // Adaptive refractory: also >= this x the running step interval (0 = off). Kept at 0.4 so a
  // detector that ever locked onto every other step (typical = 2T) still accepts the true steps
  // (0.8 T); 0.6-0.7 can lock at half cadence after a sudden speed-up (docs/pdr.md).
  double refractory_fraction = 0.4;
  double min_sigma_mps2 = 0.3;         // walking gate: sigma below this = not walking, symbol undefined
                                       // (0.4 missed 66 % of a walk with 0.25x the motion; docs/pdr.md)
  double min_swing_mps2 = 0.0;         // peak-to-trough of a period must exceed this (0 = off)
  // --- Bout gate (like the phones' hardware counter): steps count only inside a bout of at
  // least bout_min_steps steps whose intervals are all below max_step_interval_s.
  int bout_min_steps = 4;              // 1 = every step counts at once (paper form)
  // A walk shorter than the bout (issue 19.6) still counts once it ends, if it has at least
  // this many regular steps (3 = a 2 m walk; 2 steps alone are as likely a jolt). 0 = off.
  int short_walk_min_steps = 3;
  // The same with a live gyroscope (Pdr only): the motion classifier then refuses handling and
  // waving (docs/pdr.md "Motion classifier"), which is what made two steps "as likely a jolt",
  // so two regular steps between two pauses count: stepping on to the next spot and stopping
  // (on the ILC survey walks, 1-2 m to a waypoint; measured in docs/pdr.md "First steps").
  int short_walk_min_steps_gyro = 2;
  // The bout itself with a live gyroscope (Pdr only): two regular steps already count when the
  // walk ends there (above), so holding the first steps until the fourth only delays them; a
  // walker's position then lags by up to three steps at every start (measured on the ILC walks:
  // mean waypoint error 3.26 -> 3.16 m, docs/pdr.md "Latency of the first steps"). 0 = as
  // bout_min_steps.
  int bout_min_steps_gyro = 2;
  double max_step_interval_s = 1.3;    // longer pause ends the bout (cadence >= ~0.8 Hz)
  // --- Swinging hand (issue 20.1, docs/pdr.md "Swinging hand"): an arm swings at the STRIDE
  // frequency, so |a| peaks once per stride and the level crossings count every other step.
  // A candidate whose interval is stride-like and whose filtered |a| over the last two
  // intervals carries real power at twice 1/interval (the body's bounce and the heel strikes,
  // i.e. the step frequency) is a stride: the step between is emitted at the midpoint. Needs
  // two such candidates in a row (one odd long interval is a pause or a missed step, not a
  // swinging arm). Measured: real pocket/bag/hand/texting walks have < 1 % stride-like
  // candidates in a row; the simulated swinging hand > 90 %. 0 = off.
  double stride_min_interval_s = 0.75;  // shortest stride (cadence <= 2.67 steps/s)
  // ... while running (set_running: the motion classifier's running test, Pdr): a run's stride
  // is 0.6-0.8 s (2.5-3.3 steps/s, issue 27). Not by default: at 0.55 s a walk's steps pass for
  // strides (ILC 2.44 -> 2.97 m, Oxford 0.44 -> 2.98 %).
  double running_stride_min_interval_s = 0.55;
  // ... and one stride-like interval is split without a second in a row: a run does not pause
  // between two strikes (stopping ends the running state first), so an interval of a stride
  // whose |a| carries the step frequency (the test above) holds a strike the level crossings
  // missed. TYREX runs (issue 27), steps against the capture: hand -14.4 -> -7.0 %, pocket
  // -14.5 -> -8.4 %; walking unchanged.
  bool running_single_stride = true;
  // ... and, running, an interval of n >= 2 steps of the run's own period holds n - 1 steps the
  // level crossings missed: faster than ~3 steps/s the low-pass above leaves a hand's arm swing
  // (at the stride) over the steps, and the crossings skip runs of them. The period is half the
  // stride: the lag in running_stride_lag_min_s..max_s with the largest normalised
  // autocorrelation of the unfiltered |a| (20 ms bins) over the last running_period_window_s
  // (the stride is the one period of every body segment in gait: Moe-Nilssen & Helbostad, J.
  // Biomech. 2004; autocorrelation step counting: Rai et al., MobiCom 2012). Used when that
  // autocorrelation is >= running_period_min_corr, the interval is within
  // running_fill_tolerance of n periods (3 sigma of a run's step-time jitter over a few steps;
  // a turn's slower steps fall between) and at most running_fill_max_interval_s. Where it does
  // not apply, running_single_stride's tests decide. TYREX runs, steps in the capture's span:
  // hand 295 -> 298 of 313, pocket 286 (unchanged) of 311; the 14 recordings taken 1.2 times
  // faster (eval-pdr --speed 1.2, the runs at 3.3 steps/s): hand -26.2 -> -16.0 %, pocket
  // -11.9 -> -10.0 % (tools/eval-pdr-all, as docs/pdr.md). 0 = off.
  double running_period_window_s = 3.0;
  double running_stride_lag_min_s = 0.5, running_stride_lag_max_s = 0.95;  // 2.1-4 steps/s
  double running_period_min_corr = 0.5;
  double running_fill_tolerance = 0.2;   // steps
  double running_fill_max_interval_s = 2.0;
  // ... and, walking, one stride-like interval of 2 steps of the bout's own cadence: an
  // interval within [1 - tol, 1 + tol] x twice the running step interval, whose |a| carries
  // the step frequency and whose phone swings at 1/I (the tests above), holds a step the level
  // crossings missed (a swinging arm's weak heel strike); a pause shows no step power. The
  // cadence is the one the bout kept up to it (step-to-step regularity: Moe-Nilssen &
  // Helbostad 2004). Only with the swing read from the gyroscope: the tilt test passes a flat
  // phone's sway (texting, below). 0 = off.
  double walking_single_stride_tol = 0.2;
  double stride_max_interval_s = 2.6;   // longest stride (cadence >= 0.77 steps/s)
  double stride_harmonic_ratio = 0.1;   // |X(2/I)| / |X(1/I)| of |a| above this = step power present
  // The phone must also swing at 1/I: its tilt (direction of the low-passed specific force)
  // oscillates once per interval by more than this amplitude, and more than at 1/(2I) (a
  // pocket phone on a slow walk swings with the thigh once per STRIDE = every 2 intervals).
  double stride_min_tilt_rad = 3.0 * kDegToRad;
  // With a live gyroscope (Pdr feeds it) the swing is read from the angular rate instead: the
  // rotation at 1/I must exceed this amplitude and the rotation at 1/(2I). A phone swinging
  // with the arm is a pendulum, whose specific force stays along the arm: its tilt as seen by
  // the accelerometer moves only 3-7 deg while the phone turns +-15-25 deg. Measured at the
  // stride-like candidates (amplitude at 1/I, p10-p90): swinging hand 1.3-2.3 rad/s, runs
  // 1.7-5.2; pockets, phone at the ear and hand-held (ILC) 0.5-1.0 rad/s. 0 = the tilt always.
  // Without a gyroscope Pdr feeds the magnetometer's rate (PlacementOptions::mag_rate_lowpass_hz).
  double stride_min_rotation_radps = 1.0;
  // --- Input hygiene.
  double gap_reset_s = 0.5;            // a sample gap longer than this resets the detector

  /// The paper's form: no low-pass, no refractory time, no walking or bout gate.
  static StepDetectorOptions paper();
};

/// A detected step (before length and heading are attached).
struct StepCandidate {
  TimeNs t_ns = 0;          // time the period completed (the "0" symbol after a "1")
  double swing_mps2 = 0.0;  // max - min of the filtered |a| over the period (for Weinberg)
  double interval_s = 0.0;  // time since the previous candidate step (0 for the first)
  /// A step placed inside a longer interval (a stride's midpoint, a run's missed steps): the
  /// interval's start, the previous candidate (0 = an ordinary candidate, completed at t_ns).
  TimeNs placed_from_ns = 0;
};

/// Holds steps until a bout of `min_steps` regular steps is confirmed, then releases them; while
/// a bout lasts every step is released at once. Payload T carries the caller's data (its own
/// time, so a released step keeps the time it was taken). A walk that ends before the gate
/// confirmed it (issue 19.6: a 2 m walk) is released when it ends - no step for
/// max_interval_s (expire), a gap (end_bout) or the end of the input (finish) - if it has at
/// least `short_walk_min_steps` steps with regular intervals (longest / shortest <= 2).
template <typename T>
class BoutGate {
 public:
  BoutGate(int min_steps, double max_interval_s, int short_walk_min_steps = 3)
      : min_steps_(min_steps), short_min_(short_walk_min_steps), max_interval_ns_(s_to_ns(max_interval_s)) {}

  /// Adds a step at t_ns; returns the steps released by it (possibly several, possibly none):
  /// a short walk ended by the pause before this step, then this bout's steps.
  std::vector<T> push(TimeNs t_ns, T payload) {
    std::vector<T> out;
    if (have_last_ && t_ns - last_t_ns_ > max_interval_ns_) out = end_bout();
    have_last_ = true;
    last_t_ns_ = t_ns;
    if (in_bout_) {
      out.push_back(std::move(payload));
      return out;
    }
    pending_.push_back(std::move(payload));
    pending_t_.push_back(t_ns);
    if (static_cast<int>(pending_.size()) >= min_steps_) {
      in_bout_ = true;
      release_pending(out);
    }
    return out;
  }
  /// Time passes without a step (call with the latest sample time): a walk that has ended
  /// (no step for max_interval_s) is closed; returns a short walk's steps if it qualifies.
  std::vector<T> expire(TimeNs now_ns) {
    if (have_last_ && now_ns - last_t_ns_ > max_interval_ns_) return end_bout();
    return {};
  }
  /// End of the input: closes the current walk (see expire).
  std::vector<T> finish() { return end_bout(); }
  /// Ends the current bout (e.g. after a gap). Unconfirmed steps are released as a short walk
  /// when they qualify, otherwise discarded (and counted).
  std::vector<T> end_bout() {
    std::vector<T> out;
    if (!in_bout_ && short_walk_qualifies()) {
      short_walk_steps_ += static_cast<std::int64_t>(pending_.size());
      release_pending(out);
    }
    discarded_ += static_cast<std::int64_t>(pending_.size());
    pending_.clear();
    pending_t_.clear();
    in_bout_ = false;
    have_last_ = false;
    return out;
  }
  std::int64_t discarded() const { return discarded_; }
  /// Minimum length of a short walk from now on (0 = off); see StepDetectorOptions.
  void set_short_walk_min_steps(int n) { short_min_ = n; }
  /// Steps that confirm a bout from now on (>= 1); the steps already held are released at the next push.
  void set_min_steps(int n) { min_steps_ = std::max(1, n); }
  std::int64_t short_walk_steps() const { return short_walk_steps_; }
  bool in_bout() const { return in_bout_; }
  /// Steps held, waiting for the bout to be confirmed.
  std::size_t pending() const { return pending_.size(); }

 private:
  void release_pending(std::vector<T>& out) {
    for (auto& p : pending_) out.push_back(std::move(p));
    pending_.clear();
    pending_t_.clear();
  }
  bool short_walk_qualifies() const {
    if (short_min_ <= 0 || static_cast<int>(pending_.size()) < short_min_ || pending_t_.size() < 2) return false;
    TimeNs lo = pending_t_[1] - pending_t_[0], hi = lo;
    for (std::size_t i = 2; i < pending_t_.size(); ++i) {
      lo = std::min(lo, pending_t_[i] - pending_t_[i - 1]);
      hi = std::max(hi, pending_t_[i] - pending_t_[i - 1]);
    }
    return lo > 0 && hi <= 2 * lo;
  }

  int min_steps_;
  int short_min_;
  TimeNs max_interval_ns_;
  std::vector<T> pending_;
  std::vector<TimeNs> pending_t_;
  bool in_bout_ = false;
  bool have_last_ = false;
  TimeNs last_t_ns_ = 0;
  std::int64_t discarded_ = 0;
  std::int64_t short_walk_steps_ = 0;
};

/// Level-crossing step detector on the acceleration magnitude (APT Sec. V-A). Incremental:
/// O(1) per sample; the running mean/std use sums over a time window.
class StepDetector {
 public:
  explicit StepDetector(const StepDetectorOptions& options = {});

  /// Feeds one accelerometer sample; returns the raw step candidates completed by it, in time
  /// order: none, one, or two when a stride was recognised (the midpoint step, then this one).
  /// Candidates are not yet bout-gated: use BoutGate (as Pdr and detect_steps do).
  std::vector<StepCandidate> feed(const AccelSample& s);
  /// Feeds one calibrated gyroscope sample (optional): while its samples cover the interval,
  /// the stride test reads the phone's swing from the angular rate (stride_min_rotation_radps).
  void feed(const GyroSample& s);
  /// The walker is running (Pdr: MotionClassifier::running()): strides down to
  /// running_stride_min_interval_s are recognised.
  void set_running(bool running) { running_ = running; }
  /// The same detector on any scalar signal (no stride splitting, no tilt): the forward
  /// acceleration channel of Pdr. Same hygiene, filter, window and symbols.
  std::vector<StepCandidate> feed_value(TimeNs t_ns, double value);
  /// The walking gate passed at the latest sample (sigma of the window >= the gate).
  bool gate_open() const;
  /// max - min of the filtered |a| over [from, to] (the stride history; 0 when none).
  double swing_between(TimeNs from_ns, TimeNs to_ns) const;
  /// Steps added at stride midpoints (swinging-hand mode) and in running intervals of several
  /// steps (running_fill_*) so far.
  std::int64_t stride_steps_added() const { return stride_steps_added_; }
  /// Clears all state but the counters (called on gaps).
  void reset();

  const SampleCounters& counters() const { return counters_; }
  const StepDetectorOptions& options() const { return opt_; }

 private:
  struct Tilted {
    TimeNs t_ns;
    double value;           // filtered |a|
    double raw;             // |a|
    Eigen::Vector3d dir;    // unit vector of the low-passed specific force (phone tilt)
  };
  enum class Symbol { kUndefined, kLow, kHigh };
  double filter(double magnitude, double dt_s);
  Symbol quantise(double value) const;
  /// Input hygiene, gap reset, low-pass and window for one raw value; the filtered value, or
  /// nothing when the sample is skipped (counted). dt_s: the time since the previous sample.
  std::optional<double> accept(TimeNs t_ns, bool finite, double raw, double* dt_s);
  std::optional<StepCandidate> on_symbol(Symbol sym, TimeNs t_ns, double value);
  void split_strides(const StepCandidate& c, std::vector<StepCandidate>& out);
  /// by_gyro (optional): set true when the swing was read from the gyroscope, not the tilt.
  bool stride_like(TimeNs t_ns, double interval_s, bool* by_gyro = nullptr) const;
  /// Whether the gyroscope shows the phone swinging at 1/I; nullopt when its samples do not
  /// cover the last two intervals (no gyroscope, a gap, or a batch not yet delivered).
  std::optional<bool> rotates_at(TimeNs t_ns, double interval_s) const;
  /// Running: the step period, half the stride lag of |a|'s autocorrelation over the last
  /// running_period_window_s (running_fill_*); 0 when |a| is not that periodic or not covered.
  double running_step_period_s(TimeNs t_ns) const;
  /// Running: candidate c ends an interval of n >= 2 steps of that period; its steps, evenly
  /// spaced, go to out (true), else nothing (false).
  bool fill_run(const StepCandidate& c, std::vector<StepCandidate>& out);

  StepDetectorOptions opt_;
  SampleCounters counters_;
  bool have_last_ = false;
  TimeNs last_t_ns_ = 0;
  // low-pass state
  bool filter_init_ = false;
  double lp1_ = 0.0, lp2_ = 0.0;
  // running statistics
  TimeWindowMoments window_;  // filtered |a| over window_s
  // symbol state machine
  Symbol last_defined_ = Symbol::kUndefined;
  double period_max_ = 0.0, period_min_ = 0.0;
  bool have_step_ = false;
  TimeNs last_step_ns_ = 0;
  double typical_interval_s_ = 0.0;  // running average of in-bout step intervals (0 = none yet)
  double typical_before_s_ = 0.0;    // ... before the latest candidate updated it
  // stride recognition (swinging hand)
  std::deque<Tilted> history_;       // the last 2 * stride_max_interval_s
  Eigen::Vector3d lpv1_ = Eigen::Vector3d::Zero(), lpv2_ = Eigen::Vector3d::Zero();
  struct Rate {
    TimeNs t_ns;
    Eigen::Vector3d rate_radps;
  };
  std::deque<Rate> rates_;           // gyroscope, the last 2 * stride_max_interval_s
  bool prev_stride_like_ = false;
  bool running_ = false;
  std::int64_t stride_steps_added_ = 0;
};

/// Offline helper: runs detector + bout gate over a whole recording, returns the step times.
std::vector<StepCandidate> detect_steps(const std::vector<AccelSample>& samples,
                                        const StepDetectorOptions& options,
                                        SampleCounters* counters = nullptr);

}  // namespace pdnav::pdr
