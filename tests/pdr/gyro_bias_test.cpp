// The bias of an uncalibrated gyro whose logger did not export the platform's drift, learned
// while the phone lies still (pdr/gyro_bias.h). Streams synthesised here: bias + white noise at
// rest, the synthetic walker (synthetic_imu.h) after it.
#include <algorithm>
#include <cmath>
#include <functional>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/pdr/gyro_bias.h"
#include "pdnav/pdr/pdr.h"
#include "synthetic_imu.h"

using namespace pdnav;
using namespace pdnav::pdr;

namespace {

const Eigen::Vector3d kRawBias(-0.0616, 0.0494, 0.0673);  // rad/s: the shared ETH phone's (-3.5, 2.8, 3.9 deg/s)

/// t0_s .. t0_s + dur_s at 100 Hz: the gyro reads bias + rate(t) + noise, the accelerometer
/// gravity (+ vibration of this 1-sigma).
void feed_block(GyroBiasAtRest& g, double t0_s, double dur_s, const std::function<Eigen::Vector3d(double)>& rate,
                double gyro_noise, double accel_vibration, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  for (double t = t0_s; t < t0_s + dur_s; t += 0.01) {
    g.feed_gyro(s_to_ns(t), kRawBias + rate(t) + gyro_noise * Eigen::Vector3d(n(rng), n(rng), n(rng)));
    g.feed_accel(s_to_ns(t), Eigen::Vector3d(0.1, 0.3, 9.8) + accel_vibration * Eigen::Vector3d(n(rng), n(rng), n(rng)));
  }
}

const auto kNoRate = [](double) { return Eigen::Vector3d::Zero().eval(); };

}  // namespace

TEST(GyroBiasAtRest, ThePhoneOnATableGivesTheBias) {
  GyroBiasAtRest g;
  std::mt19937_64 rng(5);
  EXPECT_FALSE(g.known());
  EXPECT_EQ(g.bias_radps(), Eigen::Vector3d::Zero());
  feed_block(g, 0.0, 10.0, kNoRate, 0.003, 0.01, rng);  // 0.17 deg/s of noise, as the ETH phone
  EXPECT_TRUE(g.known());
  EXPECT_GE(g.still_blocks(), 4);
  EXPECT_LT((g.bias_radps() - kRawBias).norm(), 0.05 * kDegToRad);
}

TEST(GyroBiasAtRest, MotionIsNotABias) {
  std::mt19937_64 rng(6);
  // walking / turning: the rate changes within each block
  GyroBiasAtRest turning;
  feed_block(turning, 0.0, 20.0, [](double t) { return Eigen::Vector3d(0.0, 0.0, 0.5 * std::sin(2.0 * t)); }, 0.003, 0.01,
             rng);
  EXPECT_FALSE(turning.known());
  // held in a hand: 2 deg/s of tremor about every axis
  GyroBiasAtRest hand;
  feed_block(hand, 0.0, 20.0, kNoRate, 2.0 * kDegToRad, 0.01, rng);
  EXPECT_FALSE(hand.known());
  // a slow steady turn with the gyro still (no scatter) but the accelerometer vibrating (a car)
  GyroBiasAtRest car;
  feed_block(car, 0.0, 20.0, [](double) { return Eigen::Vector3d(0.0, 0.0, 0.1); }, 0.003, 0.3, rng);
  EXPECT_FALSE(car.known());
  // a still phone after motion: only the still blocks count
  feed_block(turning, 20.0, 10.0, kNoRate, 0.003, 0.01, rng);
  EXPECT_TRUE(turning.known());
  EXPECT_LT((turning.bias_radps() - kRawBias).norm(), 0.05 * kDegToRad);
}

TEST(GyroBiasAtRest, UncalibratedGyroWithoutItsDriftWalksLikeTheCalibratedOne) {
  // 10 s on a table, then the synthetic walk (two turns). The calibrated run reads the gyro with
  // the walk's small residual bias; the uncalibrated run reads it plus the raw offset, drift not
  // given (NaN), as Sensor Logger exports it.
  test::WalkSpec spec;
  spec.seed = 4;
  const test::SyntheticWalk w = test::make_walk(spec, {{15, 90}, {15, -90}});
  const TimeNs lead_ns = s_to_ns(10.0);
  Eigen::Vector3d g_phone = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < 100; ++i) g_phone += w.accel[i].acc_mps2 / 100.0;
  std::mt19937_64 rng(9);
  std::normal_distribution<double> n(0.0, 1.0);
  PdrOptions opt;
  opt.heading.mount = Mount::kHandheld;  // flat, top ahead: the gyro's yaw carries the heading
  const auto run = [&](bool uncal) {
    Pdr pdr(opt);
    std::vector<PdrStep> out;
    const Eigen::Vector3d not_exported = Eigen::Vector3d::Constant(kNaN);
    for (TimeNs t = 0; t < lead_ns; t += 10'000'000) {  // the table: 100 Hz
      const Eigen::Vector3d rate = spec.gyro_bias_radps + 0.003 * Eigen::Vector3d(n(rng), n(rng), n(rng));
      pdr.feed(AccelSample{t, kMissingInt, g_phone + 0.02 * Eigen::Vector3d(n(rng), n(rng), n(rng))});
      if (uncal) pdr.feed(UncalGyroSample{t, kMissingInt, rate + kRawBias, not_exported});
      else pdr.feed(GyroSample{t, kMissingInt, rate});
    }
    for (std::size_t i = 0; i < w.accel.size(); ++i) {
      AccelSample a = w.accel[i];
      a.t_ns += lead_ns;
      pdr.feed(a);
      const GyroSample& gy = w.gyro[i];
      if (uncal) pdr.feed(UncalGyroSample{gy.t_ns + lead_ns, gy.utc_ms, gy.rate_radps + kRawBias, not_exported});
      else pdr.feed(GyroSample{gy.t_ns + lead_ns, gy.utc_ms, gy.rate_radps});
      for (const PdrStep& s : pdr.take_steps()) out.push_back(s);
    }
    pdr.finish();
    for (const PdrStep& s : pdr.take_steps()) out.push_back(s);
    return std::make_pair(out, pdr.gyro_bias_at_rest());
  };
  const auto [cal, cal_rest] = run(false);
  const auto [unc, unc_rest] = run(true);
  EXPECT_FALSE(cal_rest.known());  // a calibrated gyro is not touched
  ASSERT_TRUE(unc_rest.known());
  EXPECT_LT((unc_rest.bias_radps() - kRawBias - spec.gyro_bias_radps).norm(), 0.05 * kDegToRad);
  ASSERT_GT(cal.size(), 60u);
  ASSERT_NEAR(static_cast<double>(unc.size()), static_cast<double>(cal.size()), 2.0);
  // against the walker's true heading (clockwise from north = 90 deg - psi): the uncalibrated
  // run knows its gyro's whole offset from the table, the calibrated one keeps the walk's
  // 0.4 deg/s residual; uncorrected, 3.9 deg/s of raw offset would turn the track by ~180 deg
  const auto worst_error_deg = [&](const std::vector<PdrStep>& steps) {
    double worst = 0.0;
    for (const PdrStep& s : steps) {
      const double t_walk_s = ns_to_s(s.t_ns - lead_ns);
      if ((t_walk_s > 14.0 && t_walk_s < 19.0) || (t_walk_s > 32.0 && t_walk_s < 37.0)) continue;  // the turns
      const auto k = static_cast<std::size_t>(std::clamp(t_walk_s * spec.rate_hz, 0.0, w.psi_rad.size() - 1.0));
      worst = std::max(worst, std::abs(wrap_pi(s.heading_rad - (kPi / 2 - w.psi_rad[k]))) / kDegToRad);
    }
    return worst;
  };
  std::printf("worst heading error: uncalibrated, bias at rest %.1f deg; calibrated %.1f deg\n", worst_error_deg(unc),
              worst_error_deg(cal));
  EXPECT_LT(worst_error_deg(unc), 9.0);  // the +-3 deg sway about the first sample's (swayed) reference
  EXPECT_LE(worst_error_deg(unc), worst_error_deg(cal));
  // the walk turned (north, west, north): the headings compared are not one constant
  double west = 0.0;
  for (const PdrStep& c : unc) west = std::max(west, std::cos(c.heading_rad - 1.5 * kPi));
  EXPECT_GT(west, 0.95);
}
