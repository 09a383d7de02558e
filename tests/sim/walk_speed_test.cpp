// phonesim::at_walk_speed: a recording as the same walk taken k times faster (what `pdnav
// eval-pdr --speed` replays: the cadences of faster walkers and runners).
#include <cmath>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "samples_of_type.h"

#include "pdnav/phonesim/walk_speed.h"

namespace pdnav::phonesim {
namespace {

constexpr TimeNs kMs = 1000000;

using test::only;

/// 20 s at 100 Hz: gravity along +Z plus a 2 Hz "gait" of 1 m/s^2 along X; a gyroscope turning
/// 0.5 rad/s about Z with a stated drift; a magnetometer; a Truth line and span Meta rows.
std::vector<Sample> recording() {
  std::vector<Sample> in;
  MetaSample from{1000 * kMs, "TruthStepsFromNanos", std::to_string(6000 * kMs)};
  MetaSample cad{1000 * kMs, "TruthCadenceHz", "2.000"};
  in.emplace_back(from);
  in.emplace_back(cad);
  for (int i = 0; i < 2000; ++i) {
    const TimeNs t = 1000 * kMs + i * 10 * kMs;
    const double ts = i * 0.01;
    AccelSample a;
    a.t_ns = t;
    a.utc_ms = 1700000000000 + i * 10;
    a.acc_mps2 = Eigen::Vector3d(std::sin(2.0 * M_PI * 2.0 * ts), 0.0, 9.81);
    in.emplace_back(a);
    UncalGyroSample g;
    g.t_ns = t + 2 * kMs;
    g.rate_radps = Eigen::Vector3d(0.01, 0.0, 0.5 + 0.01);
    g.drift_radps = Eigen::Vector3d(0.01, 0.0, 0.01);
    in.emplace_back(g);
    MagSample m;
    m.t_ns = t + 3 * kMs;
    m.field_ut = Eigen::Vector3d(20.0, 0.0, -40.0);
    in.emplace_back(m);
    if (i % 100 == 0) {
      TruthSample tr;
      tr.t_ns = t;
      tr.lat_deg = 45.0 + i * 1e-7;
      tr.lon_deg = 5.0;
      in.emplace_back(tr);
    }
  }
  return in;
}

TEST(WalkSpeed, TheSameWalkFasterHasItsTimesCompressedAndItsGaitScaled) {
  const std::vector<Sample> in = recording();
  const double k = 1.25;
  const std::vector<Sample> out = at_walk_speed(in, k);
  ASSERT_EQ(out.size(), in.size());
  const auto acc = only<AccelSample>(out), acc0 = only<AccelSample>(in);
  // times: t0 + (t - t0) / k, the wall clock moved with them
  EXPECT_EQ(acc.front().t_ns, 1000 * kMs);
  EXPECT_EQ(acc.back().t_ns, 1000 * kMs + std::llround(1999 * 10 * kMs / k));
  EXPECT_EQ(acc.back().utc_ms - acc.front().utc_ms, std::llround(19990 / k));
  // gravity kept, the gait (now at 2.5 Hz) k^2 larger: away from the ends' filter transients
  double peak = 0.0, z_dev = 0.0;
  for (std::size_t i = 400; i < 1600; ++i) {
    peak = std::max(peak, std::abs(acc[i].acc_mps2.x()));
    z_dev = std::max(z_dev, std::abs(acc[i].acc_mps2.z() - 9.81));
  }
  EXPECT_NEAR(peak, k * k, 0.03 * k * k);
  EXPECT_LT(z_dev, 1e-6);
  // the gait sample by sample: (a - slow) k^2 with the slow part ~0 along X
  EXPECT_NEAR(acc[1000].acc_mps2.x(), k * k * acc0[1000].acc_mps2.x(), 0.03);
  // rotation rates k times larger about the stated drift, which stays
  const auto g = only<UncalGyroSample>(out);
  EXPECT_NEAR(g[5].rate_radps.z(), 0.01 + k * 0.5, 1e-12);
  EXPECT_NEAR(g[5].rate_radps.x(), 0.01, 1e-12);
  EXPECT_NEAR(g[5].drift_radps.z(), 0.01, 1e-12);
  // field and positions unchanged, their times compressed
  const auto m = only<MagSample>(out);
  EXPECT_EQ(m[7].field_ut, Eigen::Vector3d(20.0, 0.0, -40.0));
  const auto tr = only<TruthSample>(out), tr0 = only<TruthSample>(in);
  ASSERT_EQ(tr.size(), 20u);
  EXPECT_EQ(tr[3].lat_deg, tr0[3].lat_deg);
  EXPECT_EQ(tr[3].t_ns, 1000 * kMs + std::llround((tr0[3].t_ns - 1000 * kMs) / k));
  // the capture's span and cadence move with the walk
  const auto meta = only<MetaSample>(out);
  EXPECT_EQ(meta[0].value, std::to_string(1000 * kMs + std::llround(5000 * kMs / k)));
  EXPECT_EQ(meta[1].value, "2.500");
}

TEST(WalkSpeed, AsRecordedIsTheRecordingAndBadFactorsAreRefused) {
  const std::vector<Sample> in = recording();
  const std::vector<Sample> same = at_walk_speed(in, 1.0);
  const auto a = only<AccelSample>(same), a0 = only<AccelSample>(in);
  ASSERT_EQ(a.size(), a0.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].t_ns, a0[i].t_ns);
    EXPECT_LT((a[i].acc_mps2 - a0[i].acc_mps2).norm(), 1e-12);
  }
  EXPECT_THROW(at_walk_speed(in, 0.0), std::invalid_argument);
  EXPECT_THROW(at_walk_speed(in, 5.0), std::invalid_argument);
  EXPECT_THROW(at_walk_speed(in, std::nan("")), std::invalid_argument);
  EXPECT_THROW(at_walk_speed(in, 1.2, 0.0), std::invalid_argument);
  // GNSS measurement rows cannot be taken faster: dropped
  std::vector<Sample> with_raw = in;
  with_raw.emplace_back(GnssRawSample{});
  EXPECT_EQ(at_walk_speed(with_raw, 1.2).size(), in.size());
  EXPECT_TRUE(at_walk_speed({}, 1.2).empty());
}

}  // namespace
}  // namespace pdnav::phonesim
