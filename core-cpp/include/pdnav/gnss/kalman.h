// Robust Kalman filter of Walker, Remote Sens. 2019 (Sec. 2.5), extended to a kinematic state:
// position and velocity in ECEF (m, m/s), receiver clock and clock drift of the SPP reference
// system (m, m/s). Time update either from a displacement (TDCP, or PDR from the fusion layer)
// or from the constant-velocity model with white acceleration noise (Groves 2013, Sec. 9.4.2.2;
// `dynamics` picks the spectral density); measurement updates from an SPP fix (position + clock)
// and from a velocity (Doppler or TDCP, + drift). Updates are robust: the standardised
// innovation gets the IGG-III weight (Yang, Song & Xu 2002, J. Geodesy 76:353-358: the
// variance is inflated by 1/w between k0 and k1, the update rejected beyond k1), then Walker's
// posterior residual test (r^2 / var > 36) guards the state.
// Inter-system biases are solved per epoch in the SPP (loosely coupled: the fix already carries
// them; docs/gnss.md); the KF clock is that of the fix's reference system.
#pragma once
#include <string>

#include <Eigen/Core>

#include "pdnav/geo/frames.h"
#include "pdnav/geo/samples.h"

namespace pdnav::gnss {

/// Process-noise model of the kinematic KF.
enum class KfDynamics { kPedestrian, kVehicle };
/// "pedestrian" / "vehicle"; false for anything else.
bool parse_kf_dynamics(const std::string& s, KfDynamics& out);
const char* kf_dynamics_name(KfDynamics d);
/// Acceleration power spectral density per horizontal axis, m^2/s^3 (Groves, Principles of
/// GNSS, Inertial, and Multisensor Integrated Navigation Systems, 2nd ed. 2013, Sec. 9.4.2.2:
/// "around 1 m^2 s^-3 for a pedestrian or ship, 10 m^2 s^-3 for a car").
double kf_accel_psd_m2ps3(KfDynamics d);

struct KalmanOptions {
  double residual_threshold = 36.0;       // Walker 2019: reject when r^2 / var > 36
  // Walker 2019 uses the displacement covariance alone (1e-4 m^2 here before); on a moving
  // phone TDCP displacements have metre-level tails (urban multipath on the carrier,
  // undetected slips): 0.1 m^2 per epoch, measured on the GSDC drive (docs/gnss.md).
  double displacement_q_m2 = 0.1;
  KfDynamics dynamics = KfDynamics::kPedestrian;  // walkers; also the better-calibrated one on the GSDC car (docs/gnss.md)
  // Acceleration PSD per horizontal axis; NaN = kf_accel_psd_m2ps3(dynamics). The vertical
  // axis gets `vertical_psd_fraction` of it (both walkers and cars follow the ground).
  double accel_psd_h_m2ps3 = kNaN;
  double vertical_psd_fraction = 0.1;
  double clock_q_m2ps = 1e4;              // clock random walk (phone clocks are steered, ~100 m/s^0.5)
  double drift_q_m2ps3 = 1e2;             // clock-drift random walk (TCXO under temperature change)
  double initial_velocity_var_m2ps2 = 400.0;  // (20 m/s)^2 before any velocity measurement
  // The SPP covariance treats each fix as independent; phone code errors are correlated over
  // tens of seconds (multipath). Fixes correlated by rho(k) at lag k carry the information of
  // n / (1 + 2 sum rho(k)) independent ones (the effective sample size, von Storch & Zwiers 1999,
  // Sec. 17.1.3). The SPP errors' autocorrelation has a long tail (rho(30 s) 0.2-0.5), so the
  // sum is measured, not extrapolated from rho(1): over 30 s of lags, 41 / 28 (east / north) on
  // the GSDC car (SP3 orbits), 40 / 29 on the static Mountain View phone (docs/gnss.md "Robust
  // Kalman filter") -> 30 (the north value of both; east has the longer tail), the scale of an
  // average over all time: the AR(1) with rho = 29 / 31 per second. The filter applies it over
  // its own memory (fix_variance_scale_for(dt, gain)).
  double fix_variance_scale = 30.0;
  double min_fix_variance_m2 = 1.0;       // floor of each axis of R (phone code errors are never < 1 m)
  double min_velocity_variance_m2ps2 = 0.01;  // floor of each axis of a velocity measurement
  // IGG-III (Yang et al. 2002): full weight up to k0, zero beyond k1, on the standardised
  // innovation sqrt(nu' S^-1 nu / m). k0 = 1.5 and k1 = 3.0 are the paper's values.
  bool robust_igg3 = true;
  double igg_k0 = 1.5;
  double igg_k1 = 3.0;
  int max_consecutive_rejections = 10;    // then reset to the SPP fix (the filter diverged)
  // ... or after this long of rejected fixes (a duty-cycled phone gives a fix every 5-20 s:
  // 10 rejections there are minutes of divergence)
  double max_rejected_span_s = 10.0;
};

/// R scale for SPP fixes dt_s apart (see KalmanOptions::fix_variance_scale); >= 1. A filter
/// that gives each new fix the weight `gain` averages the fixes with weights gain (1 - gain)^j,
/// exponential smoothing; for AR(1) errors the variance of that average is its white value times
/// (1 + a) / (1 - a), a = rho^dt (1 - gain). gain 0 = an average over all time.
double fix_variance_scale_for(const KalmanOptions& opt, double dt_s, double gain = 0.0);

/// The IGG-III equivalent weight of a standardised residual t (Yang, Song & Xu 2002):
/// 1 for |t| <= k0; k0/|t| * ((k1 - |t|)/(k1 - k0))^2 for k0 < |t| <= k1; 0 beyond k1.
double igg3_weight(double t, double k0, double k1);

struct KalmanUpdateResult {
  bool accepted = false;
  double max_normalised_residual = 0.0;   // largest r_i^2 / var_i of the posterior residuals
  double standardised_innovation = 0.0;   // sqrt(nu' S^-1 nu / m)
  double robust_weight = 1.0;             // IGG-III weight applied to R (1 = none)
  bool reset = false;                     // filter re-initialised from the fix
};

class RobustKalman {
 public:
  static constexpr int kStates = 8;  // x, y, z, vx, vy, vz (ECEF), clock, drift
  using Vector = Eigen::Matrix<double, kStates, 1>;
  using Matrix = Eigen::Matrix<double, kStates, kStates>;

  explicit RobustKalman(KalmanOptions opt = {});

  bool initialized() const { return initialized_; }
  /// Start (or restart) from a fix with its covariance; the velocity is unknown (zero with
  /// initial_velocity_var), unless a velocity measurement comes later.
  void reset(const geo::Ecef& pos, const Eigen::Matrix3d& pos_cov, double clock_m, double clock_var_m2);
  /// Time update with a known displacement and its covariance (TDCP, PDR); clock change may be
  /// NaN. The velocity and drift keep their values with the dynamics' random walk over dt_s.
  void predict(const Eigen::Vector3d& disp_m, const Eigen::Matrix3d& disp_cov, double clock_change_m,
               double clock_change_var_m2, double dt_s = 1.0);
  /// Time update of the constant-velocity model over dt_s (no displacement measured):
  /// r += v dt, clock += drift dt, Q = white-acceleration (Bar-Shalom 2001, Sec. 6.2.2).
  void coast(double dt_s);
  /// The clock reference moved by a known amount (Android FullBiasNanos + BiasNanos change).
  void shift_clock(double delta_m);
  /// The clock jumped (hardware clock discontinuity): forget the clock state.
  void reset_clock(double clock_m, double clock_var_m2);
  /// Measurement update with an SPP fix (robust, see the header comment).
  /// `since_last_fix_s`: time since the previous fix offered to the filter (sets the R scale).
  KalmanUpdateResult update(const geo::Ecef& fix, const Eigen::Matrix3d& fix_cov, double clock_m,
                            double clock_var_m2, double since_last_fix_s = 1.0);
  /// Measurement update with a velocity (ECEF m/s) and optionally the clock drift (m/s; NaN =
  /// not measured). Rejected (state unchanged) by the same robust tests.
  KalmanUpdateResult update_velocity(const Eigen::Vector3d& vel_mps, const Eigen::Matrix3d& vel_cov,
                                     double drift_mps, double drift_var_m2ps2);

  /// Replace the velocity (and drift when finite) by a value derived from the displacement the
  /// last predict() used (TDCP mean velocity): no cross-covariance, so it never moves the
  /// position that displacement already moved (the same data must not be used twice).
  void set_velocity(const Eigen::Vector3d& vel_mps, const Eigen::Matrix3d& vel_cov, double drift_mps,
                    double drift_var_m2ps2);

  /// Squared Mahalanobis distance of a displacement measured over dt_s from this filter's
  /// constant-velocity prediction v dt (covariance P_v dt^2 + S_a dt^3 / 3 + disp_cov); NaN
  /// before initialisation. The check of a displacement without redundancy of its own.
  double displacement_mahalanobis2(const Eigen::Vector3d& disp_m, const Eigen::Matrix3d& disp_cov, double dt_s) const;

  geo::Ecef position() const { return geo::Ecef(x_.head<3>()); }
  Eigen::Vector3d velocity_ecef_mps() const { return x_.segment<3>(3); }
  double clock_m() const { return x_(6); }
  double drift_mps() const { return x_(7); }
  const Vector& state() const { return x_; }
  const Matrix& covariance() const { return p_; }
  Eigen::Matrix3d position_cov_ecef() const { return p_.topLeftCorner<3, 3>(); }
  Eigen::Matrix3d velocity_cov_ecef() const { return p_.block<3, 3>(3, 3); }
  /// Position covariance rotated into the local ENU frame at the current position.
  Eigen::Matrix3d position_cov_enu() const;
  const KalmanOptions& options() const { return opt_; }

 private:
  template <int M>
  KalmanUpdateResult robust_update(const Eigen::Matrix<double, M, 1>& z, const Eigen::Matrix<double, M, kStates>& h,
                                   const Eigen::Matrix<double, M, M>& r, bool allow_reset, double span_s);
  /// Acceleration PSD as an ECEF 3x3 (ENU diagonal rotated at the current position).
  Eigen::Matrix3d accel_psd_ecef() const;

  KalmanOptions opt_;
  bool initialized_ = false;
  double fix_gain_ = 0.0;  // the weight the last accepted fix got (mean over the position axes)
  int rejections_in_row_ = 0;
  double rejected_span_s_ = 0.0;
  Vector x_ = Vector::Zero();
  Matrix p_ = Matrix::Identity();
};

}  // namespace pdnav::gnss
