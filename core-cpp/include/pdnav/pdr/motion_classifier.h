// Motion classifier that gates the step detector (issue 16): walking / standing / phone
// handled or waved. Window features after Susi, Renaudin, Lachapelle, "Motion mode recognition
// and step detection algorithms for mobile phone users", Sensors 13(2), 2013 (variance of
// the acceleration norm, energy of the angular rate), plus the spread of the rotation axis:
// walking rotates a carried phone about one axis (arm or thigh swing, gait sway), a waved
// phone (the figure-eight compass calibration, turning it over, picking it up) about several.
// Without a gyroscope nothing is called handling (no evidence), so accelerometer-only data
// (the Oxford walks) are gated exactly as before.
#pragma once
#include <cstdint>
#include <deque>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/samples.h"
#include "pdnav/geo/units.h"

namespace pdnav::pdr {

enum class MotionState { kStanding, kWalking, kHandling };
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
  double gyro_timeout_s = 0.5;        // no gyro sample for this long: no handling evidence
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
  MotionState state() const { return state_; }
  /// True when t_ns lies inside a handling span (closed, or the open one).
  bool handling_at(TimeNs t_ns) const;
  /// Handling spans so far (bounded to the last 256).
  const std::deque<MotionSpan>& handling_spans() const { return spans_; }
  double rate_rms_radps() const { return rate_rms_; }
  double axis_spread() const { return spread_; }

 private:
  void update(TimeNs t_ns);

  MotionClassifierOptions opt_;
  std::deque<std::pair<TimeNs, double>> acc_;  // |a|
  double acc_sum_ = 0.0, acc_sq_ = 0.0;
  std::deque<std::pair<TimeNs, Eigen::Vector3d>> gyro_;
  Eigen::Matrix3d gyro_outer_ = Eigen::Matrix3d::Zero();
  TimeNs last_gyro_ns_ = -1;
  TimeNs last_acc_ns_ = -1;
  double rate_rms_ = 0.0, spread_ = 0.0;
  MotionState state_ = MotionState::kStanding;
  bool handling_raw_ = false;
  TimeNs handling_last_ns_ = -1;
  std::deque<MotionSpan> spans_;
  bool span_open_ = false;
};

}  // namespace pdnav::pdr
