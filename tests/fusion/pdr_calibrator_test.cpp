// PDR calibration from GNSS (issue 14): after 5 minutes of open-sky GNSS on a simulated walk with
// a known step-length scale and heading bias, the scale is within 2 % and the bias within 3 deg.
// The simulation does not use the filter's error model: the heading bias is a constant plus
// uniform (not Gaussian) per-step noise, the length error uniform, and the GNSS errors a sum of
// slow sinusoids (multipath-like, time-correlated) plus Laplace noise.
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/fusion/pdr_calibrator.h"

namespace pdnav::fusion {
namespace {

struct Walk {
  double true_scale = 1.07;            // true step = 1.07 x the PDR's step
  double true_bias_rad = 6.0 * kDegToRad;  // PDR heading = true heading + 6 deg
  double bias_drift_rad = 0.0;             // the bias moves linearly by this over the walk
};

/// The GNSS course over ground fed beside the positions: none, or the direction the walker
/// moved `lag_s` earlier (a chipset's velocity filter lags at turns) plus a slow wander and
/// uniform noise (not the calibrator's Gaussian model).
struct CourseFeed {
  bool on = false;
  double lag_s = 2.0;
  double wander_rad = 4.0 * kDegToRad, noise_rad = 10.0 * kDegToRad;
};

/// The GNSS speed fed beside the positions (TDCP/Doppler): none, or the walker's speed over the
/// last step plus a slow wander and uniform noise (not the calibrator's Gaussian model).
struct SpeedFeed {
  bool on = false;
  double wander_mps = 0.05, noise_mps = 0.15;
};

PdrCalibration run(const Walk& w, double minutes, std::uint64_t seed, double multipath_m = 3.0,
                   const CourseFeed& course = {}, PdrCalibration* last = nullptr, const SpeedFeed& speed = {}) {
  std::mt19937_64 rng(seed), speed_rng(seed + 1000);  // (the speed's own draws: the same walk with or without it)
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::exponential_distribution<double> expo(1.0);
  auto laplace = [&](double b) { return (u(rng) > 0 ? 1.0 : -1.0) * b * expo(rng); };
  PdrCalibrator cal;
  const TimeNs step_ns = 550 * kNsPerMs;
  double heading = 0.3, e = 0.0, n = 0.0;
  double next_turn_s = 30.0;
  const double ph1 = u(rng) * kPi, ph2 = u(rng) * kPi;
  TimeNs next_gnss = kNsPerS;
  std::vector<std::pair<double, double>> headings;  // (t, true heading) per step, for the lagged course
  for (TimeNs t = 0; t < static_cast<TimeNs>(minutes * 60.0) * kNsPerS; t += step_ns) {
    const double ts = static_cast<double>(t) * 1e-9;
    if (ts > next_turn_s) {  // a turn of 40-140 deg either way every 20-60 s
      heading += (u(rng) > 0 ? 1.0 : -1.0) * (40.0 + 50.0 * (u(rng) + 1.0)) * kDegToRad;
      next_turn_s = ts + 40.0 + 20.0 * u(rng);
    }
    const double true_len = 0.75 * (1.0 + 0.05 * u(rng));
    headings.emplace_back(ts, heading);
    e += true_len * std::sin(heading);
    n += true_len * std::cos(heading);
    PdrStep s;
    s.t_ns = t;
    s.length_m = true_len / w.true_scale * (1.0 + 0.04 * u(rng));
    s.heading_rad = heading + w.true_bias_rad + w.bias_drift_rad * ts / (minutes * 60.0) + 8.0 * kDegToRad * u(rng);
    cal.add_step(s);
    while (next_gnss <= t) {
      const double tg = static_cast<double>(next_gnss) * 1e-9;
      const Eigen::Vector2d err(multipath_m * std::sin(2 * kPi * tg / 47.0 + ph1) + laplace(1.5),
                                multipath_m * std::cos(2 * kPi * tg / 71.0 + ph2) + laplace(1.5));
      if (course.on) {
        double h = headings.front().second;
        for (const auto& [th, hh] : headings)
          if (th <= tg - course.lag_s) h = hh;
        cal.add_course(next_gnss, h + course.wander_rad * std::sin(2 * kPi * tg / 83.0 + ph2) + course.noise_rad * u(rng),
                       1.36, std::nan(""));
      }
      if (speed.on)
        cal.add_speed(next_gnss,
                      true_len / (static_cast<double>(step_ns) * 1e-9) + speed.wander_mps * std::sin(2 * kPi * tg / 61.0 + ph1) +
                          speed.noise_mps * u(speed_rng),
                      0.1);
      cal.add_gnss(next_gnss, Eigen::Vector2d(e, n) + err, 4.0);
      next_gnss += kNsPerS;
    }
  }
  if (!cal.published().valid) {
    const PdrCalibration& l = cal.calibration();
    std::printf("last fit: epochs %d baseline %.1f scale %.4f +- %.4f bias %.2f +- %.2f deg\n", l.epochs, l.baseline_m, l.scale,
                l.scale_sigma, l.heading_bias_rad / kDegToRad, l.heading_bias_sigma_rad / kDegToRad);
  }
  if (last) *last = cal.calibration();
  return cal.published();
}

TEST(PdrCalibrator, FiveMinutesOfOpenSkyGiveScaleWithin2PercentAndBiasWithin3Deg) {
  const Walk w;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const PdrCalibration c = run(w, 5.0, seed);
    ASSERT_TRUE(c.valid) << "seed " << seed << ": epochs " << c.epochs << " baseline " << c.baseline_m;
    EXPECT_NEAR(c.scale, w.true_scale, 0.02 * w.true_scale) << "seed " << seed;
    EXPECT_NEAR(c.heading_bias_rad, w.true_bias_rad, 3.0 * kDegToRad) << "seed " << seed;
    // the stated 1-sigma covers the error (3 sigma)
    EXPECT_LT(std::abs(c.scale - w.true_scale), 3.0 * c.scale_sigma + 1e-3) << "seed " << seed;
    EXPECT_LT(std::abs(c.heading_bias_rad - w.true_bias_rad), 3.0 * c.heading_bias_sigma_rad + 1e-3) << "seed " << seed;
    // a constant bias: the two halves of the window agree (issue 28)
    EXPECT_LT(c.heading_bias_drift_sigma_rad, 5.0 * kDegToRad) << "seed " << seed;
    EXPECT_TRUE(c.heading_applied) << "seed " << seed;
  }
}

// Issue 28: a heading bias that moves by 40 deg over the window (a walk through magnetic
// disturbances) is seen moving; what is published never claims to know the bias now better than
// it does: either the heading is not applied, or the bias at the end lies within 3 stated sigma.
TEST(PdrCalibrator, AMovingHeadingBiasIsSeenAndNotClaimedKnown) {
  Walk w;
  w.true_bias_rad = -20.0 * kDegToRad;
  w.bias_drift_rad = 40.0 * kDegToRad;  // -20 deg at the start, +20 deg at the end
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const PdrCalibration c = run(w, 5.0, seed);
    ASSERT_TRUE(c.valid) << "seed " << seed << " (the scale is still known)";
    // a rotation that moves through the window shrinks the fitted gain (measured 5-10 % here)
    EXPECT_NEAR(c.scale, w.true_scale, 0.12 * w.true_scale) << "seed " << seed;
    EXPECT_GT(c.heading_bias_drift_sigma_rad, 10.0 * kDegToRad) << "seed " << seed;
    const double now = w.true_bias_rad + w.bias_drift_rad;
    if (c.heading_applied)
      EXPECT_LT(std::abs(c.heading_bias_rad - now), 3.0 * c.heading_bias_sigma_rad) << "seed " << seed;
  }
}

TEST(PdrCalibrator, NegativeBiasAndShortStrideAreFoundToo) {
  Walk w;
  w.true_scale = 0.90;
  w.true_bias_rad = -9.0 * kDegToRad;
  const PdrCalibration c = run(w, 5.0, 42);
  ASSERT_TRUE(c.valid);
  EXPECT_NEAR(c.scale, w.true_scale, 0.02 * w.true_scale);
  EXPECT_NEAR(c.heading_bias_rad, w.true_bias_rad, 3.0 * kDegToRad);
}

TEST(PdrCalibrator, NotPublishedBeforeEnoughBaseline) {
  const PdrCalibration c = run(Walk{}, 0.25, 3);  // 15 s: ~20 m walked
  EXPECT_FALSE(c.valid);
}

// Issue 28: with 15 m of slow multipath over 3 minutes the positions know the heading bias
// only to several degrees; the course over ground (a chipset's Doppler velocity, lagging 2 s
// at turns) pins it. Turning epochs are not used (their lagged course is 40-140 deg off).
TEST(PdrCalibrator, CourseOverGroundPinsTheHeadingBiasWhenPositionsCannot) {
  const Walk w;
  for (std::uint64_t seed : {5u, 6u, 7u, 8u}) {
    PdrCalibration pos, both;
    run(w, 3.0, seed, 15.0, CourseFeed{}, &pos);
    CourseFeed f;
    f.on = true;
    run(w, 3.0, seed, 15.0, f, &both);
    std::printf("seed %d: positions %.2f +- %.2f deg; with course %.2f +- %.2f deg (course alone %.2f +- %.2f, %d samples)\n",
                static_cast<int>(seed), pos.heading_bias_rad / kDegToRad, pos.heading_bias_sigma_rad / kDegToRad,
                both.heading_bias_rad / kDegToRad, both.heading_bias_sigma_rad / kDegToRad, both.course_bias_rad / kDegToRad,
                both.course_bias_sigma_rad / kDegToRad, both.course_epochs);
    EXPECT_EQ(pos.course_epochs, 0);
    EXPECT_GT(both.course_epochs, 60);
    EXPECT_LT(both.course_epochs, 176);  // the turning epochs (4-5 turns, 2-5 s each) are refused
    EXPECT_LT(both.heading_bias_sigma_rad, 0.9 * pos.heading_bias_sigma_rad);
    EXPECT_LE(both.heading_bias_sigma_rad, both.course_bias_sigma_rad);  // never worse than either alone
    EXPECT_LT(both.heading_bias_sigma_rad, 3.0 * kDegToRad);
    EXPECT_NEAR(both.heading_bias_rad, w.true_bias_rad, 2.0 * kDegToRad);
    // honest: the truth inside 3 sigma
    EXPECT_LT(std::abs(both.heading_bias_rad - w.true_bias_rad), 3.0 * both.heading_bias_sigma_rad);
  }
}

// The GNSS speed (TDCP/Doppler) against the PDR speed is a step-scale sample that needs no
// baseline: 45 s of walking (one straight ~40 m leg and a turn; the position fit's baseline is
// below its 20 m) already publish the scale, within its stated 3 sigma of the truth; without the
// speed nothing is published. Over five minutes it tightens the position fit's scale.
TEST(PdrCalibrator, GnssSpeedPublishesTheScaleBeforeThePositionsCan) {
  Walk w;
  w.true_scale = 1.3;  // a walker whose steps are 30 % longer than the model's (the shared ETH walk)
  SpeedFeed sp;
  sp.on = true;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    PdrCalibration pos_last;
    const PdrCalibration pos = run(w, 0.75, seed, 3.0, CourseFeed{}, &pos_last);
    const PdrCalibration both = run(w, 0.75, seed, 3.0, CourseFeed{}, nullptr, sp);
    std::printf("seed %d: 45 s, positions (baseline %.1f m) %s; with speed %.3f +- %.3f (%d samples)\n", static_cast<int>(seed),
                pos_last.baseline_m, pos.valid ? "published" : "not published", both.scale, both.scale_sigma,
                both.speed_epochs);
    EXPECT_FALSE(pos.valid) << seed;
    ASSERT_TRUE(both.valid) << seed;
    EXPECT_FALSE(both.positions_used) << seed;
    EXPECT_GE(both.speed_epochs, 10) << seed;
    EXPECT_LT(both.scale_sigma, 0.10) << seed;  // well inside the filter's 15 % prior
    EXPECT_LT(std::abs(both.scale - w.true_scale), 3.0 * both.scale_sigma) << seed;
    EXPECT_FALSE(both.heading_applied) << seed;  // the speed says nothing of the heading
  }
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const PdrCalibration pos = run(w, 5.0, seed);
    const PdrCalibration both = run(w, 5.0, seed, 3.0, CourseFeed{}, nullptr, sp);
    ASSERT_TRUE(pos.valid && both.valid) << seed;
    EXPECT_TRUE(both.positions_used) << seed;
    EXPECT_LT(both.scale_sigma, pos.scale_sigma) << seed;
    EXPECT_NEAR(both.scale, w.true_scale, 0.02 * w.true_scale) << seed;
  }
}

TEST(PdrCalibrator, SlowCourseSamplesAreNotUsed) {
  PdrCalibrator cal;
  for (int k = 0; k < 200; ++k) {
    PdrStep s;
    s.t_ns = k * 500 * kNsPerMs;
    s.length_m = 0.7;
    s.heading_rad = 0.5;
    cal.add_step(s);
    if (k % 2 == 0) {  // standing / shuffling: no direction, no speed to compare
      cal.add_course(s.t_ns, 2.0, 0.3, std::nan(""));
      cal.add_speed(s.t_ns, 0.3, 0.05);
    }
  }
  for (int k = 0; k < 100; ++k) cal.add_gnss(k * kNsPerS, Eigen::Vector2d(0.7 * std::sin(0.5) * 2 * k, 0.7 * std::cos(0.5) * 2 * k), 3.0);
  EXPECT_EQ(cal.calibration().course_epochs, 0);
  EXPECT_EQ(cal.calibration().speed_epochs, 0);
}

// After an outage of the course (e.g. GNSS lost, positions back first) the old samples leave
// the window with the positions, not when the next course sample comes.
TEST(PdrCalibrator, CourseSamplesLeaveTheWindowWithThePositions) {
  PdrCalibrator cal;
  for (int k = 0; k < 1400; ++k) {  // 700 s straight at 1.4 m/s
    PdrStep s;
    s.t_ns = k * 500 * kNsPerMs;
    s.length_m = 0.7;
    s.heading_rad = 0.5;
    cal.add_step(s);
    const double d = 0.7 * (k + 1);
    if (k % 2 == 1) {
      if (k < 200) cal.add_course(s.t_ns, 0.5, 1.4, std::nan(""));  // the first 100 s only
      cal.add_gnss(s.t_ns, Eigen::Vector2d(d * std::sin(0.5), d * std::cos(0.5)), 3.0);
    }
    if (k == 300) EXPECT_GT(cal.calibration().course_epochs, 90);
  }
  EXPECT_EQ(cal.calibration().course_epochs, 0);
}

// A chipset's course is smoothed (its velocity filter): samples 1 s apart correlate over many
// seconds, rho(1) near 1, and decorrelate. Here 240 s of a straight walk whose course error is
// the moving average of 20 uniform draws (not the calibrator's model), scaled so that each
// sample's spread is the sigma the calibrator states for it. Over 400 walks the course fit's
// sigma covers its error 76 % of the time (the halves' drift test adds a little); the AR(1)
// effective sample size from rho(1) (0.95 here: 39 samples a sample) covered 86 %.
TEST(PdrCalibrator, ASmoothedCourseIsCountedByItsMeasuredAutocorrelation) {
  constexpr int kWalks = 400, kMa = 20;
  constexpr double kSpeed = 1.4;  // m/s: 0.7 m steps every 0.5 s
  const double stated = std::atan2(PdrCalibrationOptions{}.course_velocity_sigma_mps, kSpeed);
  int covered = 0;
  double ratio_sum = 0.0;
  for (int walk = 0; walk < kWalks; ++walk) {
    std::mt19937_64 rng(1000 + walk);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> draws;
    PdrCalibrator cal;
    const double bias = 5.0 * kDegToRad;
    for (int k = 0; k < 480; ++k) {
      PdrStep s;
      s.t_ns = k * 500 * kNsPerMs;
      s.length_m = 0.7;
      s.heading_rad = 0.5 + bias;
      cal.add_step(s);
      if (k % 2 == 1) {
        draws.push_back(u(rng));
        if (draws.size() > kMa) draws.erase(draws.begin());
        double ma = 0.0;
        for (double d : draws) ma += d;
        // a uniform draw's sigma is 1/sqrt(3); the mean of kMa of them 1/sqrt(3 kMa)
        const double err = ma / static_cast<double>(draws.size()) * std::sqrt(3.0 * static_cast<double>(draws.size())) * stated;
        cal.add_course(s.t_ns, 0.5 + err, kSpeed, std::nan(""));
        // positions far too noisy to matter: the course alone decides the heading
        const double d = 0.7 * (k + 1);
        cal.add_gnss(s.t_ns, Eigen::Vector2d(d * std::sin(0.5), d * std::cos(0.5)), 1000.0);
      }
    }
    const PdrCalibration& c = cal.calibration();
    ASSERT_GT(c.course_epochs, 200) << walk;
    ASSERT_GT(c.course_bias_sigma_rad, 0.0) << walk;
    const double z = std::abs(c.course_bias_rad - bias) / c.course_bias_sigma_rad;
    covered += z <= 1.0 ? 1 : 0;
    ratio_sum += c.course_bias_sigma_rad / stated;
  }
  const double coverage = static_cast<double>(covered) / kWalks;
  std::printf("course fit: error within its 1-sigma on %.3f of %d walks; sigma %.3f x a sample's\n", coverage, kWalks,
              ratio_sum / kWalks);
  EXPECT_GT(coverage, 0.55);
  EXPECT_LT(coverage, 0.82);
}

TEST(PdrCalibrator, StandingStillNeverPublishes) {
  PdrCalibrator cal;
  for (int k = 0; k < 600; ++k) cal.add_gnss(k * kNsPerS, Eigen::Vector2d(0.3 * std::sin(k), 0.2), 4.0);
  EXPECT_FALSE(cal.published().valid);
}

}  // namespace
}  // namespace pdnav::fusion
