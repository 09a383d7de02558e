// The fused estimator: an error-tolerant EKF driven by (calibrated) PDR steps, with GNSS
// positions (SPP or chipset Fix, with their covariances), TDCP / Doppler displacements
// (stochastic cloning of the previous epoch's position) and, during outages, the terrain and
// route engines' estimates as measurements. State (local ENU frame of the session start):
//   x = [e, n, db, ds, e_c, n_c]
// e, n position; db residual heading bias and ds residual step-length scale error left after
// the sliding-window calibration (PdrCalibrator); e_c, n_c the clone of the position at the
// last GNSS epoch. Prediction and measurement equations, gating and the re-acquisition rule
// are in docs/fusion.md. Walker et al., Remote Sensing 2019, Sec. 3, is the starting point
// (PDR prediction, SPP + TDCP measurements of a robust KF); the windowed gate replaces its
// single-epoch residual test.
#pragma once
#include <algorithm>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/events.h"
#include "pdnav/geo/units.h"

namespace pdnav::fusion {

struct FusionFilterOptions {
  // --- prediction ---
  /// Step-length scale of an unknown walker: 18 % = the spread between data sets (RMS of the log
  /// of the uncalibrated length ratio, ILC 1.01 / TYREX 0.91 / ETH 0.75 / unseen hand-held 0.87:
  /// 15 %) and between the walks of one set (ILC, 43 walks: 10 %) together; APT's height model
  /// claims 10 % (Zhu 2015 Sec. V-C). = DeadReckoningOptions, PdrCalibratorOptions::max_scale_sigma.
  double initial_scale_sigma = 0.18;
  double initial_heading_bias_sigma_rad = 10.0 * kDegToRad;  // rotation-vector heading accuracy class
  /// Random walk of the residual heading bias (magnetic disturbances, gyro drift): (2 deg)^2 per minute.
  double heading_bias_rw_rad2ps = (2.0 * kDegToRad) * (2.0 * kDegToRad) / 60.0;
  /// Random walk of the residual step scale (pace changes): (1 %)^2 per minute; only with
  /// scale_tau_s = 0 (the Gauss-Markov model below replaces it).
  double scale_rw_1ps = 1e-4 / 60.0;
  /// The residual step-scale error is a first-order Gauss-Markov process too, with stationary
  /// sigma initial_scale_sigma (the scale of an unknown walker) and this correlation time (the
  /// calibration window): what a calibration learned about the scale fades back to the prior over
  /// minutes, as a walker's pace, stride and ground change (Gelb 1974, Sec. 3.8; measured on the
  /// ETH walk: fitted scale 1.22 / 1.40 / 1.24 over consecutive 2-5 min spans, docs/fusion.md).
  /// 0 = the random walk alone (the model before this option).
  double scale_tau_s = 300.0;
  /// ... and, once a calibration has been applied (set_residual_uncertainty), the stationary
  /// sigma of that process is the step scale's variation WITHIN a walk, not the spread between
  /// walkers (initial_scale_sigma, which the calibration has learnt): the walker's constant is
  /// known to the calibration's own sigma, what remains is pace, ground and carry. Measured on
  /// our PDR over the real sets: TYREX 20 s windows about each walk's median, sd of the log length
  /// ratio 0.104 (robust 0.080, 12 walks); the ETH walk's fitted scale over consecutive 2-5 min
  /// spans 1.22 / 1.40 / 1.24, sd of the log 0.075 (docs/fusion.md). <= 0: initial_scale_sigma.
  double scale_within_walk_sigma = 0.10;
  /// The PDR's stated heading 1-sigma (PdrStep::heading_sigma_rad: compass / rotation vector
  /// accuracy) is the sigma of a slowly varying error (magnetic disturbances along the way, gyro
  /// drift), not of independent per-step noise: the heading bias state is a first-order
  /// Gauss-Markov process with that stationary sigma and this correlation time (Gelb 1974,
  /// Sec. 3.8), taken as the calibration window (the span over which the calibrator assumes the
  /// bias constant). Each step then keeps only min_step_heading_sigma_rad as white noise.
  /// 0 = the stated sigma is white per-step noise (the model before issue 28).
  double heading_bias_tau_s = 300.0;
  double min_step_heading_sigma_rad = 3.0 * kDegToRad;  // floor of a step's white heading noise
  double min_step_length_sigma_m = 0.05;                // floor of a step's white length noise
  /// Motion no step reported (shuffling, a missed detection): position random walk, m^2/s,
  /// applied to the time beyond undetected_after_s since the last step.
  double undetected_motion_q_m2ps = 0.05;
  double undetected_after_s = 1.5;
  /// No motion sensor at all (a GNSS-only recording, sensors not logged): the walker's motion
  /// is unobserved, not absent. Position random walk of a pedestrian of speed v whose direction
  /// decorrelates over tau: the diffusive limit v^2 tau = (1.4 m/s)^2 x 10 s per axis of a
  /// correlated random walk (Codling, Plank & Benhamou, J. R. Soc. Interface 2008). Its exact
  /// ballistic start (v t)^2 / 2 was measured worse: this filter has no velocity state, so a
  /// tighter prediction only lags a walker (a simulated GNSS-only walk: mean error 4.0 m against
  /// 3.1 m, the fixes' own 3.8 m). Applied beyond blind_after_s since the last motion-sensor
  /// sample (note_motion_sensing, track_motion_sensing); 0 = off.
  double blind_motion_q_m2ps = 20.0;
  double blind_after_s = 2.0;
  // --- gating ---
  double gate_chi2 = 11.83;          // chi^2(2 dof) at 99.73 % = a 3-sigma innovation
  int confirm_epochs = 5;            // consecutive rejected epochs that agree = a real correction
  double confirm_window_s = 20.0;    // ... within this time
  double agreement_p = 0.99;         // mutual-consistency test of those epochs (chi^2 quantile)
  double reacquire_after_s = 30.0;   // no accepted position this long = an outage
  int reacquire_epochs = 2;          // after an outage, this many agreeing epochs before use
  double displacement_gate_chi2 = 13.82;  // TDCP / Doppler: chi^2(2) at 99.9 % (cycle slips)
  double scale_gate_chi2 = 9.0;           // a direct step-scale sample: chi^2(1) at 99.73 % (3 sigma)
  /// Phone code errors are time-correlated (multipath, minutes): after a position update the
  /// position variance is kept >= this fraction of the measurement's, so a run of correlated
  /// fixes never claims they averaged out (beyond the paper; docs/fusion.md). 0 = off.
  double position_floor_fraction = 0.25;
  /// Position measurements (SPP, the GNSS KF, chipset fixes, engine aiding) leave the heading
  /// bias and scale states as consider states (Schmidt 1966; the Schmidt-Kalman filter): their
  /// uncertainty enters the position covariance but a position update does not shrink or move
  /// them. Their errors are correlated over minutes (multipath, a chipset's own filter), so a run
  /// of fixes would "learn" a PDR scale and bias it does not know; the sliding-window calibrator
  /// (with its effective sample size) and TDCP/Doppler displacements set them (docs/fusion.md).
  bool consider_pdr_states_on_position = true;
};

struct PositionUpdateResult {
  bool accepted = false;
  bool forced = false;         // accepted after consistent disagreement (covariance inflated)
  bool reacquired = false;     // first use after an outage
  double nis = 0.0;            // normalised innovation squared against the prediction
  double innovation_m = 0.0;   // |z - prediction|
  std::string reason;          // why (rejected, waiting for agreement, accepted ...)
};

class FusionFilter {
 public:
  explicit FusionFilter(const FusionFilterOptions& opt = {}) : opt_(opt) {}
  void initialize(const Eigen::Vector2d& en_m, double sigma_m, TimeNs t_ns);
  bool initialized() const { return initialized_; }

  /// Propagate with one (calibrated) step.
  void predict(const PdrStep& step);
  /// The calibration changed: the residual bias/scale states restart at zero with these
  /// variances (their cross-covariances with the position are dropped).
  void set_residual_uncertainty(double heading_bias_var_rad2, double scale_var);
  /// The variance of the heading bias *now* given a calibration that fitted its average over a
  /// window of window_s (the fit's own variance fit_var_rad2): under the Gauss-Markov model
  /// (heading_bias_tau_s, the PDR's stated sigma) the current value differs from the window mean
  /// by sigma^2 g(W / tau), g(u) = 1 - 2 (1 - e^-u) / u + 2 (u - 1 + e^-u) / u^2 (the
  /// exponential autocovariance integrated over the window). Without the model: fit_var_rad2.
  double heading_bias_var_after_window(double fit_var_rad2, double window_s) const;
  /// The heading bias expected age_s after a calibration of calibrated_rad: the Gauss-Markov
  /// mean decays as exp(-age / heading_bias_tau_s) while its variance relaxes to the stationary
  /// one (the residual state does the same; the sources, magnetic disturbances along the way,
  /// average out). The step scale is not treated so: a walker's stride differs from the model
  /// by a constant of its own. Without the model: calibrated_rad.
  double heading_bias_expected(double calibrated_rad, double age_s) const;
  /// The same for the step scale (scale_tau_s, scale_within_walk_sigma): the variance of the
  /// scale error now given a fit of its window average with variance fit_var.
  double scale_var_after_window(double fit_var, double window_s) const;
  /// Position measurement at t_ns (possibly before the last step: the steps after it are
  /// taken off the prediction) through the windowed gate. `R` is its 2x2 covariance.
  /// `floor_fraction` >= 0 replaces options().position_floor_fraction for this update (and the
  /// held epochs it may apply), e.g. 1 for an already-filtered, time-correlated measurement.
  PositionUpdateResult update_position(TimeNs t_ns, const Eigen::Vector2d& z_en_m, const Eigen::Matrix2d& r_m2,
                                       bool use_gate_policy = true, double floor_fraction = -1.0);
  /// A position estimate whose error is correlated with the filter's by an unknown amount (an
  /// aiding engine driven by the same PDR steps): covariance intersection on the position block
  /// (Julier & Uhlmann 1997): with w in (0, 1] minimising det of the fused position covariance,
  /// the position rows/columns of P are scaled by 1/sqrt(w) and R by 1/(1 - w) before a Kalman
  /// update, which stays consistent for any cross-correlation. Gated at gate_chi2 on P_pos + R.
  PositionUpdateResult update_position_ci(TimeNs t_ns, const Eigen::Vector2d& z_en_m, const Eigen::Matrix2d& r_m2);
  /// A direct sample of the residual step-scale error `ds` (true step = (1 + ds) x the fed
  /// step), e.g. the map's path between two matched turns over the steps' distance, minus 1;
  /// gated at scale_gate_chi2; only `ds` is updated (its gain on the other states is zero).
  /// Returns accepted.
  bool update_scale(TimeNs t_ns, double ds, double var, double* nis = nullptr);
  /// Displacement since the clone (the last GNSS epoch), e.g. TDCP. Returns accepted.
  bool update_displacement(TimeNs t_ns, TimeNs from_ns, const Eigen::Vector2d& d_en_m, const Eigen::Matrix2d& r_m2,
                           double* nis = nullptr);
  /// Clone the position at t_ns (a GNSS epoch) for the next displacement measurement.
  void clone(TimeNs t_ns);
  /// Account for the time since the last event (undetected motion).
  void advance_to(TimeNs t_ns);
  /// The caller reports every motion-sensor sample (accelerometer, gyroscope, rotation vector,
  /// step event, ...) with note_motion_sensing: time without any is then blind
  /// (blind_motion_q_m2ps). Off (the default for a filter used on its own): every quiet interval
  /// is a walker standing (undetected_motion_q_m2ps).
  void track_motion_sensing(bool on) { track_sensing_ = on; }
  void note_motion_sensing(TimeNs t_ns) { last_sensing_ns_ = std::max(last_sensing_ns_, t_ns); }

  Eigen::Vector2d position_en_m() const { return x_.head<2>(); }
  Eigen::Matrix2d position_cov_m2() const { return p_.topLeftCorner<2, 2>(); }
  double heading_bias_rad() const { return x_(2); }
  double scale_error() const { return x_(3); }
  double scale_error_var() const { return p_(3, 3); }
  TimeNs t_ns() const { return t_ns_; }
  TimeNs last_accepted_ns() const { return last_accept_ns_; }
  TimeNs clone_t_ns() const { return clone_ok_ ? clone_t_ns_ : -1; }
  const FusionFilterOptions& options() const { return opt_; }

 private:
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  struct Recent { TimeNs t_ns; Eigen::Vector2d d_en_m; double var_m2; };
  struct Held { TimeNs t_ns; Eigen::Vector2d z, nu; Eigen::Matrix2d r; };
  /// Steps after t_ns: their displacement and variance.
  void after(TimeNs t_ns, Eigen::Vector2d* d, double* var) const;
  /// Checks a position measurement, advances to t_ns and carries it (and its variance) to the
  /// last step; false with res->reason set when it is invalid.
  bool carry_to_last_step(TimeNs t_ns, const Eigen::Vector2d& z_en_m, const Eigen::Matrix2d& r_in, Eigen::Vector2d* z,
                          Eigen::Matrix2d* r, PositionUpdateResult* res);
  void apply_position(const Eigen::Vector2d& z, const Eigen::Matrix2d& r);
  bool agree(const std::vector<Held>& h, Eigen::Vector2d* mean_nu) const;
  void symmetrize();
  /// First-order Gauss-Markov propagation of state k over dt_s (x decays, P towards stationary_var).
  void gauss_markov_step(int k, double dt_s, double tau_s, double stationary_var);
  /// The heading bias follows the Gauss-Markov model: a correlation time and the PDR's stated
  /// sigma (the stationary one) known from a step.
  bool heading_bias_gauss_markov() const { return opt_.heading_bias_tau_s > 0.0 && heading_stationary_var_ > 0.0; }
  /// Variance of the scale's wander within a walk (scale_within_walk_sigma, else the walker's).
  double scale_within_walk_var() const;
  /// Stationary variance of the residual scale state: between walkers before a calibration,
  /// within the walk after one.
  double scale_stationary_var() const;

  FusionFilterOptions opt_;
  double floor_fraction_ = -1.0;  // per-update override of opt_.position_floor_fraction (< 0: none)
  bool initialized_ = false;
  Vec6 x_ = Vec6::Zero();
  Mat6 p_ = Mat6::Identity();
  TimeNs t_ns_ = 0;
  double heading_stationary_var_ = -1.0;  // the PDR's stated heading variance (last step), < 0 unknown
  bool scale_calibrated_ = false;          // a calibration was applied: the scale wanders within the walk
  TimeNs last_step_ns_ = -1;
  TimeNs last_sensing_ns_ = -1;  // the latest motion-sensor sample (-1: none yet)
  bool track_sensing_ = false;
  TimeNs last_accept_ns_ = -1;
  bool clone_ok_ = false;
  TimeNs clone_t_ns_ = 0;
  std::deque<Recent> recent_;
  std::vector<Held> rejected_;   // consecutive gate failures
  std::vector<Held> reacq_;      // passes waiting for agreement after an outage
};

/// chi^2 quantile (Wilson-Hilferty), for the gates.
double chi2_quantile(int dof, double p);

/// One hypothesis of a multi-modal aiding engine (the route engine's position clusters): where
/// it puts the walker, its covariance as the filter would use it (R), and its prior weight.
struct AidHypothesis {
  Eigen::Vector2d z_en_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d r_m2 = Eigen::Matrix2d::Identity();
  double weight = 0.0;
};
struct AidAssociation {
  int index = -1;          // the most probable hypothesis (-1: none has any probability)
  double runner_up = 0.0;  // the next one's posterior weight relative to it (0..1)
};
/// Probabilistic data association (Bar-Shalom & Tse, Automatica 1975): each hypothesis's
/// posterior weight is its prior weight times N(z; x, P + R); the most probable one, and how
/// close the next comes.
AidAssociation associate(const Eigen::Vector2d& x_en_m, const Eigen::Matrix2d& p_m2,
                         const std::vector<AidHypothesis>& hypotheses);

}  // namespace pdnav::fusion
