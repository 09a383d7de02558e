// Issue 27: the heading source of every step (Pdr::heading_sources, summary.json): the rotation
// vector while its readings pass the field tests, the gyro where the field is disturbed or the
// absolute readings stop. Real data: one ILC 2020 hand-held walk (accelerometer, gyroscope,
// rotation vector), with the rotation vector cut out or a disturbed magnetometer added.
#include <algorithm>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/pdr/pdr.h"
#include "real_walk.h"
#include "test_data.h"

using namespace pdnav;
using namespace pdnav::pdr;
using pdnav::test::RealWalk;
using pdnav::test::read_ilc;

namespace {

const char* kWalk = "pdr-ilc2020/data/site2/F3/path_data_files/5dd38fff44333f00067aa387.txt";

struct SourceRun {
  std::vector<PdrStep> steps;
  std::vector<HeadingSourceSpan> spans;
};

/// Feeds the walk in time order; rotation-vector samples inside [cut_from, cut_to) are dropped;
/// with `field_ut` a magnetometer sample of that (phone-axes) field accompanies every rotation
/// vector sample.
SourceRun feed(const RealWalk& w, TimeNs cut_from, TimeNs cut_to, const Eigen::Vector3d* field_ut, bool with_gyro = true) {
  PdrOptions o;
  o.heading.mount = Mount::kAuto;
  Pdr p(o);
  p.set_location(geo::Geodetic{45.19 * kDegToRad, 5.73 * kDegToRad, 200.0}, 1'574'000'000'000);
  SourceRun r;
  std::size_t ig = 0, ir = 0;
  for (const auto& s : w.accel) {
    while (with_gyro && ig < w.gyro.size() && w.gyro[ig].t_ns <= s.t_ns) p.feed(w.gyro[ig++]);
    while (ir < w.rotation.size() && w.rotation[ir].t_ns <= s.t_ns) {
      const RotationVectorSample& rv = w.rotation[ir++];
      if (rv.t_ns >= cut_from && rv.t_ns < cut_to) continue;
      if (field_ut) p.feed(MagSample{rv.t_ns, kMissingInt, *field_ut});
      p.feed(rv);
    }
    p.feed(s);
    for (const auto& st : p.take_steps()) r.steps.push_back(st);
  }
  p.finish();
  for (const auto& st : p.take_steps()) r.steps.push_back(st);
  r.spans = p.heading_sources();
  return r;
}

std::int64_t steps_with(const SourceRun& r, HeadingSource s, TimeNs from = 0, TimeNs to = INT64_MAX) {
  std::int64_t n = 0;
  for (const auto& span : r.spans)
    if (span.source == s && span.t_start_ns >= from && span.t_end_ns <= to) n += span.steps;
  return n;
}

std::int64_t total(const SourceRun& r) {
  std::int64_t n = 0;
  for (const auto& span : r.spans) n += span.steps;
  return n;
}

}  // namespace

TEST(PdrHeadingSource, RotationVectorWhileItArrivesGyroWhereItStops) {
  const RealWalk walk = read_ilc(pdnav::test::shared_data(kWalk));
  ASSERT_FALSE(walk.rotation.empty());
  const SourceRun recorded = feed(walk, 0, 0, nullptr);
  ASSERT_GT(recorded.steps.size(), 40u);
  EXPECT_EQ(total(recorded), static_cast<std::int64_t>(recorded.steps.size()));  // every step has a source
  // no magnetometer in the log: the rotation vector's readings have full weight
  EXPECT_EQ(steps_with(recorded, HeadingSource::kRotationVector), total(recorded));

  // the rotation vector stops for the middle third of the walk: after source_tau_s ln 2 (3.5 s)
  // without readings the heading is the gyro's; with the readings back, the rotation vector's
  const TimeNs t0 = walk.accel.front().t_ns, t1 = walk.accel.back().t_ns;
  const TimeNs cut_from = t0 + (t1 - t0) / 3, cut_to = t0 + 2 * (t1 - t0) / 3;
  const SourceRun cut = feed(walk, cut_from, cut_to, nullptr);
  const std::int64_t gyro_inside = steps_with(cut, HeadingSource::kGyro, cut_from, cut_to);
  std::int64_t steps_inside_late = 0;  // steps in the cut more than 4 s after its start
  for (const auto& st : cut.steps) steps_inside_late += st.t_ns >= cut_from + s_to_ns(4.0) && st.t_ns < cut_to;
  EXPECT_GT(steps_inside_late, 5);
  EXPECT_GE(gyro_inside, steps_inside_late);
  EXPECT_EQ(steps_with(cut, HeadingSource::kGyro), gyro_inside);  // nowhere else
  EXPECT_GT(steps_with(cut, HeadingSource::kRotationVector, cut_to), 5);
}

TEST(PdrHeadingSource, ADisturbedFieldHandsTheHeadingToTheGyro) {
  // a magnetometer reading twice the Earth's field (WMM ~47 uT here) with every rotation vector
  // sample: the field test fails (HeadingFusionOptions::field_tolerance), the rotation vector that
  // used it is down-weighted to disturbed_weight, and the steps report the gyro
  const RealWalk walk = read_ilc(pdnav::test::shared_data(kWalk));
  const Eigen::Vector3d disturbed(60.0, 40.0, -50.0);  // 88 uT
  const SourceRun r = feed(walk, 0, 0, &disturbed);
  ASSERT_GT(total(r), 40);
  EXPECT_EQ(steps_with(r, HeadingSource::kGyro), total(r));
  EXPECT_EQ(steps_with(r, HeadingSource::kRotationVector), 0);
}

TEST(PdrHeadingSource, WithoutAGyroscopeTheFollowedStreamIsTheSource) {
  // the same disturbed walk from a phone without a gyroscope: nothing holds the heading through
  // the disturbance, the heading follows the absolute stream (HeadingFusionOptions::no_gyro_tau_s)
  // whatever its weight, so that stream is the source, never "gyro" (summary.json used to say
  // gyro on logs without one)
  const RealWalk walk = read_ilc(pdnav::test::shared_data(kWalk));
  const Eigen::Vector3d disturbed(60.0, 40.0, -50.0);
  const SourceRun r = feed(walk, 0, 0, &disturbed, false);
  ASSERT_GT(total(r), 40);
  EXPECT_EQ(steps_with(r, HeadingSource::kGyro), 0);
  EXPECT_EQ(steps_with(r, HeadingSource::kRotationVector), total(r));
}
