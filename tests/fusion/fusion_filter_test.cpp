// The fused filter's gate (issue 14): a multipath jump is rejected, a real correction accepted
// after consistent disagreement, re-acquisition after an outage needs agreeing epochs, and
// TDCP displacements are used. The walk and the GNSS errors here are not the filter's model:
// the GNSS noise is uniform and the jump a constant offset.
#include <cmath>
#include <random>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "pdnav/fusion/fusion_filter.h"

namespace pdnav::fusion {
namespace {

/// A 0.7 m PDR step north at t.
PdrStep step_north(TimeNs t) {
  PdrStep s;
  s.t_ns = t;
  s.length_m = 0.7;
  s.heading_rad = 0.0;
  s.length_sigma_m = 0.05;
  s.heading_sigma_rad = 0.05;
  return s;
}

struct Sim {
  FusionFilter f;
  std::mt19937_64 rng{5};
  std::uniform_real_distribution<double> u{-1.0, 1.0};
  Eigen::Vector2d truth = Eigen::Vector2d::Zero();
  TimeNs t = 0;
  Sim() { f.initialize(Eigen::Vector2d::Zero(), 3.0, 0); }
  /// Walk one second east (2 steps); a GNSS epoch with `offset` on top of +-2 m uniform noise.
  PositionUpdateResult second(const Eigen::Vector2d& offset, bool gnss = true) {
    for (int k = 0; k < 2; ++k) {
      t += 500 * kNsPerMs;
      PdrStep s;
      s.t_ns = t;
      s.length_m = 0.7;
      s.heading_rad = kPi / 2;
      s.length_sigma_m = 0.05;
      s.heading_sigma_rad = 0.05;
      f.predict(s);
      truth.x() += 0.7;
    }
    PositionUpdateResult r;
    if (gnss) r = f.update_position(t, truth + offset + Eigen::Vector2d(2 * u(rng), 2 * u(rng)), 4.0 * Eigen::Matrix2d::Identity());
    return r;
  }
};

TEST(FusionFilter, MultipathJumpIsRejected) {
  Sim s;
  for (int k = 0; k < 60; ++k) s.second(Eigen::Vector2d::Zero());
  const Eigen::Vector2d jump(40.0, -25.0);
  for (int k = 0; k < 3; ++k) EXPECT_FALSE(s.second(jump).accepted) << k;  // 3 epochs of multipath
  EXPECT_TRUE(s.second(Eigen::Vector2d::Zero()).accepted);
  EXPECT_LT((s.f.position_en_m() - s.truth).norm(), 4.0);
}

TEST(FusionFilter, ConsistentDisagreementIsAcceptedAsARealCorrection) {
  Sim s;
  for (int k = 0; k < 60; ++k) s.second(Eigen::Vector2d::Zero());
  // the filter is wrong by 30 m (e.g. a wrong start); GNSS is right from now on
  s.truth += Eigen::Vector2d(0.0, 30.0);
  int rejected = 0;
  bool forced = false;
  for (int k = 0; k < 10 && !forced; ++k) {
    const PositionUpdateResult r = s.second(Eigen::Vector2d::Zero());
    forced = r.forced;
    rejected += r.accepted ? 0 : 1;
  }
  EXPECT_TRUE(forced);
  EXPECT_EQ(rejected, s.f.options().confirm_epochs - 1);
  for (int k = 0; k < 5; ++k) s.second(Eigen::Vector2d::Zero());
  EXPECT_LT((s.f.position_en_m() - s.truth).norm(), 4.0);
}

TEST(FusionFilter, ReacquisitionAfterAnOutageNeedsAgreement) {
  Sim s;
  for (int k = 0; k < 30; ++k) s.second(Eigen::Vector2d::Zero());
  for (int k = 0; k < 60; ++k) s.second(Eigen::Vector2d::Zero(), /*gnss=*/false);  // a 60 s outage
  const PositionUpdateResult first = s.second(Eigen::Vector2d::Zero());
  EXPECT_FALSE(first.accepted);
  EXPECT_NE(first.reason.find("re-acquisition"), std::string::npos) << first.reason;
  const PositionUpdateResult second = s.second(Eigen::Vector2d::Zero());
  EXPECT_TRUE(second.accepted) << second.reason;
  EXPECT_TRUE(second.reacquired);
}

TEST(FusionFilter, CovarianceGrowsInAnOutageAndShrinksWithGnss) {
  Sim s;
  for (int k = 0; k < 30; ++k) s.second(Eigen::Vector2d::Zero());
  const double before = s.f.position_cov_m2().trace();
  for (int k = 0; k < 120; ++k) s.second(Eigen::Vector2d::Zero(), false);
  const double during = s.f.position_cov_m2().trace();
  EXPECT_GT(during, 4.0 * before);
  // the error after 2 min of dead reckoning is inside 3 sigma of the stated covariance
  const Eigen::Vector2d err = s.f.position_en_m() - s.truth;
  EXPECT_LT(err.dot(s.f.position_cov_m2().inverse() * err), 11.83);
}

TEST(FusionFilter, TdcpDisplacementCorrectsTheStepLength) {
  // PDR says 0.7 m per step, the walker makes 0.8 m: TDCP displacements (no positions) pull the
  // residual scale state towards +14 %
  FusionFilter f;
  f.initialize(Eigen::Vector2d::Zero(), 3.0, 0);
  TimeNs t = 0;
  double truth = 0.0;
  f.clone(t);
  for (int k = 0; k < 120; ++k) {
    const TimeNs from = t;
    for (int j = 0; j < 2; ++j) {
      t += 500 * kNsPerMs;
      f.predict(step_north(t));
      truth += 0.8;
    }
    EXPECT_TRUE(f.update_displacement(t, from, Eigen::Vector2d(0.0, 1.6), 0.01 * Eigen::Matrix2d::Identity())) << k;
    f.clone(t);
  }
  EXPECT_NEAR(f.scale_error(), 0.8 / 0.7 - 1.0, 0.02);
}

// Issue 27: a direct step-scale sample (the route engine's two matched turns) moves the residual
// scale and nothing else; the steps after it are corrected; a sample beyond 3 sigma is refused.
TEST(FusionFilter, AStepScaleSampleMovesOnlyTheScale) {
  FusionFilter f;
  f.initialize(Eigen::Vector2d::Zero(), 3.0, 0);
  TimeNs t = 0;
  auto walk = [&](int n) {
    for (int k = 0; k < n; ++k) {
      t += 500 * kNsPerMs;
      f.predict(step_north(t));
    }
  };
  walk(100);
  const Eigen::Vector2d p0 = f.position_en_m();
  const double var0 = f.scale_error_var();
  ASSERT_GT(var0, 0.01);  // the unknown walker's prior (18 %)
  double nis = 0.0;
  EXPECT_FALSE(f.update_scale(t, 1.0, 0.05 * 0.05, &nis));  // 100 % longer: beyond the gate
  EXPECT_GT(nis, 9.0);
  EXPECT_TRUE(f.update_scale(t, 0.15, 0.05 * 0.05, &nis));
  EXPECT_NEAR(f.scale_error(), 0.15 * var0 / (var0 + 0.0025), 1e-9);  // the scalar Kalman gain
  EXPECT_NEAR(f.scale_error_var(), var0 * 0.0025 / (var0 + 0.0025), 1e-9);
  EXPECT_EQ(f.position_en_m(), p0);  // the position is not moved by it
  const double ds = f.scale_error();
  walk(10);  // (the Gauss-Markov scale fades by exp(-5 s / 300 s) meanwhile)
  EXPECT_NEAR(f.position_en_m().y() - p0.y(), 10 * 0.7 * (1.0 + ds), 0.01);
  EXPECT_GT(ds, 0.13);
}

// Issue 14: an already-filtered GNSS position (the engine's KF) is time-correlated, so a run of
// them never makes the fused position more certain than one of them: with floor_fraction 1
// the position covariance stays >= R; the default (0.25) lets it fall to R / 4.
TEST(FusionFilter, FloorFractionOverrideKeepsPositionCovarianceAtTheFilteredMeasurements) {
  const Eigen::Matrix2d r = 1.5 * 1.5 * Eigen::Matrix2d::Identity();
  auto run = [&](double floor_fraction) {
    FusionFilter f;
    f.initialize(Eigen::Vector2d::Zero(), 3.0, 0);
    for (int k = 1; k <= 120; ++k) {
      const PositionUpdateResult res =
          f.update_position(k * kNsPerS, Eigen::Vector2d(0.5, -0.5), r, true, floor_fraction);
      if (k > 2) EXPECT_TRUE(res.accepted) << k;
    }
    const Eigen::Matrix2d p = f.position_cov_m2();
    return 0.5 * p.trace() - std::sqrt(0.25 * p.trace() * p.trace() - p.determinant());  // smallest eigenvalue
  };
  const double lmin_kf = run(1.0), lmin_default = run(-1.0);
  EXPECT_GE(lmin_kf, 0.999 * r(0, 0));
  EXPECT_LT(lmin_kf, 1.2 * r(0, 0));  // not inflated beyond the floor
  EXPECT_LT(lmin_default, 0.5 * r(0, 0));
  EXPECT_GE(lmin_default, 0.999 * 0.25 * r(0, 0));
}

// Issue 28: an aiding engine's estimate correlated with the filter's (same PDR steps) is fused by
// covariance intersection: the same estimate given 20 times never makes the filter more certain
// than the estimate itself (a Kalman update would claim R / 20), and the filter moves onto it.
TEST(FusionFilter, CovarianceIntersectionNeverAveragesARepeatedEstimate) {
  FusionFilter f;
  f.initialize(Eigen::Vector2d::Zero(), 20.0, 0);
  const Eigen::Vector2d z(15.0, -10.0);
  const Eigen::Matrix2d r = 25.0 * Eigen::Matrix2d::Identity();
  for (int k = 1; k <= 20; ++k) {
    const PositionUpdateResult res = f.update_position_ci(k * kNsPerS, z, r);
    ASSERT_TRUE(res.accepted) << res.reason;
  }
  const Eigen::Matrix2d p = f.position_cov_m2();
  const double lmin = 0.5 * p.trace() - std::sqrt(0.25 * p.trace() * p.trace() - p.determinant());
  EXPECT_GT(lmin, 0.9 * 25.0);
  EXPECT_LT((f.position_en_m() - z).norm(), 1.0);
  // the plain Kalman update, for contrast, claims it averaged out
  FusionFilterOptions o;
  o.position_floor_fraction = 0.0;
  FusionFilter g(o);
  g.initialize(Eigen::Vector2d::Zero(), 20.0, 0);
  for (int k = 1; k <= 20; ++k) g.update_position(k * kNsPerS, z, r, /*use_gate_policy=*/false);
  EXPECT_LT(g.position_cov_m2()(0, 0), 0.1 * 25.0);
}

// Issue 28: the heading bias is a Gauss-Markov process with the PDR's stated sigma; the variance
// of the bias now given a fit of its window mean follows the integrated exponential covariance.
TEST(FusionFilter, HeadingBiasVarianceAfterAWindowFollowsTheGaussMarkovModel) {
  FusionFilter f;  // tau 300 s
  f.initialize(Eigen::Vector2d::Zero(), 3.0, 0);
  PdrStep s;
  s.t_ns = kNsPerS;
  s.length_m = 0.7;
  s.heading_rad = 0.0;
  s.length_sigma_m = 0.05;
  s.heading_sigma_rad = 15.0 * kDegToRad;
  f.predict(s);
  const double sh2 = std::pow(15.0 * kDegToRad, 2), fit = std::pow(2.0 * kDegToRad, 2);
  EXPECT_NEAR(f.heading_bias_var_after_window(fit, 1e-6), fit, 1e-9);
  // u = W / tau = 1: g = 1 - 2 (1 - 1/e) + 2 / e = 0.4715
  EXPECT_NEAR(f.heading_bias_var_after_window(fit, 300.0), fit + 0.4715 * sh2, 1e-3 * sh2);
  EXPECT_NEAR(f.heading_bias_var_after_window(fit, 3e5), fit + sh2, 0.01 * sh2);
  FusionFilterOptions white;
  white.heading_bias_tau_s = 0.0;  // the model before issue 28: the fit's variance only
  FusionFilter g(white);
  g.initialize(Eigen::Vector2d::Zero(), 3.0, 0);
  g.predict(s);
  EXPECT_NEAR(g.heading_bias_var_after_window(fit, 300.0), fit, 1e-12);
  // the expected bias fades from the calibrated value as the Gauss-Markov mean: 1/e after tau
  const double b = 8.0 * kDegToRad;
  EXPECT_NEAR(f.heading_bias_expected(b, 0.0), b, 1e-12);
  EXPECT_NEAR(f.heading_bias_expected(b, 300.0), b / std::exp(1.0), 1e-9);
  EXPECT_NEAR(f.heading_bias_expected(b, 3e4), 0.0, 1e-9);
  EXPECT_NEAR(g.heading_bias_expected(b, 300.0), b, 1e-12);  // no model: the calibration holds
  FusionFilter unknown;  // no step yet: the PDR's sigma (the stationary one) is not known
  unknown.initialize(Eigen::Vector2d::Zero(), 3.0, 0);
  EXPECT_NEAR(unknown.heading_bias_expected(b, 300.0), b, 1e-12);
}

// Issue 28: the residual step-scale error is a Gauss-Markov process. Before a calibration its
// stationary sigma is the unknown walker's (initial_scale_sigma: the spread between walkers, a
// constant the filter never forgets it does not know); once a calibration has learnt the walker,
// what wanders is the scale within the walk (scale_within_walk_sigma), and the calibration's
// knowledge fades to that, at the rate the window fit's own variance predicts.
TEST(FusionFilter, ScaleErrorFadesBackToTheWithinWalkSigmaAsAGaussMarkovProcess) {
  FusionFilter f;  // scale_tau_s 300 s, initial_scale_sigma 0.18, scale_within_walk_sigma 0.10
  const double tau = f.options().scale_tau_s, prior2 = std::pow(f.options().initial_scale_sigma, 2),
               walk2 = std::pow(f.options().scale_within_walk_sigma, 2);
  ASSERT_GT(tau, 0.0);
  ASSERT_GT(walk2, 0.0);
  ASSERT_LT(walk2, prior2);
  f.initialize(Eigen::Vector2d::Zero(), 3.0, 0);
  const double fit = 0.02 * 0.02;
  EXPECT_NEAR(f.scale_var_after_window(fit, 1e-6), fit, 1e-9);
  EXPECT_NEAR(f.scale_var_after_window(fit, tau), fit + 0.4715 * walk2, 1e-3 * walk2);  // g(1) = 0.4715
  f.set_residual_uncertainty(1e-4, fit);
  const double rw = f.options().scale_rw_1ps;
  f.advance_to(static_cast<TimeNs>(tau * 1e9 / 2));  // in two steps: the same as one
  f.advance_to(static_cast<TimeNs>(tau * 1e9));      // one correlation time: phi = 1/e
  const double phi2 = std::exp(-2.0);
  EXPECT_NEAR(f.scale_error_var(), phi2 * fit + (1.0 - phi2) * walk2, 1e-9);
  f.advance_to(static_cast<TimeNs>(20.0 * tau * 1e9));  // long after: the within-walk variance
  EXPECT_NEAR(f.scale_error_var(), walk2, 1e-9);
  // an uncalibrated filter stays at the prior: it never claims less than it started with
  FusionFilter g;
  g.initialize(Eigen::Vector2d::Zero(), 3.0, 0);
  g.advance_to(static_cast<TimeNs>(600e9));
  EXPECT_NEAR(g.scale_error_var(), prior2, 1e-12);
  // ... and a new start forgets the calibration: the prior again
  f.initialize(Eigen::Vector2d::Zero(), 3.0, static_cast<TimeNs>(21.0 * tau * 1e9));
  f.advance_to(static_cast<TimeNs>(40.0 * tau * 1e9));
  EXPECT_NEAR(f.scale_error_var(), prior2, 1e-12);
  // scale_within_walk_sigma <= 0: the walker's prior throughout (the model before)
  FusionFilterOptions one_level;
  one_level.scale_within_walk_sigma = 0.0;
  FusionFilter k(one_level);
  k.initialize(Eigen::Vector2d::Zero(), 3.0, 0);
  EXPECT_NEAR(k.scale_var_after_window(fit, tau), fit + 0.4715 * prior2, 1e-3 * prior2);
  k.set_residual_uncertainty(1e-4, fit);
  k.advance_to(static_cast<TimeNs>(20.0 * tau * 1e9));
  EXPECT_NEAR(k.scale_error_var(), prior2, 1e-9);
  // scale_tau_s = 0: the random walk alone (before this model)
  FusionFilterOptions rw_only;
  rw_only.scale_tau_s = 0.0;
  FusionFilter h(rw_only);
  h.initialize(Eigen::Vector2d::Zero(), 3.0, 0);
  h.set_residual_uncertainty(1e-4, fit);
  h.advance_to(static_cast<TimeNs>(tau * 1e9));
  EXPECT_NEAR(h.scale_error_var(), fit + rw * tau, 1e-12);
  EXPECT_NEAR(h.scale_var_after_window(fit, tau), fit, 1e-12);
}

TEST(FusionFilter, Chi2QuantileMatchesTables) {
  EXPECT_NEAR(chi2_quantile(2, 0.99), 9.21, 0.15);
  EXPECT_NEAR(chi2_quantile(8, 0.99), 20.09, 0.2);
}

}  // namespace
}  // namespace pdnav::fusion

namespace pdnav::fusion {
namespace {

// The route engine's clusters weighed by the fused prediction (Navigator: route_cluster_association).
TEST(AidAssociation, ThePredictionPicksAmongTheClustersAndSaysWhenItCannot) {
  const Eigen::Matrix2d r = Eigen::Matrix2d::Identity() * 26.0;  // a 1 m cluster + the 5 m aiding floor
  // the leading cluster (weight 0.7) 45 m east, a minority one (0.3) 8 m from a 10 m prediction
  const std::vector<AidHypothesis> two = {{Eigen::Vector2d(45.0, 0.0), r, 0.7}, {Eigen::Vector2d(0.0, 8.0), r, 0.3}};
  const AidAssociation near = associate(Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity() * 100.0, two);
  EXPECT_EQ(near.index, 1);
  EXPECT_LT(near.runner_up, 0.01);
  // a 60 m prediction cannot tell them apart: the weights decide, and the other is close behind
  const AidAssociation broad = associate(Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity() * 3600.0, two);
  EXPECT_EQ(broad.index, 0);
  EXPECT_GT(broad.runner_up, 0.3);
  // symmetric clusters either side of the prediction: equally likely
  const std::vector<AidHypothesis> sym = {{Eigen::Vector2d(-20.0, 0.0), r, 0.5}, {Eigen::Vector2d(20.0, 0.0), r, 0.5}};
  EXPECT_NEAR(associate(Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity() * 100.0, sym).runner_up, 1.0, 1e-9);
  // nothing usable
  EXPECT_EQ(associate(Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity(), {}).index, -1);
  EXPECT_EQ(associate(Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity(), {{Eigen::Vector2d(1.0, 0.0), r, 0.0}}).index, -1);
}

}  // namespace
}  // namespace pdnav::fusion
