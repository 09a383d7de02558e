// Online hard-iron magnetometer calibration (docs/pdr.md, "Hard-iron calibration").
#pragma once
#include <cstdint>

#include <Eigen/Core>

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
struct MagCalibrationOptions {
  bool enabled = true;
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
  // Off by default: on the ETH walk it cost outage_ratio 1.060 -> 1.103 (docs/pdr.md).
  double restart_change_ut = 0.0;
};

/// Streaming hard-iron sphere fit. Deterministic; time as int64 ns.
class MagCalibration {
 public:
  explicit MagCalibration(const MagCalibrationOptions& options = {}) : opt_(options) {}
  /// One reading (phone axes, uT). Non-finite readings and backwards time are ignored.
  void add(TimeNs t_ns, const Eigen::Vector3d& field_ut);
  /// The reading with the bias in use removed (unchanged while not active).
  Eigen::Vector3d corrected(const Eigen::Vector3d& field_ut) const {
    return active_ ? Eigen::Vector3d(field_ut - bias_ut_) : field_ut;
  }
  bool active() const { return active_; }
  /// The bias in use (zero while not active), sphere radius and fit residual (fraction of r)
  /// of the last accepted fit.
  const Eigen::Vector3d& bias_ut() const { return bias_ut_; }
  double radius_ut() const { return radius_ut_; }
  double residual() const { return residual_; }
  /// Second eigenvalue of the current window's covariance (uT^2); how many fits were refused.
  double spread_ut2() const { return spread_ut2_; }
  std::int64_t refusals() const { return refusals_; }
  double last_explained() const { return last_explained_; }
  double last_residual() const { return last_residual_; }
  std::int64_t fits_accepted() const { return accepted_; }
  const MagCalibrationOptions& options() const { return opt_; }

 private:
  void clear_sums();
  MagCalibrationOptions opt_;
  // weighted sums of m, m m^T, y = |m|^2, y m, y^2 (weights in s, forgotten with tau_s)
  double w_ = 0.0, sy_ = 0.0, syy_ = 0.0;
  Eigen::Vector3d sm_ = Eigen::Vector3d::Zero(), sym_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d smm_ = Eigen::Matrix3d::Zero();
  bool have_last_ = false;
  TimeNs last_ns_ = 0;
  bool active_ = false;
  Eigen::Vector3d bias_ut_ = Eigen::Vector3d::Zero();
  double last_explained_ = kNaN, last_residual_ = kNaN;
  double radius_ut_ = kNaN, residual_ = kNaN, spread_ut2_ = 0.0;
  std::int64_t refusals_ = 0, accepted_ = 0;
};

}  // namespace pdnav::pdr
