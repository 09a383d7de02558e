// Accuracy of GNSS epoch solutions against a static surveyed truth (issue 7 bar):
// SPP horizontal error percentiles, KF horizontal RMS, and the RMS of the 1-second TDCP
// displacement per axis (a static receiver's true displacement is zero).
#pragma once
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/frames.h"
#include "pdnav/gnss/gnss_engine.h"

namespace pdnav::gnss {

struct StaticAccuracy {
  int spp_epochs = 0, kf_epochs = 0, tdcp_epochs = 0, doppler_epochs = 0;
  double spp_p50_h_m = kNaN, spp_p95_h_m = kNaN, spp_rms_h_m = kNaN, spp_rms_v_m = kNaN;
  double kf_rms_h_m = kNaN, kf_p50_h_m = kNaN, kf_p95_h_m = kNaN, kf_rms_v_m = kNaN;
  Eigen::Vector3d tdcp_rms_enu_m = Eigen::Vector3d::Constant(kNaN);     // per axis, TDCP epochs
  Eigen::Vector3d doppler_rms_enu_m = Eigen::Vector3d::Constant(kNaN);  // per axis, Doppler fallback epochs
  double tdcp_rms_max_axis_m() const { return tdcp_rms_enu_m.allFinite() ? tdcp_rms_enu_m.maxCoeff() : kNaN; }
};

/// Percentile (0..100) by linear interpolation between order statistics; NaN when empty.
double percentile(std::vector<double> v, double pct);

/// Errors of `sols` against a static truth. Displacements count when their interval is
/// 1 s +- 0.1 s (the 1-second TDCP displacement of the issue).
StaticAccuracy evaluate_static(const std::vector<EpochSolution>& sols, const geo::Geodetic& truth);

}  // namespace pdnav::gnss
