// The PDR stages' sliding-window sum (pdr/time_window.h) against a brute-force sum over the
// samples it should hold: which samples are kept, and rounding bounded on long sessions.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/pdr/time_window.h"

using namespace pdnav;
using namespace pdnav::pdr;

namespace {

struct Pushed {
  TimeNs t_ns;
  double x;
};

// The samples of `all` that a window of span_s ending at the last one holds: younger than span_s.
std::vector<Pushed> expected_window(const std::vector<Pushed>& all, double span_s) {
  std::vector<Pushed> kept;
  const TimeNs horizon = all.back().t_ns - s_to_ns(span_s);
  for (const Pushed& p : all)
    if (p.t_ns > horizon) kept.push_back(p);
  return kept;
}

}  // namespace

TEST(TimeWindow, HoldsExactlyTheSamplesYoungerThanItsSpan) {
  // irregular sampling (2-40 ms, a 0.3 s batch gap), integer values: every sum is exact
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> dt_ms(2, 40), value(-50, 50);
  TimeWindowSum<double> w(1.0, 0.0);
  std::vector<Pushed> all;
  TimeNs t = 1'000'000'000;
  for (int k = 0; k < 3000; ++k) {
    t += (k == 1500 ? 300 : dt_ms(rng)) * 1'000'000LL;
    all.push_back({t, static_cast<double>(value(rng))});
    w.push(t, all.back().x);
    const std::vector<Pushed> kept = expected_window(all, 1.0);
    double sum = 0.0;
    for (const Pushed& p : kept) sum += p.x;
    ASSERT_EQ(w.size(), kept.size()) << "push " << k;
    ASSERT_EQ(w.sum(), sum) << "push " << k;
    ASSERT_NEAR(w.covered_s(), ns_to_s(kept.back().t_ns - kept.front().t_ns), 1e-12);
  }
  // a sample exactly one span older than the newest is gone
  TimeWindowSum<double> edge(1.0, 0.0);
  edge.push(0, 7.0);
  edge.push(s_to_ns(1.0) - 1, 1.0);
  EXPECT_EQ(edge.size(), 2u);
  edge.push(s_to_ns(1.0), 1.0);
  EXPECT_EQ(edge.size(), 2u);
  EXPECT_EQ(edge.sum(), 2.0);
  edge.clear();
  EXPECT_TRUE(edge.empty());
  EXPECT_EQ(edge.sum(), 0.0);
  EXPECT_EQ(edge.covered_s(), 0.0);
}

TEST(TimeWindow, RoundingFromLargeSamplesDoesNotOutliveThem) {
  // 100 Hz, 1 s window; 40 spikes of 1e15 (the ulp there is 0.125) among values in [0, 1): each
  // spike's add and subtract leaves its rounding in a running sum. After the last spike has left
  // the window and kResumEvery more pushes, the sum and sigma must be the window's own.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  TimeWindowMoments m(1.0);
  std::vector<Pushed> all;
  TimeNs t = 0;
  const int n = 20'000;
  for (int k = 0; k < n; ++k) {
    t += 10'000'000;
    const double x = (k < 4'000 && k % 97 == 0) ? 1e15 + u(rng) : u(rng);
    all.push_back({t, x});
    m.push(t, x);
  }
  ASSERT_GT(n - 4'000, TimeWindowSum<double>::kResumEvery + 100);
  const std::vector<Pushed> kept = expected_window(all, 1.0);
  double mean = 0.0;
  for (const Pushed& p : kept) mean += p.x;
  mean /= static_cast<double>(kept.size());
  double var = 0.0;
  for (const Pushed& p : kept) var += (p.x - mean) * (p.x - mean);
  const double sigma = std::sqrt(var / static_cast<double>(kept.size()));
  ASSERT_EQ(m.size(), kept.size());
  EXPECT_NEAR(m.mean(), mean, 1e-12);
  EXPECT_NEAR(m.sigma(), sigma, 1e-9);  // without the re-sum: off by ~0.1 (the spikes' rounding)
}

TEST(TimeWindow, SumsVectorsAndMatrices) {
  TimeWindowSum<Eigen::Matrix3d> outer(0.5, Eigen::Matrix3d::Zero());
  const Eigen::Vector3d a(1, 2, 3), b(-1, 0, 2);
  outer.push(0, a * a.transpose());
  outer.push(s_to_ns(0.3), b * b.transpose());
  EXPECT_TRUE(outer.sum().isApprox(a * a.transpose() + b * b.transpose()));
  outer.push(s_to_ns(0.6), b * b.transpose());  // a is 0.6 s old now: beyond the 0.5 s span
  EXPECT_TRUE(outer.sum().isApprox(2.0 * b * b.transpose()));
  EXPECT_EQ(outer.size(), 2u);
}
