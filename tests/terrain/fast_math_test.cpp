// Accuracy of the particle filter's fast approximations (private header of the module).
#include <cmath>
#include <cstring>
#include <vector>

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


TEST(FastMath, FourLaneExpEqualsScalarExp) {
  // The step's weighting runs 4 particles at a time through fast_exp_neg4 and the block's tail
  // through fast_exp_neg: they must agree bit for bit (the same operations in the same order),
  // including the clamp below -87 and NaN.
  std::vector<float> xs;
  for (float x = -100.0f; x <= 0.0f; x += 0.0137f) xs.push_back(x);
  xs.push_back(-87.0f);
  xs.push_back(-1000.0f);
  xs.push_back(std::nanf(""));
  xs.push_back(-0.0f);
  while (xs.size() % 4 != 0) xs.push_back(0.0f);
  for (std::size_t i = 0; i < xs.size(); i += 4) {
    float y[4];
    store4(y, fast_exp_neg4(load4(xs.data() + i)));
    for (std::size_t l = 0; l < 4; ++l) {
      const float ref = fast_exp_neg(xs[i + l]);
      ASSERT_EQ(std::memcmp(&ref, &y[l], sizeof ref), 0) << "x = " << xs[i + l];
    }
  }
  const Float4 sel = select4(Int4{-1, 0, -1, 0}, splat4(1.0f), splat4(2.0f));
  EXPECT_EQ(sel[0], 1.0f);
  EXPECT_EQ(sel[1], 2.0f);
  EXPECT_EQ(sel[2], 1.0f);
  EXPECT_EQ(sel[3], 2.0f);
}

TEST(FastMath, LaneGeneratorIsSeededDeterministicAndNormal) {
  constexpr std::size_t kLanes = 64;
  LaneXoshiro128Plus<kLanes> a(9), b(9), c(10);
  std::uint32_t ra[4][kLanes], rb[4][kLanes], rc[4][kLanes];
  a.fill4(ra[0], ra[1], ra[2], ra[3]);
  b.fill4(rb[0], rb[1], rb[2], rb[3]);
  c.fill4(rc[0], rc[1], rc[2], rc[3]);
  EXPECT_EQ(std::memcmp(ra, rb, sizeof ra), 0);  // same seed, same words
  EXPECT_NE(std::memcmp(ra, rc, sizeof ra), 0);
  int same_lanes = 0;
  for (std::size_t l = 1; l < kLanes; ++l) same_lanes += ra[0][l] == ra[0][0];
  EXPECT_EQ(same_lanes, 0);  // the lanes are distinct streams
  // Irwin-Hall(4) normals from word pairs, over all lanes: unit variance, kurtosis 2.7, and
  // no correlation between consecutive draws of a lane or neighbouring lanes.
  double s = 0, s2 = 0, s4 = 0, lag = 0, nb = 0, mx = 0;
  const int rounds = 3000;
  float prev[kLanes] = {};
  for (int k = 0; k < rounds; ++k) {
    a.fill4(ra[0], ra[1], ra[2], ra[3]);
    for (std::size_t l = 0; l < kLanes; ++l) {
      const double v = normal_from_words(ra[0][l], ra[1][l]);
      const double v2 = normal_from_words(ra[2][l], ra[3][l]);
      s += v;
      s2 += v * v;
      s4 += v * v * v * v;
      lag += v * v2;
      nb += l > 0 ? v * prev[l - 1] : 0.0;
      mx = std::max(mx, std::abs(v));
      prev[l] = static_cast<float>(v);
    }
  }
  const double n = static_cast<double>(rounds) * kLanes;
  EXPECT_NEAR(s / n, 0.0, 0.01);
  EXPECT_NEAR(s2 / n, 1.0, 0.01);
  EXPECT_NEAR(s4 / n, 2.7, 0.05);
  EXPECT_NEAR(lag / n, 0.0, 0.01);
  EXPECT_NEAR(nb / n, 0.0, 0.01);
  EXPECT_LE(mx, 3.4642);
}

}  // namespace
}  // namespace pdnav::terrain::detail
