#include <cmath>

#include <gtest/gtest.h>

#include "pdnav/fusion/dead_reckoning.h"

using namespace pdnav;

TEST(DeadReckoning, NotInitializedUntilStart) {
  fusion::DeadReckoning dr;
  dr.feed(PdrStep{1, 0.7, 0.0, 0.1, 0.1});
  EXPECT_EQ(dr.estimate().status, EstimateStatus::kNotInitialized);
}

TEST(DeadReckoning, SquareWalkClosesAndCovarianceGrows) {
  fusion::DeadReckoning dr;
  const auto start = geo::Geodetic::from_deg(42.5, 1.5, 1500.0);
  dr.initialize(start, 5.0, 0);
  TimeNs t = 0;
  double prev_trace = dr.estimate().cov_en_m2.trace();
  for (int side = 0; side < 4; ++side) {
    for (int i = 0; i < 100; ++i) {
      t += 550 * kNsPerMs;
      dr.feed(PdrStep{t, 0.75, side * kPi / 2, 0.0, 0.0});
      // Walking away from the start, position uncertainty only grows. (Walking back it may
      // shrink: a shared heading bias rotates the whole path about the start point.)
      const double tr = dr.estimate().cov_en_m2.trace();
      if (side == 0) EXPECT_GE(tr, prev_trace - 1e-9);
      prev_trace = tr;
    }
    const Estimate e = dr.estimate();
    const double expect_e[] = {0.0, 75.0, 75.0, 0.0};
    const double expect_n[] = {75.0, 75.0, 0.0, 0.0};
    EXPECT_NEAR(e.en_m.x(), expect_e[side], 1e-6);
    EXPECT_NEAR(e.en_m.y(), expect_n[side], 1e-6);
  }
  const Estimate e = dr.estimate();
  EXPECT_LT(geo::horizontal_distance_m(start, e.position), 1e-3);
  // a 15 deg heading bias decorrelating with tau = 60 s over a 220 s walk leaves the closed
  // square uncertain by more than the 5 m start sigma
  EXPECT_GT(std::sqrt(e.cov_en_m2.trace()), 5.0 * std::sqrt(2.0) + 1.0);
  EXPECT_TRUE(e.cov_en_m2.allFinite());
}

TEST(DeadReckoning, IgnoresNonFiniteSteps) {
  fusion::DeadReckoning dr;
  dr.initialize(geo::Geodetic::from_deg(0, 0, 0), 1.0, 0);
  dr.feed(PdrStep{1, std::nan(""), 0.0, 0.0, 0.0});
  dr.feed(PdrStep{2, 1.0, std::numeric_limits<double>::infinity(), 0.0, 0.0});
  EXPECT_NEAR(dr.estimate().en_m.norm(), 0.0, 1e-12);
  EXPECT_TRUE(dr.estimate().cov_en_m2.allFinite());
}
