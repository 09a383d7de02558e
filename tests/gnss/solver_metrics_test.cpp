// The accuracy metrics against a static truth: the KF's 68 % coverage counts the epochs whose
// horizontal error lies inside the reported covariance's 2-D 68 % ellipse (Mahalanobis^2 <= 2.279);
// along a truth track, the 1 s displacement against the track's own.
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

// A receiver moving east at 5 m/s along a truth track: the 1 s displacement is scored against the
// truth's own displacement over the same second (not against zero, as for a static receiver);
// intervals other than 1 s +- 0.1 s, and seconds the track does not cover, are not scored.
TEST(SolverMetrics, TrackDisplacementErrorIsAgainstTheTruthsOwnDisplacement) {
  const geo::LocalFrame frame(kTruth);
  TruthTrack track;
  for (int k = 0; k <= 10; ++k)
    track.points.push_back({static_cast<std::int64_t>(k) * 1000000000LL, frame.to_geodetic(geo::Enu(5.0 * k, 0.0, 0.0))});
  std::vector<EpochSolution> sols;
  for (int k = 1; k <= 12; ++k) {
    EpochSolution s;
    s.gps_ns = static_cast<std::int64_t>(k) * 1000000000LL;
    s.disp_source = k % 2 == 0 ? "tdcp" : "doppler";
    s.disp_dt_s = 1.0;
    s.tdcp_disp_m = k % 2 == 0 ? Eigen::Vector3d(5.03, 0.04, 0.0) : Eigen::Vector3d(4.7, 0.0, 0.0);
    sols.push_back(s);
  }
  sols[4].disp_dt_s = 2.0;  // k = 5: a 2 s interval, not scored
  const TrackAccuracy a = evaluate_track(sols, track);
  EXPECT_EQ(a.tdcp_epochs, 5);     // k = 2, 4, 6, 8, 10 (11 and 12 are past the track)
  EXPECT_EQ(a.doppler_epochs, 4);  // k = 1, 3, 7, 9
  // 0.1 mm: the local frames along 50 m of track turn by ~1e-5 rad against the start's
  EXPECT_NEAR(a.tdcp_err_rms_enu_m.x(), 0.03, 1e-4);
  EXPECT_NEAR(a.tdcp_err_rms_enu_m.y(), 0.04, 1e-4);
  EXPECT_NEAR(a.tdcp_err_rms_max_axis_m(), 0.04, 1e-4);
  EXPECT_NEAR(a.doppler_err_rms_enu_m.x(), 0.3, 1e-4);
}

}  // namespace
}  // namespace pdnav::gnss
