// The face every engine shares: Options -> Engine(options, seed) -> feed(...) / estimate().
#pragma once
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/frames.h"
#include "pdnav/geo/units.h"

namespace pdnav {

enum class EngineKind { kNone, kDeadReckoning, kTerrain, kRoute, kGnss };
const char* to_string(EngineKind k);

enum class EstimateStatus {
  kNotInitialized,  // no start position yet
  kOk,              // tracking
  kDegraded,        // tracking with reduced confidence (e.g. few satellites, flat terrain)
  kAmbiguous,       // several hypotheses (route engine: needs a fix)
  kLost,            // diverged or no hypotheses; waiting for a reset
};
const char* to_string(EstimateStatus s);

/// 1-sigma / 2-sigma horizontal error ellipse from a 2x2 east/north covariance.
struct ErrorEllipse {
  double semi_major_m = 0.0;   // 1-sigma
  double semi_minor_m = 0.0;   // 1-sigma
  double orientation_rad = 0.0;  // of the major axis, clockwise from north
  static ErrorEllipse from_covariance(const Eigen::Matrix2d& cov_en_m2);
  /// Scale for a probability content in 2D: k = sqrt(-2 ln(1-p)) (e.g. 2.4477 for 95 %).
  static double scale_for_probability(double p);
};

/// The 2-D "1-sigma" region holds the probability of +-1 sigma in 1-D, 68.27 %:
/// Mahalanobis^2 <= -2 ln(1 - 0.682689) = 2.2957 (ErrorEllipse::scale_for_probability(0.6827)^2).
/// Every coverage_68 figure (replay, eval-outage, eval-fusion, eval-pdr, the terrain evaluation).
inline constexpr double kOneSigmaM2 = 2.295748928898636;

/// Squared Mahalanobis distance d' cov^-1 d of a 2-D offset (inf when cov is not positive definite);
/// <= 1 means inside the 1-sigma ellipse.
double mahalanobis2(const Eigen::Matrix2d& cov, const Eigen::Vector2d& d);

/// The probability (percent) that a 2-D Gaussian offset lies inside squared Mahalanobis distance
/// m2: the chi^2(2) CDF, 1 - exp(-m2 / 2). Where an error falls in its stated distribution
/// (50 = its median; kOneSigmaM2 -> 68.27); NaN for NaN.
double chi2_2dof_percent(double m2);

/// The median of squared Mahalanobis distances, a distance that is not finite (a covariance that
/// is not positive definite, a NaN error) counted as outside every region (+inf), as the coverage
/// figures count it; NaN when there is none. chi2_2dof_percent of it: where a walk's typical
/// error falls in its stated distribution (a walk's errors are correlated, its coverage a few draws).
double median_mahalanobis2(std::vector<double> m2);

struct Estimate {
  TimeNs t_ns = 0;
  EngineKind engine = EngineKind::kNone;
  EstimateStatus status = EstimateStatus::kNotInitialized;
  std::string reason;                 // human-readable, e.g. "GNSS lost, terrain engine"
  geo::Geodetic position;             // best estimate
  Eigen::Vector2d en_m = Eigen::Vector2d::Zero();  // east/north in the engine's local frame
  Eigen::Matrix2d cov_en_m2 = Eigen::Matrix2d::Identity();  // horizontal covariance
  double vertical_sigma_m = 0.0;
  bool valid() const { return status == EstimateStatus::kOk || status == EstimateStatus::kDegraded || status == EstimateStatus::kAmbiguous; }
  ErrorEllipse ellipse() const { return ErrorEllipse::from_covariance(cov_en_m2); }
};

}  // namespace pdnav
