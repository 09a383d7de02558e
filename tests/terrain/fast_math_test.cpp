// Accuracy of the particle filter's fast approximations (private header of the module).
#include <cmath>

#include <gtest/gtest.h>

#include "../../core-cpp/src/terrain/fast_math.h"

namespace pdnav::terrain::detail {
namespace {

TEST(FastMath, SinCosExpWrap) {
  double err = 0.0;
  for (float x = -3.14159f; x <= 3.14159f; x += 0.001f) {
    float s, c;
    fast_sincos(x, s, c);
    err = std::max(err, static_cast<double>(std::max(std::fabs(s - std::sin(x)), std::fabs(c - std::cos(x)))));
  }
  EXPECT_LT(err, 1e-5);
  double rel = 0.0;
  for (float x = -80.0f; x <= 0.0f; x += 0.01f)
    rel = std::max(rel, std::abs(static_cast<double>(fast_exp_neg(x)) / std::exp(static_cast<double>(x)) - 1.0));
  EXPECT_LT(rel, 1e-5);
  EXPECT_EQ(fast_exp_neg(-1000.0f), 0.0f);
  EXPECT_EQ(fast_exp_neg(std::nanf("")), 0.0f);
  EXPECT_NEAR(wrap_pi_f(4.0f), 4.0f - 6.2831853f, 1e-5);
  EXPECT_NEAR(wrap_pi_f(-4.0f), -4.0f + 6.2831853f, 1e-5);
}

TEST(FastMath, NormalApproximationMoments) {
  Xoshiro256Plus rng(123);
  const int n = 400000;
  double s = 0, s2 = 0, s4 = 0, mx = 0;
  for (int i = 0; i < n; ++i) {
    const double v = normal_from_bits(rng.next());
    s += v;
    s2 += v * v;
    s4 += v * v * v * v;
    mx = std::max(mx, std::abs(v));
  }
  EXPECT_NEAR(s / n, 0.0, 0.01);
  EXPECT_NEAR(s2 / n, 1.0, 0.01);
  EXPECT_NEAR(s4 / n, 2.7, 0.05);  // Irwin-Hall(4): kurtosis 3 - 1.2/4 = 2.7
  EXPECT_LE(mx, 3.4642);
  Xoshiro256Plus a(5), b(5);
  EXPECT_EQ(a.next(), b.next());
  double u = 0;
  for (int i = 0; i < 1000; ++i) u += a.uniform_f();
  EXPECT_NEAR(u / 1000, 0.5, 0.05);
}

}  // namespace
}  // namespace pdnav::terrain::detail
