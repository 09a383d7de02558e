// Dead reckoning from PDR steps: the baseline every other engine is measured against.
// A 4-state EKF [east, north, heading bias, step scale error] whose bias is first-order Gauss-Markov as in
// Broyles et al., Sensors 2018, Eq. 3-4 (sigma_theta 15 deg, tau_theta 60 s); no measurements,
// so the mean is plain dead reckoning and the covariance grows the way the bias makes it.
// Issue 19.1: each step's own heading sigma (from the PDR) sets the bias' spread at that step,
// so a phone that gives no absolute heading (sigma = pi) grows the ellipse as it should, and
// the estimate says "relative heading only" until an absolute heading has been seen.
#pragma once
#include <Eigen/Core>

#include "pdnav/geo/estimate.h"
#include "pdnav/geo/events.h"
#include "pdnav/geo/frames.h"

namespace pdnav::fusion {

struct DeadReckoningOptions {
  double heading_bias_sigma_rad = 15.0 * kDegToRad;  // Broyles 2018, Table 1
  double heading_bias_tau_s = 60.0;                   // Broyles 2018, Table 1
  double length_sigma_m = 0.15;                       // Broyles 2018, sigma_l
  // Issue 28: the walker's step-length scale error is a per-walk constant (stride vs the
  // population model, grade, fatigue), not white per step: a random constant plus the fused
  // filter's (1 %)^2/min random walk. Its sigma is the spread of the uncalibrated length ratio
  // between walkers and places, measured on the real sets: between the sets (ILC 1.01, TYREX 0.91,
  // ETH 0.75 and the unseen hand-held walks 0.87: RMS of the log 15 %) and between the
  // walks of one set (ILC 43 walks: 10 %), sqrt(15^2 + 10^2) = 18 %; wider than the height model's
  // level-ground 10 % (APT, Zhu 2015 Sec. V-C), which does not cover grades and walkers. 0 = white only.
  double length_scale_sigma = 0.18;
  double length_scale_rw_1ps = 1e-4 / 60.0;
  // Per-step heading sigma (issue 19.1; docs/pdr.md "Dead-reckoning ellipse"). A step whose
  // PdrStep::heading_sigma_rad is below absolute_heading_max_sigma_rad has an absolute
  // heading: its sigma replaces heading_bias_sigma_rad as the bias' stationary sigma (the EKF's
  // linearisation holds). Above it (no absolute heading, e.g. sigma = pi) the path is known
  // only up to a rotation about the start by an angle of that sigma; that error is added in
  // closed form (rotation_covariance), since a linear model fails for large angles (it has no
  // along-track error at all). 0/NaN sigma = unknown: the fixed model above.
  bool use_step_heading_sigma = true;
  double absolute_heading_max_sigma_rad = 60.0 * kDegToRad;
  // A magnetic heading's error also depends on the heading itself: the one-cycle deviation
  // B sin(psi) + C cos(psi) of a compass (Bowditch, American Practical Navigator, Ch. 6; the
  // hard-iron field left after calibration turns with the phone). Unlike the bias it does not
  // average out around a loop: a walker circling drifts by ~B L / 2 after L metres. B and C are
  // random constants of this sigma, on absolute-heading steps only (measured per walk as the
  // heading error's sin/cos fit against the truth: TYREX 2-5 deg beyond the fit's noise, ETH
  // after the hard-iron calibration 4.4 / 2.4 deg). 0 = off.
  double compass_deviation_sigma_rad = 5.0 * kDegToRad;
};

class DeadReckoning {
 public:
  explicit DeadReckoning(const DeadReckoningOptions& opt = {}) : opt_(opt) {}
  void initialize(const geo::Geodetic& start, double sigma_m, TimeNs t_ns);
  bool initialized() const { return initialized_; }
  void feed(const PdrStep& step);
  Estimate estimate() const;
  /// True once a step came with an absolute heading (sigma below absolute_heading_max_sigma_rad).
  bool has_absolute_heading() const { return absolute_heading_seen_; }
  /// Covariance (east/north, m^2) of R(e) p - p for a path displacement p and a rotation e ~ N(0, sigma^2).
  static Eigen::Matrix2d rotation_covariance(const Eigen::Vector2d& p_en_m, double sigma_rad);
  const geo::LocalFrame& frame() const { return frame_; }

 private:
  DeadReckoningOptions opt_;
  bool initialized_ = false;
  geo::LocalFrame frame_;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  // e, n, heading bias, step-length scale error, compass deviation B (sin) and C (cos)
  Vec6 x_ = Vec6::Zero();
  Mat6 p_ = Mat6::Zero();
  TimeNs t_ns_ = 0;
  bool have_steps_ = false;
  bool absolute_heading_seen_ = false;
  double rotation_sigma_rad_ = 0.0;  // heading sigma while only a relative heading is known
};

}  // namespace pdnav::fusion
