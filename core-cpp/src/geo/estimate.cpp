#include "pdnav/geo/estimate.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

namespace pdnav {

const char* to_string(EngineKind k) {
  switch (k) {
    case EngineKind::kNone: return "none";
    case EngineKind::kDeadReckoning: return "dead-reckoning";
    case EngineKind::kTerrain: return "terrain";
    case EngineKind::kRoute: return "route";
    case EngineKind::kGnss: return "gnss";
  }
  return "?";
}

const char* to_string(EstimateStatus s) {
  switch (s) {
    case EstimateStatus::kNotInitialized: return "not-initialized";
    case EstimateStatus::kOk: return "ok";
    case EstimateStatus::kDegraded: return "degraded";
    case EstimateStatus::kAmbiguous: return "ambiguous";
    case EstimateStatus::kLost: return "lost";
  }
  return "?";
}

ErrorEllipse ErrorEllipse::from_covariance(const Eigen::Matrix2d& cov) {
  ErrorEllipse e;
  if (!cov.allFinite()) {
    e.semi_major_m = e.semi_minor_m = std::numeric_limits<double>::quiet_NaN();
    return e;
  }
  const Eigen::Matrix2d sym = 0.5 * (cov + cov.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(sym);
  const Eigen::Vector2d ev = es.eigenvalues().cwiseMax(0.0);  // ascending
  const Eigen::Vector2d major = es.eigenvectors().col(1);     // (east, north)
  e.semi_major_m = std::sqrt(ev(1));
  e.semi_minor_m = std::sqrt(ev(0));
  double az = std::atan2(major.x(), major.y());  // clockwise from north
  if (az < 0) az += kPi;
  if (az >= kPi) az -= kPi;
  e.orientation_rad = az;
  return e;
}

double ErrorEllipse::scale_for_probability(double p) { return std::sqrt(-2.0 * std::log(1.0 - p)); }

double mahalanobis2(const Eigen::Matrix2d& cov, const Eigen::Vector2d& d) {
  const double a = cov(0, 0), b = 0.5 * (cov(0, 1) + cov(1, 0)), c = cov(1, 1);
  const double det = a * c - b * b;
  if (!(det > 0.0) || !(a > 0.0)) return std::numeric_limits<double>::infinity();
  return (c * d.x() * d.x() - 2.0 * b * d.x() * d.y() + a * d.y() * d.y()) / det;
}

double chi2_2dof_percent(double m2) { return 100.0 * (1.0 - std::exp(-0.5 * m2)); }

double median_mahalanobis2(std::vector<double> m2) {
  if (m2.empty()) return std::numeric_limits<double>::quiet_NaN();
  for (double& x : m2)
    if (!std::isfinite(x)) x = std::numeric_limits<double>::infinity();
  std::sort(m2.begin(), m2.end());
  const std::size_t h = m2.size() / 2;
  return m2.size() % 2 ? m2[h] : 0.5 * (m2[h - 1] + m2[h]);
}

}  // namespace pdnav
