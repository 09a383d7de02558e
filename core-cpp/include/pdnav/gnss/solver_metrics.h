// Accuracy of GNSS epoch solutions against a static surveyed truth (issue 7 bar):
// SPP horizontal error percentiles, KF horizontal RMS, and the RMS of the 1-second TDCP
// displacement per axis (a static receiver's true displacement is zero).
#pragma once
#include <cstdint>
#include <istream>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/frames.h"
#include "pdnav/gnss/gnss_engine.h"

namespace pdnav::gnss {

/// The worst axis of a per-axis RMS, NaN when any axis has none.
inline double worst_axis_m(const Eigen::Vector3d& rms_m) { return rms_m.allFinite() ? rms_m.maxCoeff() : kNaN; }

struct StaticAccuracy {
  int spp_epochs = 0, kf_epochs = 0, tdcp_epochs = 0, doppler_epochs = 0;
  double spp_p50_h_m = kNaN, spp_p95_h_m = kNaN, spp_rms_h_m = kNaN, spp_rms_v_m = kNaN;
  double kf_rms_h_m = kNaN, kf_p50_h_m = kNaN, kf_p95_h_m = kNaN, kf_rms_v_m = kNaN;
  /// Fraction of KF epochs whose horizontal error is inside the 2-D 68 % ellipse of the reported
  /// covariance (Mahalanobis^2 <= 2.279), as TrackStats::coverage68.
  double kf_coverage68 = kNaN;
  Eigen::Vector3d tdcp_rms_enu_m = Eigen::Vector3d::Constant(kNaN);     // per axis, TDCP epochs
  Eigen::Vector3d doppler_rms_enu_m = Eigen::Vector3d::Constant(kNaN);  // per axis, Doppler fallback epochs
  double tdcp_rms_max_axis_m() const { return worst_axis_m(tdcp_rms_enu_m); }
};

/// Percentile (0..100) by linear interpolation between order statistics; NaN when empty.
double percentile(std::vector<double> v, double pct);

/// Errors of `sols` against a static truth. Displacements count when their interval is
/// 1 s +- 0.1 s (the 1-second TDCP displacement of the issue).
StaticAccuracy evaluate_static(const std::vector<EpochSolution>& sols, const geo::Geodetic& truth);

/// One truth point of a moving receiver (GSDC ground_truth.csv), GPS time.
struct TruthPoint {
  std::int64_t gps_ns = 0;
  geo::Geodetic pos;
};

struct TruthTrack {
  std::vector<TruthPoint> points;  // sorted by time
  std::int64_t skipped_rows = 0;   // malformed / non-finite rows (counted, not fatal)
};

/// GSDC truth CSV: a header row naming `millisSinceGpsEpoch`, `latDeg`, `lngDeg` and
/// `heightAboveWgs84EllipsoidM` (any order, other columns ignored), then one row per epoch.
/// Throws std::runtime_error("name:line: reason") when a column is missing or no row is usable.
TruthTrack read_truth_csv(std::istream& in, const std::string& name);
TruthTrack read_truth_csv_file(const std::string& path);

/// Truth at a GPS time by linear interpolation between the two neighbouring points no
/// more than `max_gap_s` apart; false outside the track or across a gap.
bool truth_at(const TruthTrack& t, std::int64_t gps_ns, geo::Geodetic& out, double max_gap_s = 1.5);

/// Accuracy of one solution type (SPP or KF) along a truth track, GSDC style.
struct TrackStats {
  int epochs = 0;       // epochs inside the truth track
  int solved = 0;       // epochs with a solution
  double p50_h_m = kNaN, p95_h_m = kNaN, rms_h_m = kNaN;
  double score_m = kNaN;        // GSDC 2021 metric: (p50 + p95) / 2 of the horizontal error
  double availability = kNaN;   // solved / epochs
  /// KF only: fraction of epochs whose horizontal error is inside the 2-D 68 % ellipse of the
  /// reported covariance (Mahalanobis^2 <= 2.279, chi-square 2 dof).
  double coverage68 = kNaN;
};

struct TrackAccuracy {
  TrackStats spp, kf;
  /// The 1 s displacement (TDCP, and the Doppler fallback) against the truth track's own
  /// displacement over the same interval: per-axis RMS of the error (ENU at the epoch's truth),
  /// over the epochs whose interval is 1 s +- 0.1 s and whose two ends the truth covers.
  int tdcp_epochs = 0, doppler_epochs = 0;
  Eigen::Vector3d tdcp_err_rms_enu_m = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d doppler_err_rms_enu_m = Eigen::Vector3d::Constant(kNaN);
  double tdcp_err_rms_max_axis_m() const { return worst_axis_m(tdcp_err_rms_enu_m); }
};

TrackAccuracy evaluate_track(const std::vector<EpochSolution>& sols, const TruthTrack& truth);

}  // namespace pdnav::gnss
