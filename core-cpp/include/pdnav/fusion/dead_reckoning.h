// Dead reckoning from PDR steps: the baseline every other engine is measured against.
// A 3-state EKF [east, north, heading bias] whose bias is first-order Gauss-Markov as in
// Broyles et al., Sensors 2018, Eq. 3-4 (sigma_theta 15 deg, tau_theta 60 s); no measurements,
// so the mean is plain dead reckoning and the covariance grows the way the bias makes it.
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
};

class DeadReckoning {
 public:
  explicit DeadReckoning(const DeadReckoningOptions& opt = {}) : opt_(opt) {}
  void initialize(const geo::Geodetic& start, double sigma_m, TimeNs t_ns);
  bool initialized() const { return initialized_; }
  void feed(const PdrStep& step);
  Estimate estimate() const;
  const geo::LocalFrame& frame() const { return frame_; }

 private:
  DeadReckoningOptions opt_;
  bool initialized_ = false;
  geo::LocalFrame frame_;
  Eigen::Vector3d x_ = Eigen::Vector3d::Zero();  // e, n, heading bias
  Eigen::Matrix3d p_ = Eigen::Matrix3d::Zero();
  TimeNs t_ns_ = 0;
};

}  // namespace pdnav::fusion
