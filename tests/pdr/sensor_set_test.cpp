// Issue 27, "every sensor set": a log of the fused sensors only (rotation vector + step events,
// what `pdnav simulate` writes) gets a heading from the rotation vector's own gravity; the
// uncalibrated streams stand in for missing calibrated ones and are ignored beside them.
#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "pdnav/pdr/pdr.h"
#include "pdnav/sim/world.h"
#include "synthetic_imu.h"

using namespace pdnav;
using namespace pdnav::pdr;

namespace {

double heading_deg(const PdrStep& s) { return wrap_two_pi(s.heading_rad) / kDegToRad; }

PdrOptions as_navigator() {  // Android step events while they arrive, placement found (auto)
  PdrOptions o;
  o.source = StepSource::kAuto;
  o.heading.mount = Mount::kAuto;
  return o;
}

double angle_diff_deg(double a, double b) { return std::abs(wrap_pi((a - b) * kDegToRad)) / kDegToRad; }

/// Rotation vector only, one step event every 0.55 s; heading_of(t) gives the phone attitude.
template <typename Attitude>
std::vector<PdrStep> rv_only_walk(Attitude attitude_at, double duration_s, Pdr& pdr) {
  std::vector<PdrStep> steps;
  const TimeNs dt_ns = 20'000'000;  // 50 Hz rotation vector
  TimeNs next_step_ns = 1'000'000'000;
  for (TimeNs t = 0; t <= s_to_ns(duration_s); t += dt_ns) {
    RotationVectorSample rv;
    rv.t_ns = t;
    rv.quat_xyzw = attitude_at(ns_to_s(t));
    pdr.feed(rv);
    if (t >= next_step_ns) {
      pdr.feed(StepDetectorSample{t});
      next_step_ns += 550'000'000;
    }
    for (const PdrStep& s : pdr.take_steps()) steps.push_back(s);
  }
  pdr.finish();
  for (const PdrStep& s : pdr.take_steps()) steps.push_back(s);
  return steps;
}

}  // namespace

TEST(PdrSensorSet, RotationVectorOnlyChestPhoneWalksItsHeading) {
  // chest mount, camera forward (+Y up): east for 20 s, then south; the old auto path looked
  // for the heading of +Y (vertical here) and gave every step the initial heading (north)
  Pdr pdr(as_navigator());
  const auto steps = rv_only_walk(
      [](double t) { return sim::chest_mount_quat_xyzw((t < 20.0 ? 90.0 : 180.0) * kDegToRad); }, 40.0, pdr);
  ASSERT_GT(steps.size(), 60u);
  int checked = 0;
  for (const PdrStep& s : steps) {
    const double t = ns_to_s(s.t_ns);
    if (std::abs(t - 20.0) < 1.0) continue;  // the turn itself
    EXPECT_LT(angle_diff_deg(heading_deg(s), t < 20.0 ? 90.0 : 180.0), 2.0) << "step at " << t << " s";
    ++checked;
  }
  EXPECT_GT(checked, 55);
  EXPECT_EQ(pdr.sensor_set().name(), "rv+steps");
  EXPECT_EQ(pdr.sensor_set().heading_reference(), "rotation vector");
}

TEST(PdrSensorSet, RotationVectorOnlyFlatPhoneWalksItsTop) {
  // screen up, top ahead, walking 240 deg: the flat prior (+Y)
  const double h = 240.0 * kDegToRad;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(-h, Eigen::Vector3d::UnitZ()));  // +Y -> (sin h, cos h, 0)
  Pdr pdr(as_navigator());
  const auto steps =
      rv_only_walk([&](double) { return Eigen::Vector4d(q.x(), q.y(), q.z(), q.w()); }, 20.0, pdr);
  ASSERT_GT(steps.size(), 30u);
  for (const PdrStep& s : steps) EXPECT_LT(angle_diff_deg(heading_deg(s), 240.0), 1.0) << heading_deg(s);
}

TEST(PdrSensorSet, UncalibratedStreamsStandInAndAreIgnoredBesideCalibrated) {
  test::WalkSpec spec;
  spec.seed = 3;
  const test::SyntheticWalk w = test::make_walk(spec, {{10, 90}, {8, -45}});
  const Eigen::Vector3d drift(0.02, -0.015, 0.03);  // rad/s: a gyro offset the OS estimated
  PdrOptions opt;
  opt.heading.mount = Mount::kHandheld;  // the synthetic phone lies flat, top ahead (the default
                                         // chest mount's -Z is vertical: no heading to compare)
  const auto run = [&](bool calibrated, bool uncal) {
    Pdr pdr(opt);
    std::vector<PdrStep> out;
    for (std::size_t i = 0; i < w.accel.size(); ++i) {
      pdr.feed(w.accel[i]);
      if (calibrated) pdr.feed(w.gyro[i]);
      if (uncal) pdr.feed(UncalGyroSample{w.gyro[i].t_ns, w.gyro[i].utc_ms, w.gyro[i].rate_radps + drift, drift});
      if (i < w.rotation.size()) pdr.feed(w.rotation[i]);
      for (const PdrStep& s : pdr.take_steps()) out.push_back(s);
    }
    pdr.finish();
    for (const PdrStep& s : pdr.take_steps()) out.push_back(s);
    return std::make_pair(out, pdr.sensor_set());
  };
  const auto [cal, cal_set] = run(true, false);
  const auto [unc, unc_set] = run(false, true);
  const auto [both, both_set] = run(true, true);
  ASSERT_GT(cal.size(), 20u);
  // uncalibrated with its drift removed, used after 1 s without a calibrated gyro: the same
  // walk (the first second lacks the gyro: its steps may differ, not the headings after it)
  ASSERT_NEAR(static_cast<double>(unc.size()), static_cast<double>(cal.size()), 2.0);
  int compared = 0;
  for (const PdrStep& u : unc) {
    if (ns_to_s(u.t_ns) < 3.0) continue;
    for (const PdrStep& c : cal)
      if (c.t_ns == u.t_ns) {
        EXPECT_LT(std::abs(wrap_pi(u.heading_rad - c.heading_rad)), 2.0 * kDegToRad);
        ++compared;
      }
  }
  EXPECT_GT(compared, 20);
  double spread = 0.0;  // the walk turned: the headings compared are not one constant
  for (const PdrStep& c : cal) spread = std::max(spread, std::abs(wrap_pi(c.heading_rad - cal.front().heading_rad)));
  EXPECT_GT(spread, 40.0 * kDegToRad);
  // beside the calibrated stream it is ignored: identical output
  ASSERT_EQ(both.size(), cal.size());
  for (std::size_t i = 0; i < cal.size(); ++i) EXPECT_EQ(both[i].heading_rad, cal[i].heading_rad);
  EXPECT_EQ(cal_set.name(), "accel+gyro+rv");
  EXPECT_EQ(unc_set.name(), "accel+uncal gyro+rv");
  EXPECT_EQ(both_set.uncal_gyro, 0);
}
