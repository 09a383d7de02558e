// Robust KF: convergence on noisy fixes, the posterior residual test (> 36 rejected),
// reset after repeated rejections, coasting, and no NaN from bad input.
#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "pdnav/geo/samples.h"
#include "pdnav/gnss/kalman.h"

namespace pdnav::gnss {
namespace {

const geo::Ecef kTruth = geo::to_ecef(geo::Geodetic::from_deg(-33.9, 151.2, 50.0));
const Eigen::Matrix3d kFixCov = Eigen::Matrix3d::Identity() * 9.0;  // 3 m per axis

TEST(KalmanFilter, AveragesNoisyFixesWithZeroDisplacement) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n3(0.0, 3.0);
  KalmanOptions white;  // the averaging math: white fix noise, static process noise
  white.displacement_q_m2 = 1e-4;
  white.fix_variance_scale = 1.0;
  RobustKalman kf(white);
  for (int i = 0; i < 200; ++i) {
    if (kf.initialized()) kf.predict(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity() * 1e-6, 0.0, 1e-6);
    const Eigen::Vector3d fix = kTruth.p_m + Eigen::Vector3d(n3(rng), n3(rng), n3(rng));
    kf.update(geo::Ecef(fix), kFixCov, 10.0 + n3(rng), 9.0);
  }
  ASSERT_TRUE(kf.initialized());
  // 200 fixes of 3 m noise, process noise 1e-4 m^2 per step: a few decimetres
  EXPECT_LT((kf.position().p_m - kTruth.p_m).norm(), 1.0);
  EXPECT_NEAR(kf.clock_m(), 10.0, 1.0);
  const Eigen::Matrix3d enu = kf.position_cov_enu();
  EXPECT_LT(enu.trace(), 3.0);
  EXPECT_LT((enu - enu.transpose()).norm(), 1e-9);
  EXPECT_GT(enu.eigenvalues().real().minCoeff(), 0.0);
}

TEST(KalmanFilter, PosteriorResidualTestRejectsOutliers) {
  RobustKalman kf;
  kf.reset(kTruth, Eigen::Matrix3d::Identity() * 1.0, 0.0, 1.0);
  kf.predict(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity() * 1e-4, 0.0, 1e-4);
  const Eigen::Vector3d before = kf.position().p_m;
  const KalmanUpdateResult bad = kf.update(geo::Ecef(kTruth.p_m + Eigen::Vector3d(60.0, 0, 0)), kFixCov, 0.0, 9.0);
  EXPECT_FALSE(bad.accepted);
  EXPECT_GT(bad.max_normalised_residual, 36.0);
  EXPECT_EQ(kf.position().p_m, before);
  const KalmanUpdateResult good = kf.update(geo::Ecef(kTruth.p_m + Eigen::Vector3d(2.0, -1.0, 0)), kFixCov, 0.0, 9.0);
  EXPECT_TRUE(good.accepted);
  EXPECT_LT(good.max_normalised_residual, 36.0);
}

TEST(KalmanFilter, FollowsDisplacementsAndResetsAfterPersistentRejections) {
  KalmanOptions opt;
  opt.max_consecutive_rejections = 3;
  RobustKalman kf(opt);
  kf.reset(kTruth, Eigen::Matrix3d::Identity() * 0.01, 0.0, 1.0);
  const Eigen::Vector3d step(1.0, 0.5, 0.0);
  kf.predict(step, Eigen::Matrix3d::Identity() * 1e-4, 5.0, 1e-4);
  EXPECT_LT((kf.position().p_m - (kTruth.p_m + step)).norm(), 1e-9);
  EXPECT_NEAR(kf.clock_m(), 5.0, 1e-9);
  // the receiver really jumped 200 m (e.g. a wrong start): after 3 rejections the filter resets
  const geo::Ecef moved(kTruth.p_m + Eigen::Vector3d(200.0, 0, 0));
  int resets = 0;
  for (int i = 0; i < 5; ++i) resets += kf.update(moved, kFixCov, 5.0, 9.0).reset ? 1 : 0;
  EXPECT_EQ(resets, 1);
  EXPECT_LT((kf.position().p_m - moved.p_m).norm(), 5.0);
}

TEST(KalmanFilter, CoastingGrowsTheCovarianceAndBadInputIsIgnored) {
  RobustKalman kf;
  kf.update(kTruth, kFixCov, 0.0, 9.0);  // first fix initialises
  ASSERT_TRUE(kf.initialized());
  const double before = kf.position_cov_ecef().trace();
  kf.coast(10.0);
  EXPECT_NEAR(kf.position_cov_ecef().trace(), before + 3 * 4.0 * 10.0, 1e-6);
  kf.predict(Eigen::Vector3d(kNaN, 0, 0), Eigen::Matrix3d::Identity(), 0.0, 1.0);
  kf.update(geo::Ecef(kNaN, 0, 0), kFixCov, 0.0, 9.0);
  kf.update(kTruth, kFixCov, kNaN, 9.0);
  kf.coast(-1.0);
  kf.reset_clock(kNaN, kNaN);
  EXPECT_TRUE(kf.state().allFinite());
  EXPECT_TRUE(kf.covariance().allFinite());
  EXPECT_LT((kf.position().p_m - kTruth.p_m).norm(), 1e-9);
}

}  // namespace
}  // namespace pdnav::gnss
