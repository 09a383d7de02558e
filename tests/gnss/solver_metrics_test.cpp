// The accuracy metrics against a static truth: the KF's 68 % coverage counts the epochs whose
// horizontal error lies inside the reported covariance's 2-D 68 % ellipse (Mahalanobis^2 <= 2.279).
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/geo/frames.h"
#include "pdnav/gnss/solver_metrics.h"

namespace pdnav::gnss {
namespace {

const geo::Geodetic kTruth = geo::Geodetic::from_deg(42.5, 1.5, 1000.0);

EpochSolution kf_at(double east_m, double north_m, double sigma_e_m, double sigma_n_m) {
  const geo::LocalFrame frame(kTruth);
  EpochSolution s;
  s.kf = geo::to_ecef(frame.to_geodetic(geo::Enu(east_m, north_m, 0.0)));
  s.kf_ok = true;
  s.kf_cov_enu = Eigen::Vector3d(sigma_e_m * sigma_e_m, sigma_n_m * sigma_n_m, 4.0).asDiagonal();
  return s;
}

TEST(SolverMetrics, StaticKfCoverageCountsEpochsInsideThe68PercentEllipse) {
  std::vector<EpochSolution> sols;
  sols.push_back(kf_at(1.0, 0.0, 1.0, 1.0));   // d^2 = 1: inside
  sols.push_back(kf_at(0.0, 1.4, 1.0, 1.0));   // 1.96: inside
  sols.push_back(kf_at(1.6, 0.0, 1.0, 1.0));   // 2.56: outside
  sols.push_back(kf_at(3.0, 0.0, 2.0, 0.5));   // 2.25 along the long axis: inside
  sols.push_back(kf_at(0.0, 0.8, 2.0, 0.5));   // 2.56 across it: outside
  EpochSolution spp_only;                       // no KF fix: not scored
  spp_only.spp = geo::to_ecef(kTruth);
  spp_only.spp_ok = true;
  sols.push_back(spp_only);
  const StaticAccuracy a = evaluate_static(sols, kTruth);
  EXPECT_EQ(a.kf_epochs, 5);
  EXPECT_NEAR(a.kf_coverage68, 3.0 / 5.0, 1e-12);
  EXPECT_NEAR(a.kf_p50_h_m, 1.4, 1e-6);
}

TEST(SolverMetrics, NoKfFixMeansNoCoverage) {
  EXPECT_TRUE(std::isnan(evaluate_static({}, kTruth).kf_coverage68));
}

}  // namespace
}  // namespace pdnav::gnss
