// Phone placement and walking direction in the phone frame, from the motion alone (issue 16).
//
// Gravity-aligned frame: "up" = mean specific force over `gravity_window_s`. Placement from the
// gravity direction in phone axes: screen up/down (|up.z| >= flat_min) = held flat in front
// (texting); top up/down (|up.y| >= upright_min) = upright (chest, shirt pocket, armband, at
// the ear); anything else = "other" (trouser pocket, swinging hand, bag).
// Walking direction: the phone axis the body carries it with (flat: +Y, top ahead; upright:
// -Z, camera ahead) as the prior, because people hold phones square to the body (on the 43
// hand-held ILC walks the principal axis of horizontal acceleration is 32 deg off +Y median,
// the prior is within a few degrees, docs/pdr.md); forward/backward from the vertical-forward
// phase: the forward acceleration leads the vertical one by about a quarter step
// (corr(a_f(t), a_v(t + tau)) > 0, positive on 42 of the 43 ILC walks; Combettes & Renaudin,
// "Comparison of misalignment estimation techniques between handheld device and walking
// directions", IPIN 2015, use the same phase relation). For "other" placements the direction
// is that lagged correlation vector itself, c = E[a_h(t) a_v(t + tau)] (no axis prior). A flat
// phone may be held in landscape (+-X ahead): with a gyroscope its line is the square axis
// across the hand's dominant pitch axis (flat_square_axis).
// The vertical/horizontal split of each sample uses the instantaneous gravity direction of a
// gyro-propagated tilt filter (complementary filter on the gravity vector, Mahony, Hamel,
// Pflimlin, "Nonlinear complementary filters on the special orthogonal group", IEEE TAC 2008;
// the rotation-matrix levelling of RMPCA, Deng et al., Sensors 2015): in a pocket or a
// swinging hand the phone tilts by tens of degrees every stride, and with the 2 s mean as
// "up" that tilt leaks gravity (9.8 sin(tilt) m/s^2) into the horizontal acceleration and
// swamps the gait (pockets 30-160 deg off). Without a gyroscope, and for a flat phone (see
// placement.cpp), the 2 s mean is used. The upright prior axis (-Z) stands only while the
// motion's direction is within prior_max_angle_rad of its line (a phone at the ear or in a
// trouser pocket is upright too, but walks along +-X or obliquely).
// Limb carries (pocket, swinging hand): the walking direction is square to the dominant
// horizontal axis of the gait rotation (rotation_axis_max_ratio), signed by the correlation.
// One constant offset per placement bout; a bout ends when the gravity direction in phone
// axes moves by more than change_angle_rad for change_hold_s (the phone was moved).
#pragma once
#include <algorithm>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/samples.h"
#include "pdnav/geo/units.h"
#include "pdnav/pdr/time_window.h"

namespace pdnav::pdr {

enum class Placement { kUnknown, kFlat, kUpright, kOther };
const char* to_string(Placement p);

struct PlacementOptions {
  double gravity_window_s = 2.0;       // mean of the accelerometer over about two strides
  double flat_min = 0.6;               // |up.z| the largest and >= this (53 deg tilt): screen up/down
  // ... and a phone held in front at any pitch is that placement too: screen toward the sky by
  // at least 90 deg - held_front_max_pitch_rad (up.z >= cos(pitch)), top edge at or above the
  // horizon (up.y >= 0), rolled by less than held_front_max_roll_rad (|up.x| <= sin(roll)). A
  // hand-held phone is held square to the body whatever its pitch (reading at 28-65 deg is
  // common), so its top edge's horizontal projection is the walking direction and the hand's
  // pitch at the step frequency the phase signature, as for a phone held flat; with |up.z| the
  // largest alone, a pitch above 53 deg made it "upright", levelled, and its weaker levelled
  // correlation reversed or turned walks (ILC walks rotated by 50 deg: 2.43 -> 3.60 m).
  double held_front_max_pitch_rad = 70 * kDegToRad;
  double held_front_max_roll_rad = 30 * kDegToRad;
  double upright_min = 0.6;            // |up.y| the largest and >= this: top up/down
  double change_angle_rad = 40 * kDegToRad;  // gravity moved this far in phone axes ...
  double change_hold_s = 1.5;          // ... for this long: a new placement bout
  double phase_lag_s = 0.14;           // a quarter of a 0.55 s step (1.8 Hz cadence)
  double gait_highpass_hz = 0.6;       // first-order high-pass of the linear acceleration (0 = off)
  // Once the walker's cadence is known (set_step_interval), the linear acceleration entering the
  // phase correlation is band-passed about the step frequency instead (a second-order band-pass
  // of this Q: 1.41 = one octave, 0.71-1.41 x the step frequency): the anterior-posterior
  // acceleration and its lead over the vertical live at the step frequency, the medio-lateral
  // sway at the stride frequency, half of it (Kourogi & Kurata, "A method of pedestrian dead
  // reckoning for smartphones using frequency domain analysis on patterns of acceleration and
  // angular velocity", IEEE/ION PLANS 2014). 0 = off (the high-pass throughout).
  double step_band_q = 1.41;
  double flip_corr = -0.25;            // flat/upright prior reversed only below this correlation
  double flip_settle_s = 4.0;          // ... after this much walking; before, below flip_corr sqrt(settle / t)
  double min_bout_s = 2.0;             // correlation trusted after this much walking in a bout
  // Steps taken before that (the first steps of a bout) are held by Pdr at most this long for
  // the direction, then re-projected with it (docs/pdr.md "First steps"); 0 = no waiting.
  double max_direction_wait_s = 4.5;  // > flip_settle_s: a weak reversal is still waited for
  // A step that goes out before its bout's direction is decided (the wait ran out) takes the
  // prior or the previous bout's direction, which is the other axis of a square-held phone as
  // often as not: its heading sigma is at least this (measured: the 35 such steps of the 14
  // TYREX recordings are 89.8 deg RMS off the capture's direction, the others 33.9 deg)
  double undecided_direction_sigma_rad = 90 * kDegToRad;
  // ... but only while the motion contradicts the placement's prior axis: after this much
  // walking with a positive phase correlation along the prior, the prior stands (no wait).
  double prior_confirm_s = 0.5;
  // Tilt filter: the gyro-propagated gravity is pulled toward the accelerometer with this time
  // constant (Mahony et al. 2008: a crossover well below the gait, above gyro drift).
  double tilt_tau_s = 1.0;
  double gyro_max_age_s = 0.1;  // a gyro sample older than this is not used to propagate
  // The upright prior axis is replaced by the motion's direction when that lies further than
  // this from the prior's line, after this much walking (halfway between the axes).
  double prior_max_angle_rad = 45 * kDegToRad;
  double prior_check_s = 4.0;
  // Limb carries (trouser pocket, swinging hand): the gait turns the phone about the body's
  // medio-lateral axis (hip / shoulder flexion), a horizontal axis square to the walk. The
  // walking direction is then up x (the dominant axis of the levelled, gait-band angular rate),
  // signed by the phase correlation (docs/pdr.md "Rotation axis"). Used when that axis
  // dominates: second / largest eigenvalue of sum w_h w_h^T below rotation_axis_max_ratio
  // (TYREX pockets and swinging 0.12-0.36, phone at the ear 0.57-0.80); 0 = off.
  double rotation_axis_max_ratio = 0.5;
  // Without a gyroscope the rotation is read from the magnetometer: the Earth's field is fixed
  // in the world, so its direction m in phone axes turns as dm/dt = m x w, and w minus its part
  // along m is -(m x dm/dt) / |m|^2 (the "virtual gyroscope" of gyro-less phones; the rate
  // about the field itself is not observable, at mid latitudes the field is 60-70 deg from the
  // horizontal gait axes). The field's direction is low-passed by two first-order sections at
  // this cut-off (the gait's rotation lives below it, the sensor noise above) and the rate
  // stands in for the gyroscope in the tilt filter and the rotation axis; 0 = off.
  double mag_rate_lowpass_hz = 4.0;
  double mag_rate_start_s = 1.0;  // ... once the field has come this long without a gyroscope sample
  // ... while the field's magnitude holds within this fraction of its mean over the last
  // mag_steady_tau_s (first-order): near iron or a magnet the field turns as the phone moves
  // through it, not only as it rotates, and its magnitude changes with it (the quasi-static
  // field test of the compass, Afzal et al. 2011, applied to the rate)
  double mag_steady_tolerance = 0.05;
  double mag_steady_tau_s = 1.0;
};

/// A placement bout: from t_start_ns to t_end_ns (last sample so far for the open one).
struct PlacementBout {
  TimeNs t_start_ns = 0;
  TimeNs t_end_ns = 0;
  Placement placement = Placement::kUnknown;
  Eigen::Vector3d forward_phone = Eigen::Vector3d::UnitY();  // walking direction, phone axes
  double phase_corr = 0.0;  // normalised vertical-forward correlation along forward_phone
  /// RMS angle (deg) between the instantaneous gravity (tilt filter) and its 2 s mean while
  /// walking: how much the phone tilts back and forth with the gait (nan without a gyroscope).
  double tilt_swing_deg = kNaN;
};

class PlacementEstimator {
 public:
  explicit PlacementEstimator(const PlacementOptions& options = {});
  /// Feeds one accelerometer sample (phone axes, m/s^2). walking: the caller's gate (steps
  /// are being counted), so the correlations only learn from gait.
  void feed(const AccelSample& s, bool walking);
  /// Feeds one gyroscope sample (phone axes, rad/s): propagates the tilt between accelerometer
  /// samples. Without gyroscope samples the 2 s mean of the accelerometer is "up".
  void feed(const GyroSample& s);
  /// Feeds one magnetometer sample (phone axes, uT, hard iron removed): on a phone without a
  /// gyroscope its turning stands in for the angular rate (PlacementOptions::mag_rate_lowpass_hz).
  /// Returns the rate read from it (phone axes, rad/s, its part along the field missing), if any.
  std::optional<Eigen::Vector3d> feed(const MagSample& s);
  /// Ends the current bout (e.g. the phone was handled); the next sample starts a new one.
  void end_bout();
  /// A step interval (s) from the step detector: the step band follows the walker's cadence
  /// (median of the latest five; values outside 0.2-1.2 s are ignored).
  void set_step_interval(double interval_s);
  /// The step frequency the band is tuned to (Hz), 0 before any step interval.
  double step_frequency_hz() const { return step_frequency_hz_; }

  bool ready() const { return have_up_; }
  /// A placement bout is open (false before the first and between a handling span and the next).
  bool in_bout() const { return in_bout_; }
  const Eigen::Vector3d& up_phone() const { return up_; }
  Placement placement() const { return bout_.placement; }
  /// Walking direction in phone axes for the current bout (unit, horizontal at bout start).
  const Eigen::Vector3d& forward_phone() const { return bout_.forward_phone; }
  /// The phone axis (+X, +Y or -Z) most horizontal at the start of the bout: the heading
  /// filter follows it, the walking direction is an offset from it (fixed per bout).
  const Eigen::Vector3d& reference_phone() const { return reference_; }
  /// Increments at every new bout (the reference axis may have changed).
  std::int64_t revision() const { return revision_; }
  /// Clockwise angle (rad) from the horizontal projection of reference_phone() to that of
  /// forward_phone() under the current gravity; 0 when either is near vertical.
  double forward_offset_rad() const;
  /// The walking direction of the current bout is decided: without a prior axis ("other"), after
  /// min_bout_s of walking; with one, the motion supports it (a flat phone's sign after
  /// prior_confirm_s; an upright phone's line, tested after prior_check_s: at the ear or in a
  /// trouser pocket it is upright too and walks along +-X), or it contradicts it and the prior
  /// has been reversed (after min_bout_s) or the evidence has settled (flip_settle_s) without a
  /// reversal.
  bool direction_known() const {
    if (!in_bout_) return false;
    // no prior axis (placement "other"): the direction is the correlation itself, trusted at min_bout_s
    if (!prior_applies()) return walking_s_ >= opt_.min_bout_s;
    if (prior_supported_)
      return walking_s_ >= (bout_.placement == Placement::kUpright ? std::max(opt_.prior_confirm_s, opt_.prior_check_s) : opt_.prior_confirm_s);
    // the motion contradicts the prior: known once reversed, or once the evidence has settled
    return walking_s_ >= opt_.flip_settle_s || (walking_s_ >= opt_.min_bout_s && reversed_);
  }
  /// The bout's prior axis (flat/upright) is in use: not replaced by the motion's direction.
  bool prior_applies() const {
    return (bout_.placement == Placement::kFlat || bout_.placement == Placement::kUpright) && !prior_rejected_;
  }
  /// The levelled tilt filter is running (gyroscope seen); "up" of the last sample.
  bool levelled() const { return tilt_ok_; }
  /// Every bout so far (closed ones and the open one last).
  std::vector<PlacementBout> bouts() const;

 private:
  void start_bout(TimeNs t_ns);
  void update_forward();
  Eigen::Vector3d gait_band(const Eigen::Vector3d& lin, double dt_s);
  // the band-pass about the step frequency (RBJ biquad, direct form I, coefficients per sample)
  Eigen::Vector3d step_band(const Eigen::Vector3d& lin, double dt_s);
  // the walking direction from the dominant horizontal gait rotation axis (unsigned), if any
  std::optional<Eigen::Vector3d> rotation_axis_forward() const;
  // a flat phone's walking line: portrait (+Y) or landscape (+-X), from the gait rotation
  Eigen::Vector3d flat_square_axis() const;
  // the gait rotation's dominant horizontal axis (rotation_axis_max_ratio), if any
  std::optional<Eigen::Vector3d> dominant_rotation_axis() const;
  // one angular rate sample (phone axes, rad/s), from the gyroscope or the magnetometer
  void feed_rate(TimeNs t_ns, const Eigen::Vector3d& rate_radps);
  double flip_threshold() const;

  PlacementOptions opt_;
  TimeWindowSum<Eigen::Vector3d> win_;  // specific force over gravity_window_s
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitZ();
  bool have_up_ = false;
  bool have_last_ = false;
  TimeNs last_ns_ = 0;
  // bout
  bool in_bout_ = false;
  PlacementBout bout_;
  std::vector<PlacementBout> closed_;
  Eigen::Vector3d bout_up_ = Eigen::Vector3d::UnitZ();
  TimeNs moved_since_ns_ = -1;
  std::int64_t revision_ = 0;
  Eigen::Vector3d reference_ = Eigen::Vector3d::UnitY();
  // lagged correlation: vertical now x horizontal tau ago (phone axes)
  struct Lagged {
    TimeNs t_ns;
    Eigen::Vector3d h;       // horizontal linear acceleration (gait band)
    Eigen::Vector3d h_band;  // ... about the step frequency
    bool band;               // the step band was settled
  };
  std::deque<Lagged> hist_;
  Eigen::Vector3d corr_band_ = Eigen::Vector3d::Zero();  // the lagged correlation in the step band
  Eigen::Matrix3d cov_h_band_ = Eigen::Matrix3d::Zero();
  double var_v_band_ = 0.0, band_walking_s_ = 0.0;
  Eigen::Vector3d corr_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d hp_in_ = Eigen::Vector3d::Zero(), hp_out_ = Eigen::Vector3d::Zero();
  std::deque<double> step_intervals_s_;  // the latest step intervals (set_step_interval)
  double step_frequency_hz_ = 0.0;       // 1 / their median (0: none yet, or the band is off)
  Eigen::Vector3d bp_x1_ = Eigen::Vector3d::Zero(), bp_x2_ = Eigen::Vector3d::Zero();  // band-pass inputs
  Eigen::Vector3d bp_y1_ = Eigen::Vector3d::Zero(), bp_y2_ = Eigen::Vector3d::Zero();  // ... and outputs
  double bp_settle_s_ = 0.0;  // time the band-pass has run since its last restart
  bool reversed_ = false;  // the bout's prior axis has been reversed
  double var_v_ = 0.0, n_corr_ = 0.0;
  Eigen::Matrix3d cov_h_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d cov_w_ = Eigen::Matrix3d::Zero();  // levelled gait-band angular rate, walking (phone axes)
  Eigen::Vector3d sum_up_walk_ = Eigen::Vector3d::Zero();  // tilt filter's up while walking (phone axes)
  double swing_sq_ = 0.0, swing_n_ = 0.0;  // tilt swing while walking (PlacementBout::tilt_swing_deg)
  Eigen::Vector3d w_hp_in_ = Eigen::Vector3d::Zero(), w_hp_out_ = Eigen::Vector3d::Zero();
  TimeNs w_hp_ns_ = -1;
  double walking_s_ = 0.0;
  bool prior_supported_ = false;  // running phase correlation along the prior axis > 0
  bool prior_rejected_ = false;   // the motion's direction is off the prior's line
  Eigen::Vector3d flat_axis_ = Eigen::Vector3d::UnitY();  // a flat bout's prior axis (flat_square_axis)
  bool bout_levelled_ = false;    // the bout's correlation is split about the tilt filter's gravity
  // tilt filter (gravity direction in phone axes, gyro-propagated)
  Eigen::Vector3d tilt_up_ = Eigen::Vector3d::UnitZ();
  bool tilt_ok_ = false;
  Eigen::Vector3d gyro_radps_ = Eigen::Vector3d::Zero();
  TimeNs gyro_ns_ = -1;
  TimeNs tilt_ns_ = -1;
  bool have_gyro_ = false;  // a gyroscope sample has come (the magnetometer's rate is not used then)
  // the magnetometer's rate: the field's direction, low-passed (two first-order sections), and
  // the mean of its magnitude (the steadiness test)
  Eigen::Vector3d mag_lp1_ = Eigen::Vector3d::Zero(), mag_lp2_ = Eigen::Vector3d::Zero();
  bool mag_lp_running_ = false;  // the direction filter holds the previous steady reading
  TimeNs mag_ns_ = -1, first_mag_ns_ = -1;  // the last and first magnetometer samples
  double mag_norm_mean_ut_ = 0.0;
};

}  // namespace pdnav::pdr
