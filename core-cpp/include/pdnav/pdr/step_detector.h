// Step detection from the accelerometer: the level-crossing detector of APT (Zhu, Li, Chen,
// "APT: Accurate Outdoor Pedestrian Tracking with Smartphones", INFOCOM 2013, Sec. V-A)
// plus the gates real data needs (low-pass, minimum step interval, walking gate, bout gate).
#pragma once
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "pdnav/geo/samples.h"

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
  double lowpass_hz = 3.0;             // 2x first-order low-pass of |a| before quantising (0 = off)
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
  double max_step_interval_s = 1.3;    // longer pause ends the bout (cadence >= ~0.8 Hz)
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
};

/// Holds steps until a bout of `min_steps` regular steps is confirmed, then releases them; while
/// a bout lasts every step is released at once. Payload T carries the caller's data.
template <typename T>
class BoutGate {
 public:
  BoutGate(int min_steps, double max_interval_s) : min_steps_(min_steps), max_interval_ns_(s_to_ns(max_interval_s)) {}

  /// Adds a step at t_ns; returns the steps released by it (possibly several, possibly none).
  std::vector<T> push(TimeNs t_ns, T payload) {
    std::vector<T> out;
    if (have_last_ && t_ns - last_t_ns_ > max_interval_ns_) end_bout();
    have_last_ = true;
    last_t_ns_ = t_ns;
    if (in_bout_) {
      out.push_back(std::move(payload));
      return out;
    }
    pending_.push_back(std::move(payload));
    if (static_cast<int>(pending_.size()) >= min_steps_) {
      in_bout_ = true;
      out.assign(std::make_move_iterator(pending_.begin()), std::make_move_iterator(pending_.end()));
      pending_.clear();
    }
    return out;
  }
  /// Ends the current bout (e.g. after a gap); unconfirmed steps are discarded.
  void end_bout() {
    discarded_ += static_cast<std::int64_t>(pending_.size());
    pending_.clear();
    in_bout_ = false;
    have_last_ = false;
  }
  std::int64_t discarded() const { return discarded_; }
  bool in_bout() const { return in_bout_; }

 private:
  int min_steps_;
  TimeNs max_interval_ns_;
  std::vector<T> pending_;
  bool in_bout_ = false;
  bool have_last_ = false;
  TimeNs last_t_ns_ = 0;
  std::int64_t discarded_ = 0;
};

/// Level-crossing step detector on the acceleration magnitude (APT Sec. V-A). Incremental:
/// O(1) per sample; the running mean/std use sums over a time window.
class StepDetector {
 public:
  explicit StepDetector(const StepDetectorOptions& options = {});

  /// Feeds one accelerometer sample; returns a raw step candidate when a period completes.
  /// Candidates are not yet bout-gated: use BoutGate (as Pdr and count_steps do).
  std::optional<StepCandidate> feed(const AccelSample& s);
  /// Clears all state but the counters (called on gaps).
  void reset();

  const SampleCounters& counters() const { return counters_; }
  const StepDetectorOptions& options() const { return opt_; }

 private:
  struct Windowed {
    TimeNs t_ns;
    double value;
  };
  enum class Symbol { kUndefined, kLow, kHigh };
  double filter(double magnitude, double dt_s);
  void push_window(TimeNs t_ns, double value);
  Symbol quantise(double value) const;
  std::optional<StepCandidate> on_symbol(Symbol sym, TimeNs t_ns, double value);

  StepDetectorOptions opt_;
  SampleCounters counters_;
  bool have_last_ = false;
  TimeNs last_t_ns_ = 0;
  // low-pass state
  bool filter_init_ = false;
  double lp1_ = 0.0, lp2_ = 0.0;
  // running statistics
  std::deque<Windowed> window_;
  double sum_ = 0.0, sum_sq_ = 0.0;
  std::int64_t pushes_since_resum_ = 0;  // the sums are recomputed now and then (rounding drift)
  // symbol state machine
  Symbol last_defined_ = Symbol::kUndefined;
  double period_max_ = 0.0, period_min_ = 0.0;
  bool have_step_ = false;
  TimeNs last_step_ns_ = 0;
  double typical_interval_s_ = 0.0;  // running average of in-bout step intervals (0 = none yet)
};

/// Offline helper: runs detector + bout gate over a whole recording, returns the step times.
std::vector<StepCandidate> detect_steps(const std::vector<AccelSample>& samples,
                                        const StepDetectorOptions& options,
                                        SampleCounters* counters = nullptr);

}  // namespace pdnav::pdr
