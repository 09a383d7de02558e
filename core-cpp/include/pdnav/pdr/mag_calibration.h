// Online hard-iron magnetometer calibration (docs/pdr.md, "Hard-iron calibration").
#pragma once
#include <cstdint>
#include <deque>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pdnav/geo/samples.h"
#include "pdnav/geo/units.h"

namespace pdnav::pdr {

// Hard iron only: readings m = h + b lie on a sphere |m - b|^2 = r^2; the linear least-squares
// form 2 m.b + c = |m|^2 (c = r^2 - |b|^2) is the first step of the sphere/ellipsoid fits in
// Vasconcelos, Elkaim, Silvestre, Oliveira, Cardeira, "Geometric approach to strapdown
// magnetometer calibration in sensor frame", IEEE Trans. Aerosp. Electron. Syst. 47(2), 2011.
// Here it is causal: time-weighted sums with exponential forgetting, and a ridge prior toward
// b = 0 (Tikhonov) so a direction the readings do not excite (the vertical of a flat phone that
// only yaws) stays uncorrected. The bias is applied once the readings span two directions (second
// eigenvalue of their covariance) and the sphere fits them; a fit that does not (a magnet, steel
// nearby: the field is disturbed, not biased) is refused and its readings are forgotten.
//
// While a gyroscope is live the bias is instead estimated with the attitude the gyro gives
// (Troni & Whitcomb, "Field sensor bias calibration with angular-rate sensors", IEEE/ASME Trans.
// Mechatronics 24(3), 2019, integrated form): the field in a frame fixed to the world is the same
// at two nearby times, R_i (m_i - b) = R_j (m_j - b) with R the gyro-integrated attitude, so
// (R_i - R_j) b = R_i m_i - R_j m_j is linear in b. Pairs 1-8 s apart, weighted least squares with
// exponential forgetting and a prior on b. A turn of a quarter circle determines the horizontal
// bias (the sphere fit needs a half turn); the direction the phone never rotates about (the
// vertical of a phone that only yaws) stays at the prior and does not move the heading.
// The gyro's own bias d (phone axes) tilts the integrated attitude by -R^T (integral of R dt) d;
// to first order a pair gains the term -[h]x (S_i - S_j) d (h the field in the world-fixed frame,
// S the integral of R), so d is estimated with b (6 unknowns, a prior on each): an uncorrected
// 0.4 deg/s bias over an 8 s pair would otherwise be a 2.7 uT error at 48 uT.
struct MagCalibrationOptions {
  bool enabled = true;
  // --- gyro-aided fit (Troni & Whitcomb 2019), used while gyro samples arrive ---
  bool gyro_aided = true;
  double max_lag_s = 8.0;            // pairs at lags 1, 2, 4, 8 s (the world field at two places
                                     // a few metres apart; gyro drift over 8 s is < 0.1 deg)
  double max_gyro_gap_s = 0.2;       // a longer gap breaks the attitude: pairs restart
  // the gyro attitude is kept this long, so a magnetometer reading that arrives late (sensor
  // batching delivers each sensor's FIFO in turn) still finds the attitude at its own time; the
  // gyro-aided fit is in use while a gyro sample is at most this far from the reading
  double gyro_history_s = 5.0;
  double prior_bias_ut = 30.0;       // prior 1-sigma of b (phone hard iron left after calibration)
  double prior_gyro_bias_radps = 0.1 * kDegToRad;  // residual bias of a calibrated MEMS gyro (as HeadingFusionOptions)
  double pair_noise_ut = 1.0;        // nominal 1-sigma of one pair's residual (two readings' noise)
  double correlation_time_s = 1.0;   // pair residuals closer than this are one (N_eff)
  // applied once the two best-determined directions of b are known to this 1-sigma (5.5 deg of
  // heading at a horizontal intensity of 21 uT; a hard iron left uncorrected is tens of degrees)
  double max_bias_sigma_ut = 2.0;
  // a pair whose residual exceeds this many times the window's rms (at least pair_noise_ut) is
  // left out: the field differs between the two places (a car, a rail, steel in a wall)
  double pair_gate_sigma = 3.0;
  // rms pair residual above which the field is disturbed everywhere: the window is forgotten,
  // counted as refused, the bias in use stays (docs/pdr.md)
  double max_pair_residual_ut = 3.0;
  // ... unless the hard iron (and gyro bias) fitted to the window account for at least this
  // fraction of the pairs' differences (sum of |R_i m_i - R_j m_j|^2), as min_explained for the
  // sphere fit: the bias is then plainly there and the scatter left is the noise of a phone on a
  // limb. Measured (TYREX, Android-calibrated field): a pocket, a swinging hand or running leave
  // 4.7-8.9 uT rms with no hard iron at all (explained 0.1-0.3: refused, nothing to correct);
  // magnets on the path 16 uT (0.28); with a 36-70 uT hard iron added 0.97-0.998, the bias found
  // within 1-7 uT in a pocket or a swinging hand.
  double min_pair_explained = 0.9;
  double min_pair_rotation_rad = 3.0 * kDegToRad;  // a pair rotated less carries ~no information
  double min_pair_time_s = 5.0;      // weighted time of informative pairs before the first solve
  // --- attitude-independent sphere fit (no gyroscope) ---
  double tau_s = 300.0;            // memory (the phone's hard iron is stable for hours)
  double sample_interval_s = 0.1;  // readings closer than this are one (weights in seconds: rate-free)
  double max_weight_s = 0.5;       // weight of one reading after a gap, at most
  // ridge: a direction whose readings' spread (variance) is v is corrected by v / (v + ridge):
  // (3 uT)^2 keeps the ~1-2 uT vertical sway of a flat walking phone mostly uncorrected
  double ridge_ut2 = 9.0;
  // applied once the second eigenvalue of the readings' covariance is >= (6 uT)^2: a half turn at
  // a horizontal intensity of 20 uT gives 0.095 x 20^2 = 38 uT^2, a quarter turn 3 uT^2
  double min_spread_ut2 = 36.0;
  double min_time_s = 30.0;        // and after this much (weighted) time of readings (20 s let one
                                   // 22 s indoor ILC walk fit a spurious 36 uT vertical bias)
  // rms of |m - b| - r over the window, as a fraction of r, above which the field is disturbed and
  // the window is forgotten (measured: 6-10 % on a clean outdoor walk, 3-18 % indoors and on the
  // TYREX walks without magnets, 40-60 % with magnets on the path)
  double max_residual = 0.12;
  // coefficient of determination of the fit: the bias must explain this fraction of the variance
  // of |m|^2 over the window (measured: 0.95 outdoors with a 10 uT bias, <= 0.85 for every walk
  // of an Android-calibrated phone indoors)
  double min_explained = 0.9;
  double max_bias_ut = 200.0;      // a fit beyond this is refused (phone hard iron: tens of uT)
  // Pdr: a bias that moved this far from the one the compass heading offset was learned with
  // restarts that offset (e.g. 3 uT: up to 9 deg across a 20 uT horizontal field); 0 = off.
  // Off by default: at 3 uT with the gyro-aided fit the ETH walk's DR gains (48.0 -> 46.0 m) but
  // TYREX with compass headings loses (imu 1.62 -> 1.72 m, at 50 Hz 1.85 -> 2.13; docs/results.md).
  double restart_change_ut = 0.0;
  // Pdr: a bias that moved this far from the one the heading fusion's gyro drift was learned with
  // (zero before the first activation) restarts the drift fit only: readings with another hard
  // iron measure another offset, and a line through both reads the calibration's step as drift
  // (ETH walk with a 44 uT hard iron: 0.3 deg/s at the first step, 0.7 a minute on, its segments
  // 13-28 deg off). 10 uT: up to 30 deg across a 20 uT horizontal field, where the converging bias
  // moves by 1-7 uT (kept: the drift learned with it). 0 = off.
  double drift_restart_change_ut = 10.0;
};

/// Streaming hard-iron sphere fit. Deterministic; time as int64 ns.
class MagCalibration {
 public:
  explicit MagCalibration(const MagCalibrationOptions& options = {});
  /// One reading (phone axes, uT). Non-finite readings and backwards time are ignored.
  void add(TimeNs t_ns, const Eigen::Vector3d& field_ut);
  /// One calibrated gyroscope sample (phone axes, rad/s): the attitude of the gyro-aided fit.
  void add_gyro(TimeNs t_ns, const Eigen::Vector3d& rate_radps);
  /// The gyro-aided fit is in use (a gyroscope is live); false: the sphere fit.
  bool gyro_aided() const { return gyro_live_; }
  /// rms residual of the gyro-aided pairs over the window (uT; NaN before the first solve) and
  /// the 1-sigma of the second best-determined direction of b.
  double pair_residual_ut() const { return pair_residual_ut_; }
  double bias_sigma_ut() const { return bias_sigma_ut_; }
  /// The gyro bias estimated with it (phone axes, rad/s; zero before the first solve).
  const Eigen::Vector3d& gyro_bias_radps() const { return gyro_bias_radps_; }
  /// Pairs left out by the per-pair gate (the field differed between the two places).
  std::int64_t pairs_gated() const { return pairs_gated_; }
  /// The reading with the bias in use removed (unchanged while not active).
  Eigen::Vector3d corrected(const Eigen::Vector3d& field_ut) const {
    return active_ ? Eigen::Vector3d(field_ut - bias_ut_) : field_ut;
  }
  bool active() const { return active_; }
  /// The gyro's bias correction changed (an uncalibrated gyro's drift, learned or stated): the
  /// attitudes before and after are not one integration, so no pair spans the change and the
  /// pairs summed with the former correction are forgotten (the bias in use stays).
  void restart_pairs();
  std::int64_t pair_restarts() const { return pair_restarts_; }
  /// Time the first bias was applied (-1: never).
  TimeNs active_from_ns() const { return active_from_ns_; }
  /// The bias in use (zero while not active), sphere radius and fit residual (fraction of r)
  /// of the last accepted fit.
  const Eigen::Vector3d& bias_ut() const { return bias_ut_; }
  double radius_ut() const { return radius_ut_; }
  double residual() const { return residual_; }
  /// Second eigenvalue of the current window's covariance (uT^2); how many fits were refused.
  double spread_ut2() const { return spread_ut2_; }
  std::int64_t refusals() const { return refusals_; }
  /// Fraction of the window's variation the last fit explained (sphere: of |m|^2; gyro-aided
  /// pairs: of the pairs' differences).
  double last_explained() const { return last_explained_; }
  double last_residual() const { return last_residual_; }
  std::int64_t fits_accepted() const { return accepted_; }
  const MagCalibrationOptions& options() const { return opt_; }

 private:
  void clear_sums();
  void add_sphere(TimeNs t_ns, const Eigen::Vector3d& field_ut, double dt_s);
  void add_pairs(TimeNs t_ns, const Eigen::Vector3d& field_ut, double dt_s, const Eigen::Matrix3d& r,
                 const Eigen::Matrix3d& s);
  MagCalibrationOptions opt_;
  // gyro-aided: attitude phone -> a world-fixed frame, integrated from the gyro
  struct Reading { TimeNs t_ns; Eigen::Vector3d m; Eigen::Matrix3d r, s; };
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  struct Attitude { TimeNs t_ns; Eigen::Quaterniond q; Eigen::Matrix3d r, s; Eigen::Vector3d rate; };
  /// The attitude (and its time integral) at t_ns from the gyro history; false when no gyro
  /// sample is within max_gyro_gap_s of it on an unbroken stretch.
  bool attitude_at(TimeNs t_ns, Eigen::Matrix3d* r, Eigen::Matrix3d* s) const;
  Eigen::Quaterniond q_ = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d r_ = Eigen::Matrix3d::Identity();  // q_ as a matrix
  Eigen::Matrix3d s_ = Eigen::Matrix3d::Zero();  // integral of the attitude over time (s)
  std::vector<TimeNs> lags_ns_;                  // pair lags: 1, 2, 4, ... s up to max_lag_s
  Eigen::Vector3d rate_ = Eigen::Vector3d::Zero();
  TimeNs gyro_ns_ = -1;
  std::deque<Attitude> gyro_history_;  // the last gyro_history_s of attitudes (a gap clears it)
  bool gyro_live_ = false;
  std::deque<Reading> readings_;
  // weighted normal equations of the pairs in (b, gyro bias): sum w A^T A, w A^T y, w |y|^2, w
  Mat6 pn_ = Mat6::Zero();
  Vec6 pr_ = Vec6::Zero();
  Eigen::Vector3d pair_b_ = Eigen::Vector3d::Zero();  // latest solution (linearisation point of h)
  bool pair_solved_ = false;                          // a solution to gate pairs against
  std::int64_t pairs_gated_ = 0;
  Eigen::Vector3d gyro_bias_radps_ = Eigen::Vector3d::Zero();
  double pyy_ = 0.0, pw_ = 0.0;
  double pair_residual_ut_ = kNaN, bias_sigma_ut_ = kNaN;
  // weighted sums of m, m m^T, y = |m|^2, y m, y^2 (weights in s, forgotten with tau_s)
  double w_ = 0.0, sy_ = 0.0, syy_ = 0.0;
  Eigen::Vector3d sm_ = Eigen::Vector3d::Zero(), sym_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d smm_ = Eigen::Matrix3d::Zero();
  bool have_last_ = false;
  TimeNs last_ns_ = 0;
  bool active_ = false;
  TimeNs active_from_ns_ = -1;
  Eigen::Vector3d bias_ut_ = Eigen::Vector3d::Zero();
  double last_explained_ = kNaN, last_residual_ = kNaN;
  double radius_ut_ = kNaN, residual_ = kNaN, spread_ut2_ = 0.0;
  std::int64_t refusals_ = 0, accepted_ = 0, pair_restarts_ = 0;
};

}  // namespace pdnav::pdr
