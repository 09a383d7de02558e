// phonesim::at_sample_rate: a recording as a phone sampling its motion sensors at a lower rate
// would give it (what `pdnav eval-pdr --rate` and the PDR's rate test replay).
#include <cmath>
#include <limits>
#include <stdexcept>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "samples_of_type.h"

#include "pdnav/phonesim/sample_rate.h"

namespace pdnav::phonesim {
namespace {

constexpr TimeNs kMs = 1000000;

using test::only;

TEST(SampleRate, BlocksOfTheGridAreAveragedAndStampedWithTheirLastSample) {
  // 200 Hz accelerometer x = 0, 1, 2, ...; uncalibrated gyroscope with a drift that counts too.
  std::vector<Sample> in;
  for (int k = 0; k < 12; ++k) {
    AccelSample a;
    a.t_ns = 1000 * kMs + k * 5 * kMs;
    a.acc_mps2 = Eigen::Vector3d(k, 2.0 * k, 9.81);
    in.emplace_back(a);
    UncalGyroSample g;
    g.t_ns = a.t_ns + 1 * kMs;
    g.rate_radps = Eigen::Vector3d(k, 0.0, 0.0);
    g.drift_radps = Eigen::Vector3d(0.0, k, 0.0);
    in.emplace_back(g);
  }
  const std::vector<Sample> out = at_sample_rate(in, 50.0);  // blocks of 20 ms = 4 samples
  const auto acc = only<AccelSample>(out);
  ASSERT_EQ(acc.size(), 3u);
  for (int b = 0; b < 3; ++b) {
    EXPECT_DOUBLE_EQ(acc[b].acc_mps2.x(), 4 * b + 1.5);  // mean of 4b .. 4b + 3
    EXPECT_DOUBLE_EQ(acc[b].acc_mps2.y(), 2.0 * (4 * b + 1.5));
    EXPECT_EQ(acc[b].t_ns, 1000 * kMs + (4 * b + 3) * 5 * kMs);
  }
  const auto gyro = only<UncalGyroSample>(out);
  ASSERT_EQ(gyro.size(), 3u);
  EXPECT_DOUBLE_EQ(gyro[1].rate_radps.x(), 5.5);
  EXPECT_DOUBLE_EQ(gyro[1].drift_radps.y(), 5.5);
  for (std::size_t i = 1; i < out.size(); ++i) EXPECT_LE(sample_time_ns(out[i - 1]), sample_time_ns(out[i]));
}

TEST(SampleRate, AnUnstatedBiasStaysUnstatedAndItsReadingsAreKept) {
  // Sensor Logger's uncalibrated files carry no bias columns (NaN): the readings are still
  // averaged (they were dropped as non-finite), the bias stays NaN for the PDR to treat as raw
  std::vector<Sample> in;
  for (int k = 0; k < 8; ++k) {
    UncalMagSample m;
    m.t_ns = 1000 * kMs + k * 5 * kMs;  // 200 Hz
    m.field_ut = Eigen::Vector3d(k, 20.0, -40.0);
    m.bias_ut = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    in.emplace_back(m);
  }
  const auto mag = only<UncalMagSample>(at_sample_rate(in, 50.0));
  ASSERT_EQ(mag.size(), 2u);
  EXPECT_DOUBLE_EQ(mag[0].field_ut.x(), 1.5);
  EXPECT_DOUBLE_EQ(mag[1].field_ut.x(), 5.5);
  EXPECT_TRUE(std::isnan(mag[0].bias_ut.x()) && std::isnan(mag[1].bias_ut.z()));
}

TEST(SampleRate, OtherStreamsAreKeptOrDecimatedAndNonFiniteReadingsLeftOut) {
  std::vector<Sample> in;
  for (int k = 0; k < 8; ++k) {
    const TimeNs t = k * 10 * kMs;  // 100 Hz
    AccelSample a;
    a.t_ns = t;
    a.acc_mps2 = k == 2 ? Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0, 0) : Eigen::Vector3d(k, 0, 9.81);
    in.emplace_back(a);
    RotationVectorSample r;
    r.t_ns = t;
    r.quat_xyzw = Eigen::Vector4d(0, 0, std::sin(0.01 * k), std::cos(0.01 * k));
    in.emplace_back(r);
    PressureSample p;
    p.t_ns = t + 2 * kMs;
    p.pressure_pa = 100000.0 + k;
    in.emplace_back(p);
  }
  const std::vector<Sample> out = at_sample_rate(in, 25.0);  // blocks of 40 ms = 4 samples
  const auto acc = only<AccelSample>(out);
  ASSERT_EQ(acc.size(), 2u);
  EXPECT_DOUBLE_EQ(acc[0].acc_mps2.x(), (0.0 + 1.0 + 3.0) / 3.0);  // the NaN reading left out
  EXPECT_DOUBLE_EQ(acc[1].acc_mps2.x(), 5.5);
  const auto rv = only<RotationVectorSample>(out);
  ASSERT_EQ(rv.size(), 2u);
  EXPECT_EQ(rv[0].t_ns, 30 * kMs);  // the last of its block, not an average
  EXPECT_DOUBLE_EQ(rv[1].quat_xyzw.z(), std::sin(0.07));
  EXPECT_EQ(only<PressureSample>(out).size(), 8u);  // as recorded
}

TEST(SampleRate, AStreamBelowTheRateKeepsEverySample) {
  std::vector<Sample> in;
  for (int k = 0; k < 20; ++k) {
    GyroSample g;
    g.t_ns = k * 20 * kMs;  // 50 Hz
    g.rate_radps = Eigen::Vector3d(0.1 * k, 0, 0);
    in.emplace_back(g);
  }
  const auto out = only<GyroSample>(at_sample_rate(in, 100.0));
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t k = 0; k < out.size(); ++k) EXPECT_DOUBLE_EQ(out[k].rate_radps.x(), 0.1 * static_cast<double>(k));
}

TEST(SampleRate, ARateOutsideItsRangeIsRefused) {
  EXPECT_THROW(at_sample_rate({}, 0.0), std::invalid_argument);
  EXPECT_THROW(at_sample_rate({}, -50.0), std::invalid_argument);
  EXPECT_THROW(at_sample_rate({}, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(at_sample_rate({}, 2e9), std::invalid_argument);
  EXPECT_TRUE(at_sample_rate({}, 50.0).empty());
}

}  // namespace
}  // namespace pdnav::phonesim
