// Gyro-dominant heading (issue 16): the gyro carries the heading between absolute readings;
// the absolute heading (rotation vector, else tilt-compensated compass) only sets the offset
// between the integrated gyro yaw and north, as a weighted circular mean over the last tau_s.
// The offset is fitted as a straight line in time (weighted least squares), so a residual gyro
// bias about the vertical is estimated too, with its own long memory and a prior that keeps a
// field changing along the walk out of it (options below; clamped to max_drift_radps).
// A magnetometer reading is trusted (weight 1) only when its field magnitude and dip agree
// with the WMM at the location (Afzal, Renaudin, Lachapelle, "Assessment of indoor magnetic
// field anomalies using multiple magnetometers", ION GNSS 2010, and their quasi-static field
// detector use the same two tests); a disturbed one gets disturbed_weight, so a session that
// is disturbed everywhere still converges to its average. Indoors the field is disturbed
// locally (median |B| 41 uT vs 48 uT WMM on the ILC walks): averaging the offset over tens of
// metres of walking averages the disturbances out, the gyro keeps the shape of the path.
#pragma once
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/samples.h"
#include "pdnav/geo/units.h"

namespace pdnav::pdr {

struct HeadingFusionOptions {
  double tau_s = 60.0;                    // offset memory; gyro drift ~0.2 deg/s -> <= 12 deg per tau
  double no_gyro_tau_s = 0.3;             // without a live gyro the absolute heading is followed
  double field_tolerance = 0.15;          // |B| within 15 % of the WMM total intensity
  double dip_tolerance_rad = 10 * kDegToRad;  // dip within 10 deg of the WMM inclination
  double disturbed_weight = 0.05;         // weight of a reading failing either test
  double base_sigma_rad = 15 * kDegToRad; // 1-sigma of one absolute reading
  double decorrelation_s = 5.0;           // readings closer than this are not independent
  double min_sigma_rad = 3 * kDegToRad;
  double max_drift_radps = 1.0 * kDegToRad;  // |estimated gyro yaw drift| at most (MEMS: < 0.5 deg/s)
  // The drift is a property of the gyro (stable for minutes, small on a platform-calibrated
  // gyro); a field that changes along the walk looks like drift over tens of seconds (ILC:
  // offset slopes of +-2 deg/s on 10-60 s walks, opposite signs on consecutive walks of one
  // phone, |slope| median 0.05 deg/s over the 100 s ones). So the drift has its own long memory
  // and a Bayesian prior N(0, drift_prior_sigma^2): the slope of a weighted line with residual
  // scatter s over n independent readings is shrunk by the ridge s^2 / (sigma^2 n) (at least
  // drift_prior_s^2): a clean field teaches it in seconds, a disturbed one needs minutes
  // (docs/pdr.md "Gyro drift").
  double drift_tau_s = 600.0;                       // memory of the drift fit
  double drift_prior_sigma_radps = 0.1 * kDegToRad;  // residual bias of a calibrated MEMS gyro
  double drift_prior_s = 5.0;                       // ridge floor: time spread needed to trust it
  // Consistency: mean resultant length of the offsets (1 = all agree). Below this the gyro and
  // the absolute readings contradict each other (e.g. a heading that flips 180 deg while the
  // gyro is still): the offset is unknown, the latest reading is followed (the pre-fusion
  // behaviour) until they agree again.
  double min_consistency = 0.5;
  // Android's magnetometer accuracy (SensorEventListener.onAccuracyChanged: -1 no contact,
  // 0 unreliable, 1 low, 2 medium, 3 high) is the state of its hard-iron calibration: an
  // uncalibrated compass is tens of degrees off, so such readings count as disturbed ones.
  // Multipliers of a reading's weight for accuracy 0..3 (below 0 = unreliable); no event = 1.
  double accuracy_weight[4] = {0.05, 0.25, 0.6, 1.0};
  // Quasi-static field (QSF) detection after Afzal, Renaudin, Lachapelle, "Use of Earth's
  // magnetic field for mitigating gyroscope errors regardless of magnetic perturbation",
  // Sensors 11(12), 2011: the field is trusted for heading only while it is stationary in the
  // gyro-propagated frame, i.e. while the compass heading + the integrated gyro yaw (the offset
  // c) and |B| stay constant over qsf_window_s. Outside a QSF window a reading's weight is
  // multiplied by non_qsf_weight (1 = detector off). Thresholds: docs/pdr.md ("Quasi-static field").
  double qsf_window_s = 1.0;
  double qsf_max_offset_std_rad = 3.0 * kDegToRad;
  double qsf_max_field_std_ut = 1.0;
  double non_qsf_weight = 0.1;
};

/// Quasi-static field detector (options in HeadingFusionOptions, qsf_*).
class QuasiStaticField {
 public:
  explicit QuasiStaticField(const HeadingFusionOptions& options = {}) : opt_(options) {}
  /// One magnetometer reading: offset = compass heading of the reference axis + gyro yaw, and |B|.
  void add(TimeNs t_ns, double offset_rad, double field_ut);
  void reset() { window_.clear(); }
  /// The last window_s of readings (>= 80 % covered) have a stationary offset and |B|.
  bool quasi_static() const { return qsf_; }
  double offset_std_rad() const { return offset_std_rad_; }
  double field_std_ut() const { return field_std_ut_; }

 private:
  struct Reading {
    TimeNs t_ns;
    double offset_rad, field_ut;
  };
  HeadingFusionOptions opt_;
  std::vector<Reading> window_;
  bool qsf_ = false;
  double offset_std_rad_ = kNaN, field_std_ut_ = kNaN;
};

class HeadingFusion {
 public:
  explicit HeadingFusion(const HeadingFusionOptions& options = {});
  /// The expected field (WMM total intensity in uT and inclination, down positive).
  void set_reference_field(double total_ut, double inclination_rad);
  /// Weight of a magnetometer reading (phone axes) given "up" in phone axes: 1 if it passes
  /// the magnitude and dip tests (or no reference field is known), else disturbed_weight.
  double field_weight(const Eigen::Vector3d& field_ut, const Eigen::Vector3d& up_phone) const;
  /// Weight multiplier for Android's magnetometer accuracy level (options.accuracy_weight).
  double accuracy_weight(int android_accuracy) const;
  /// The heading error a reading's field may carry (rad, 1-sigma): its horizontal part differs
  /// from the WMM's horizontal intensity H by at least q = | |B_h| - H |, and a horizontal
  /// perturbation of size q deflects the heading by about (q / H) sin(phi), phi its unknown
  /// direction: rms q / (sqrt 2 H), at most a uniform heading's (pi / sqrt 3). The vertical
  /// part turns no heading. 0 without a reference field.
  double field_deflection_sigma_rad(const Eigen::Vector3d& field_ut, const Eigen::Vector3d& up_phone) const;
  /// One absolute heading (magnetic, of the reference axis) at gyro yaw yaw_rad (left +);
  /// deflection_sigma_rad: the field's own possible error (field_deflection_sigma_rad), part of
  /// sigma_rad() as the readings' weighted mean square.
  void add(TimeNs t_ns, double heading_mag_rad, double yaw_rad, double weight, bool gyro_live,
           double deflection_sigma_rad = 0.0);
  void reset();
  /// Forgets the drift fit only (the offset stays): the readings it was learned from measured
  /// another offset (the magnetometer's calibration changed).
  void restart_drift() { trusted_ = LineSums{}; }
  bool valid() const { return weight_ > 0.0; }
  /// Magnetic heading of the reference axis at gyro yaw yaw_rad and time t_ns.
  double heading_mag_rad(double yaw_rad, TimeNs t_ns) const;
  /// Estimated drift of the gyro yaw (rad/s, of the offset c = heading + yaw).
  double drift_radps() const;
  double sigma_rad() const;
  std::int64_t accepted() const { return accepted_; }
  std::int64_t disturbed() const { return disturbed_; }

 private:
  HeadingFusionOptions opt_;
  double ref_total_ut_ = kNaN, ref_dip_rad_ = kNaN;
  // decayed weighted sums of the line fit y = a + b tau, tau = t - last_ns_ (re-anchored at
  // every reading), y = offset unwrapped around anchor_rad_
  struct LineSums {
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, y0 = 0.0, y1 = 0.0, yy = 0.0;
    void shift_and_decay(double dt_s, double decay);
    void add(double w, double y) { s0 += w, y0 += w * y, yy += w * y * y; }  // at tau = 0
  };
  double anchor_rad_ = 0.0;
  LineSums all_;      // every reading: the offset
  LineSums trusted_;  // readings that passed the tests only: the drift (a disturbance is not a slope)
  double weight_ = 0.0;                            // decayed sum of w (= all_.s0)
  Eigen::Vector2d circ_ = Eigen::Vector2d::Zero();  // decayed sum of w (cos c, sin c)
  double last_c_rad_ = 0.0;                         // the latest reading's offset
  double weight_s_ = 0.0;                          // decayed sum of w dt (information, seconds)
  double deflection2_ = 0.0;                       // decayed sum of w deflection_sigma^2
  bool have_last_ = false;
  TimeNs last_ns_ = 0;
  std::int64_t accepted_ = 0, disturbed_ = 0;
};

}  // namespace pdnav::pdr
