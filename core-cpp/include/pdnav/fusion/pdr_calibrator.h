// PDR calibration from GNSS: step-length scale and heading bias over a sliding window, in the
// style of Walker et al., Remote Sensing 2019, Sec. 3 (Eq. 9: the PDR step length and heading
// are corrected from the GNSS track over a sliding window while GNSS is good). We solve the
// window in closed form: with 2-D positions as complex numbers z = e + i n, a PDR track P_k
// (integrated from the raw steps) and GNSS positions G_k satisfy G_k = a + c P_k + noise with
// c = s exp(i b): s the step-length scale, b the heading bias (measured heading = true + b).
// Weighted least squares gives c, its variance (inflated for time-correlated GNSS errors) and
// so s, b with 1-sigma values (docs/fusion.md).
#pragma once
#include <complex>
#include <cstdint>
#include <deque>

#include <Eigen/Core>

#include "pdnav/geo/events.h"
#include "pdnav/geo/units.h"

namespace pdnav::fusion {

struct PdrCalibrationOptions {
  double window_s = 300.0;            // Walker 2019 Sec. 3: sliding window (5 min here)
  double min_baseline_m = 20.0;       // RMS spread of the PDR track in the window before publishing
  int min_epochs = 20;                // GNSS epochs in the window before publishing
  double correlation_time_s = 10.0;   // GNSS error correlation (multipath): N_eff <= time moving / this
  bool residual_correlation = true;   // N_eff also <= N / the residuals' integrated autocorrelation time
  bool check_bias_drift = true;       // fit the two halves of the window: how far the bias moved
  bool independent_heading = true;    // false: one publication test on both sigmas (before issue 28)
  /// Published when it knows the scale and the heading bias better than the fused filter's
  /// prior (18 %, 10 deg: FusionFilterOptions); the filter then carries the fit's own sigmas,
  /// so a less certain calibration is used with its honest uncertainty.
  double max_scale_sigma = 0.18;
  double max_heading_bias_sigma_rad = 10.0 * kDegToRad;
  double prior_heading_bias_sigma_rad = 10.0 * kDegToRad;  // = FusionFilterOptions::initial_heading_bias_sigma_rad
  double min_scale = 0.5, max_scale = 1.8;  // a fit outside is not a calibration (wrong data)
  /// The GNSS course over ground (Android Location bearing: the direction of the Doppler
  /// velocity, independent of the position errors) against the PDR track's direction just
  /// before it is a direct sample of the heading bias, combined with the position fit's by
  /// inverse variance. Without a stated bearing accuracy its sigma is the velocity error over
  /// the speed, atan(course_velocity_sigma_mps / speed): 0.3 m/s (measured on the shared ETH
  /// walk: the bearing scatters 5-16 deg about the PDR direction at 1.0-1.2 m/s). The samples are
  /// time-correlated like the positions (correlation_time_s, their residuals' autocorrelation).
  bool use_course = true;
  double course_velocity_sigma_mps = 0.3;
  double course_min_speed_mps = 0.6;      // below this a walker's course is mostly noise
  double course_pdr_span_s = 3.0;         // the PDR direction is taken over this span before the fix
  double course_min_straightness = 0.9;   // and only where that path is straight (net / path length)
  int course_min_epochs = 10;             // course samples in the window before they are used
  /// The GNSS speed (Doppler: Location speed, TDCP/Doppler displacement) against the PDR speed
  /// over the same straight span is a direct sample of the step scale, as the course is of the
  /// heading bias: log(v_gnss * span / PDR path), 1-sigma from the speed's error and the step
  /// count's quantisation (1/sqrt(12) step of the steps in the span). It needs no baseline, so
  /// a calibration is published on a short straight walk where the position fit cannot be;
  /// combined with the position fit's scale by inverse variance.
  bool use_speed = true;
  std::size_t max_steps_kept = 4096;  // bound on the step history (memory)
};

struct PdrCalibration {
  bool valid = false;                 // published (passed the checks above)
  TimeNs t_ns = 0;                    // time of the last GNSS epoch used
  double scale = 1.0;                 // true step length = scale * PDR step length
  double heading_bias_rad = 0.0;      // PDR heading = true heading + bias
  double scale_sigma = 0.0;
  double heading_bias_sigma_rad = 0.0;
  bool heading_applied = true;        // false: the heading fit was too uncertain, bias 0 +- the prior
  int epochs = 0;                     // GNSS epochs in the window
  double baseline_m = 0.0;            // RMS spread of the PDR track in the window
  double residual_tau = 1.0;          // integrated autocorrelation time of the fit residuals, epochs (N_eff = N / tau)
  double span_s = 0.0;                // time from the first to the last epoch of the window
  /// How far the heading bias moved within the window: the two halves of the PDR path fitted
  /// separately differ by this beyond their own sigmas (0 when they agree).
  double heading_bias_drift_sigma_rad = 0.0;
  int course_epochs = 0;              // course samples in the window (0: heading from positions only)
  double course_bias_rad = 0.0;       // their heading bias, before combining with the position fit's
  double course_bias_sigma_rad = 0.0;
  int speed_epochs = 0;               // speed samples in the window (0: scale from positions only)
  double speed_scale = 1.0;           // their step scale, before combining with the position fit's
  double speed_scale_sigma = 0.0;
  bool positions_used = false;        // the position fit entered (its baseline reached min_baseline_m)
};

class PdrCalibrator {
 public:
  explicit PdrCalibrator(const PdrCalibrationOptions& opt = {}) : opt_(opt) {}
  /// A raw (uncalibrated) PDR step; advances the integrated PDR track.
  void add_step(const PdrStep& raw_step);
  /// A GNSS position (local east/north, 1-sigma per axis) accepted by the fusion filter; it is
  /// paired with the PDR track at the same time (steps after t_ns are not counted).
  void add_gnss(TimeNs t_ns, const Eigen::Vector2d& en_m, double sigma_m);
  /// The GNSS course over ground at t_ns (clockwise from north) and speed, with the course's
  /// 1-sigma if the receiver states one (NaN or <= 0: from the speed, course_velocity_sigma_mps).
  /// Call before add_gnss of the same epoch; a slow or turning epoch is not used.
  void add_course(TimeNs t_ns, double course_rad, double speed_mps, double sigma_rad);
  /// The GNSS speed at t_ns with its 1-sigma (NaN or <= 0: course_velocity_sigma_mps): a
  /// step-scale sample under the same conditions as add_course.
  void add_speed(TimeNs t_ns, double speed_mps, double sigma_mps);
  /// Forget everything (e.g. the user changed the phone's placement).
  void reset();
  /// The latest fit (valid only once it passes the publication checks).
  const PdrCalibration& calibration() const { return last_; }
  /// The latest published calibration (kept through outages and until a better fit).
  const PdrCalibration& published() const { return published_; }
  const PdrCalibrationOptions& options() const { return opt_; }

 private:
  struct Pair { TimeNs t_ns; std::complex<double> p, g; double w; };
  struct Series { TimeNs t_ns; double value, w; };  // a course (bias, rad) or speed (log scale) sample
  std::complex<double> pdr_at(TimeNs t_ns) const;
  /// The raw PDR path over the course_pdr_span_s before t_ns: net displacement, path length and
  /// steps; false where that path is not kept, has no step or is not straight.
  bool straight_span(TimeNs t_ns, std::complex<double>* net, double* path_m, int* steps) const;
  void forget_before_window(TimeNs t_ns);  // positions, course and speed samples older than window_s
  void fit();

  PdrCalibrationOptions opt_;
  std::complex<double> track_ = 0.0;                       // integrated raw PDR position
  std::deque<std::pair<TimeNs, std::complex<double>>> steps_;  // (t, track after the step)
  std::deque<Pair> window_;
  std::deque<Series> courses_, speeds_;
  PdrCalibration last_, published_;
};

}  // namespace pdnav::fusion
