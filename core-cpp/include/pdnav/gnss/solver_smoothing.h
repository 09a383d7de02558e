// Carrier-smoothed code (Hatch filter; RTCA DO-229 100 s smoothing window): each pseudorange
// is averaged with the previous smoothed value propagated by the carrier-phase (ADR) change,
// or by the integrated pseudorange rate (Doppler smoothing) when ADR is missing, reset or
// slipped. Code noise of a phone is white at the 1 s rate, so this cuts it by ~sqrt(window).
#pragma once
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "pdnav/gnss/noise_model.h"
#include "pdnav/gnss/types.h"

namespace pdnav::gnss {

struct SmoothingOptions {
  double window_s = 100.0;          // RTCA DO-229 (100 s); 0 disables smoothing
  double max_jump_m = 60.0;         // |code - propagated| above this restarts the satellite (slip / code error)
  /// Remove the epoch's common code-minus-carrier step (median over satellites) before the
  /// per-satellite test: a receiver clock step that moves the code but not the carrier (an
  /// Android FullBiasNanos/BiasNanos step, a RINEX file whose phase is on another clock, a
  /// clock discontinuity) is common to all satellites; a slip or multipath is not.
  bool remove_common_step = true;
  int min_sats_common_step = 4;     // fewer continuous satellites: no common-step estimate
  bool doppler_through_clock_breaks = true;  // keep smoothing by Doppler across a hardware clock discontinuity
  /// Averaging window of the dual-frequency ionosphere correction (s); 0 = the raw IF code.
  /// The L1 ionosphere changes by < 0.1 m per minute outside storms (Klobuchar's diurnal cosine
  /// at 10-50 m peak-to-peak vertical L1 delay over ~12 h), measured effect in docs/gnss.md.
  double iono_window_s = 300.0;
  double iono_max_jump_m = 10.0;    // a larger change of the IF correction restarts its average
};

/// One satellite's inputs at an epoch (NaN when missing).
struct SmoothingInput {
  SatId sat;
  double pseudorange_m = 0.0;
  double adr_m = 0.0;               // NaN unless valid and not reset / slipped
  double pr_rate_mps = 0.0;
  /// The code is the ionosphere-free combination (smoothed with the L1 carrier: the code-carrier
  /// divergence is 1 x the L1 ionosphere rate instead of 2 x); a change of this flag between
  /// epochs restarts the satellite (the code moves by its ionosphere).
  bool iono_free = false;
  /// With iono_free: the L1 code the IF code was formed from. The IF correction
  /// (pseudorange_m - pseudorange_l1_m, i.e. minus the satellite's relative L1 ionosphere) is
  /// averaged over iono_window_s before it is added to the L1 code: the ionosphere changes
  /// slowly, so this removes most of the 2.6x noise amplification of the IF combination.
  double pseudorange_l1_m = 0.0;
  /// The band of the code and carrier (FrequencyMode::kBest switches a satellite between L1
  /// and L5 when it gains or loses L5): a change restarts the satellite.
  SignalBand band = SignalBand::kL1;
  /// The code's white (C/N0) noise variance (m^2) and the pseudorange rate's variance
  /// ((m/s)^2): what an epoch propagated by Doppler adds to the smoothed code, relative to the
  /// code's own noise (white_variance_ratio). NaN: not known (a Doppler epoch then does not
  /// lower the ratio).
  double white_var_m2 = std::numeric_limits<double>::quiet_NaN();
  double rate_var_m2ps2 = std::numeric_limits<double>::quiet_NaN();
};

class CodeSmoother {
 public:
  explicit CodeSmoother(SmoothingOptions opt = {}) : opt_(opt) {}
  /// Starts a new epoch `dt_s` after the previous one; `clock_jump_m` = c * change of
  /// (FullBiasNanos + BiasNanos), which moves the code but not the carrier. A non-positive
  /// dt_s (gap) restarts every satellite. `carrier_broken` (a hardware clock discontinuity:
  /// carrier phase lost, code re-clocked) keeps the satellites but propagates them by Doppler
  /// only; the code's jump is then taken by the common-step removal (pass clock_jump_m = 0).
  void begin_epoch(double dt_s, double clock_jump_m, bool carrier_broken = false);
  /// Smoothed pseudorange of one satellite at this epoch; `reason` is set when it restarted
  /// for a reason worth counting ("code-carrier jump").
  double smooth(const SmoothingInput& in, std::string* reason = nullptr);
  /// All satellites of the epoch at once (after begin_epoch): with remove_common_step the
  /// median code-minus-propagation step is removed first. Returns one value per input;
  /// `reasons` (optional) gets one entry per input ("" when nothing to count).
  std::vector<double> smooth_epoch(const std::vector<SmoothingInput>& in, std::vector<std::string>* reasons = nullptr);
  /// The share of a satellite's white (C/N0) code noise variance left in its smoothed code after
  /// its last smooth(), the Hatch recursion's variance r_k = (1 - 1/n)^2 (r_k-1 + q) + 1/n^2:
  /// 1 for raw code; with a carrier (q = 0) 1/n after n epochs and 1/(2N-1) once the window N
  /// is full; an epoch propagated by Doppler adds q = rate variance dt^2 / white variance (the
  /// mean of two rates: each rate enters two steps at half weight, so the propagation's random
  /// walk grows by one rate variance per epoch). Satellite not smoothed at this epoch: 1.
  double white_variance_ratio(const SatId& sat) const;
  /// The common step removed at the last smooth_epoch (m), 0 when none.
  double last_common_step_m() const { return common_step_m_; }
  void reset() { sats_.clear(); }

 private:
  struct Sat {
    double pr_sm_m = 0.0, adr_m = 0.0, pr_rate_mps = 0.0;
    double n = 0.0;
    double white_ratio = 1.0;  // see white_variance_ratio
    std::int64_t epoch = -1;
    bool iono_free = false;
    SignalBand band = SignalBand::kL1;
    double iono_corr_m = 0.0, iono_n = 0.0;  // averaged IF correction and its sample count
  };
  SmoothingOptions opt_;
  std::map<SatId, Sat> sats_;
  std::int64_t epoch_ = 0;
  double dt_s_ = 0.0;
  double clock_jump_m_ = 0.0;
  bool carrier_broken_ = false;
  double common_step_m_ = 0.0;
  /// code - propagated for a continuous satellite, NaN otherwise
  double innovation(const SmoothingInput& in) const;
  /// The input with its IF correction replaced by the running average (iono_window_s).
  SmoothingInput with_iono_average(const SmoothingInput& in);
};

}  // namespace pdnav::gnss
