// Logs written in arrival order (GnssLogger, GetSensorData) with batched sensors: the motion
// samples are read in time order, everything else keeps its place in the motion timeline, and a
// log already in time order is read exactly as written (io/sample_source.cpp, MotionInTimeOrder).
#include <algorithm>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/io/sample_source.h"

using namespace pdnav;

namespace {

std::string accel(long long t_ms) { return "Accel,," + std::to_string(t_ms * 1'000'000) + ",0.1,0.2,9.8\n"; }
std::string gyro(long long t_ms) { return "Gyro,," + std::to_string(t_ms * 1'000'000) + ",0.01,0.02,0.03\n"; }

struct Read {
  std::vector<Sample> samples;
  io::ReadStats stats;
};

Read read_all(const std::string& text) {
  auto src = io::open_memory_source({{"walk.txt", text}}, "walk.txt", io::Format::kSession);
  Read r;
  Sample s;
  while (src->next(s)) r.samples.push_back(s);
  r.stats = src->stats();
  return r;
}

}  // namespace

TEST(SampleSourceTimeOrder, BatchedGyroscopeRowsAreReadInTimeOrder) {
  // accelerometer every 20 ms from 0 to 2 s; the gyroscope of each instant written 300 ms later
  // (a batch handed over late); a Truth line after the accelerometer row of 1 s
  std::string text;
  for (long long t = 0; t <= 2000; t += 20) {
    text += accel(t);
    if (t >= 300) text += gyro(t - 300);
    if (t == 1000) text += "Truth,1000000000,47.0,8.0,400,\n";
  }
  const Read r = read_all(text);
  TimeNs last = -1;
  std::size_t gyro_n = 0, truth_at = 0, accel_before_truth = 0, out_of_order = 0;
  for (std::size_t i = 0; i < r.samples.size(); ++i) {
    const Sample& s = r.samples[i];
    if (std::holds_alternative<TruthSample>(s)) {
      truth_at = i;
      continue;
    }
    const TimeNs t = sample_time_ns(s);
    // motion samples in time order, but for the first lateness: it is learnt from the first
    // late row (the accelerometer up to 300 ms had gone out before the first gyroscope row came)
    if (t < last) {
      ++out_of_order;
      EXPECT_LT(t, 300'000'000) << "sample " << i;
    }
    last = std::max(last, t);
    gyro_n += std::holds_alternative<GyroSample>(s);
    if (!truth_at && std::holds_alternative<AccelSample>(s)) ++accel_before_truth;
  }
  EXPECT_EQ(gyro_n, 86u);  // the gyroscope of 0..1700 ms (the rest was never written)
  // the Truth line stays after the motion samples read before it (up to the accelerometer's 1 s)
  EXPECT_EQ(accel_before_truth, 51u);
  EXPECT_EQ(out_of_order, 15u);  // the gyroscope of 0..280 ms
  EXPECT_GT(r.stats.reordered, 0);
  EXPECT_NEAR(r.stats.reorder_window_s, 0.3, 1e-9);
}

TEST(SampleSourceTimeOrder, ALogInTimeOrderIsReadAsWritten) {
  std::string text;
  for (long long t = 0; t <= 1000; t += 20) {
    text += accel(t);
    text += gyro(t);
    if (t == 500) text += "Truth,500000000,47.0,8.0,400,\n";
  }
  const Read r = read_all(text);
  ASSERT_EQ(r.samples.size(), 103u);
  for (std::size_t i = 0; i + 1 < r.samples.size(); ++i) {
    if (i < 52) EXPECT_EQ(r.samples[i].index(), i % 2 == 0 ? Sample(AccelSample{}).index() : Sample(GyroSample{}).index()) << i;
  }
  EXPECT_TRUE(std::holds_alternative<TruthSample>(r.samples[52]));
  EXPECT_EQ(r.stats.reordered, 0);
  EXPECT_EQ(r.stats.reorder_window_s, 0.0);
}
