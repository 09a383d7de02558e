// What carrier smoothing leaves of a code's white noise (CodeSmoother::white_variance_ratio,
// docs/gnss.md "Carrier smoothing"): the ratio the SPP weights a smoothed code by must be the
// variance the smoother's output really has. Monte Carlo over independent satellites with white
// code noise of a known sigma: with an exact carrier the variance of the smoothed error is 1/n
// of the code's after n epochs and 1/(2N-1) once the 100-epoch window is full; propagated by a
// noisy Doppler, it is the recursion with the rate's variance; a restart gives the raw code back.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/gnss/solver_smoothing.h"

namespace pdnav::gnss {
namespace {

constexpr double kCodeSigmaM = 3.0;
constexpr int kSats = 4000;  // independent satellites: the Monte Carlo sample at each epoch

struct Smoothed {
  std::vector<double> realised;  // variance of the smoothed error / code variance, per epoch
  std::vector<double> stated;    // mean white_variance_ratio, per epoch
};

/// `epochs` epochs at 1 s; with `doppler`, no carrier: the rate (noise sigma `rate_sigma_mps`)
/// propagates; `restart_at` >= 0: a gap before that epoch.
Smoothed smooth_series(int epochs, bool doppler, double rate_sigma_mps, int restart_at = -1) {
  SmoothingOptions o;
  o.remove_common_step = false;  // independent satellites: no common clock step to remove
  CodeSmoother sm{o};
  std::mt19937_64 rng(5);
  std::normal_distribution<double> code(0.0, kCodeSigmaM), rate_noise(0.0, rate_sigma_mps);
  Smoothed r;
  for (int k = 0; k < epochs; ++k) {
    sm.begin_epoch(k == 0 || k == restart_at ? 0.0 : 1.0, 0.0);
    std::vector<SmoothingInput> in;
    std::vector<double> truth;
    for (int i = 0; i < kSats; ++i) {
      const double rate = -300.0 + 0.15 * i;
      const double range = 2.1e7 + 10.0 * i + rate * k;
      SmoothingInput x{SatId{Constellation::kGps, i + 1}, range + code(rng), doppler ? std::nan("") : range,
                       rate + (doppler ? rate_noise(rng) : 0.0)};
      x.white_var_m2 = kCodeSigmaM * kCodeSigmaM;
      x.rate_var_m2ps2 = rate_sigma_mps * rate_sigma_mps;
      in.push_back(x);
      truth.push_back(range);
    }
    const std::vector<double> out = sm.smooth_epoch(in);
    double sum2 = 0.0, ratio = 0.0;
    for (int i = 0; i < kSats; ++i) {
      const double e = out[static_cast<std::size_t>(i)] - truth[static_cast<std::size_t>(i)];
      sum2 += e * e;
      ratio += sm.white_variance_ratio(in[static_cast<std::size_t>(i)].sat);
    }
    r.realised.push_back(sum2 / kSats / (kCodeSigmaM * kCodeSigmaM));
    r.stated.push_back(ratio / kSats);
  }
  return r;
}

TEST(SmoothingNoise, WithACarrierTheRatioIsOneOverNThenOneOverTwoNMinusOne) {
  const Smoothed r = smooth_series(400, false, 0.0);
  EXPECT_DOUBLE_EQ(r.stated[0], 1.0);
  for (int n : {1, 5, 20, 100}) {
    EXPECT_NEAR(r.stated[static_cast<std::size_t>(n - 1)], 1.0 / n, 1e-12) << n;
    EXPECT_NEAR(r.realised[static_cast<std::size_t>(n - 1)] / r.stated[static_cast<std::size_t>(n - 1)], 1.0, 0.1) << n;
  }
  EXPECT_NEAR(r.stated.back(), 1.0 / 199.0, 2e-4);  // the window (100 epochs) full for 300 epochs
  EXPECT_NEAR(r.realised.back() / r.stated.back(), 1.0, 0.1);
}

TEST(SmoothingNoise, ADopplerPropagationAddsTheRatesVariance) {
  // 0.3 m/s rate noise against 3 m of code noise: after 100 epochs the propagation's random walk
  // dominates (the ratio ~0.05 instead of 0.01)
  const Smoothed r = smooth_series(150, true, 0.3);
  const Smoothed carrier = smooth_series(150, false, 0.0);
  EXPECT_GT(r.stated[99], 3.0 * carrier.stated[99]);
  for (int n : {10, 50, 100, 150}) {
    const std::size_t k = static_cast<std::size_t>(n - 1);
    EXPECT_NEAR(r.realised[k] / r.stated[k], 1.0, 0.12) << n;
  }
}

TEST(SmoothingNoise, ARestartGivesTheRawCodeBackAndAnUnknownRateKeepsTheRatio) {
  const Smoothed r = smooth_series(60, false, 0.0, 40);
  EXPECT_NEAR(r.stated[38], 1.0 / 39.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.stated[40], 1.0);
  EXPECT_NEAR(r.realised[40], 1.0, 0.1);
  // a Doppler epoch without the code's or the rate's variance does not lower the ratio
  CodeSmoother sm{SmoothingOptions{}};
  const SatId g1{Constellation::kGps, 1};
  sm.begin_epoch(0.0, 0.0);
  sm.smooth_epoch({SmoothingInput{g1, 2.1e7, std::nan(""), 10.0}});
  sm.begin_epoch(1.0, 0.0);
  sm.smooth_epoch({SmoothingInput{g1, 2.1e7 + 10.0, std::nan(""), 10.0}});
  EXPECT_DOUBLE_EQ(sm.white_variance_ratio(g1), 1.0);
  EXPECT_DOUBLE_EQ(sm.white_variance_ratio(SatId{Constellation::kGps, 2}), 1.0);  // never seen
}

}  // namespace
}  // namespace pdnav::gnss
