// Issues 20.2, 19.3, 19.6: the first steps of a walk. The bout gate holds the first four
// steps; each must still carry its own time and the heading at that time, in the same
// (true-north) frame as every later step, and a walk too short for the gate still counts.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/geo/wmm.h"
#include "pdnav/pdr/heading.h"
#include "pdnav/pdr/pdr.h"
#include "pdnav/pdr/step_detector.h"
#include "synthetic_imu.h"

using namespace pdnav;
using namespace pdnav::pdr;

namespace {

constexpr std::int64_t kJuly2025UnixMs = 1751328000000;  // 2025-07-01T00:00Z

PdrOptions handheld() {
  PdrOptions o;
  o.heading.mount = Mount::kHandheld;
  return o;
}

test::WalkSpec handheld_spec() {
  test::WalkSpec spec;
  spec.mount_yaw_deg = -90.0;  // phone +Y (the handheld forward axis) along the walk
  spec.tilt_deg = 20.0;
  return spec;
}

/// Feeds a synthetic walk sample by sample; `on_sample(i)` runs before the steps are taken.
template <typename F>
std::vector<PdrStep> run(Pdr& pdr, const test::SyntheticWalk& w, F on_sample) {
  std::vector<PdrStep> steps;
  for (std::size_t i = 0; i < w.accel.size(); ++i) {
    pdr.feed(w.gyro[i]);
    pdr.feed(w.rotation[i]);
    pdr.feed(w.accel[i]);
    on_sample(i);
    for (const auto& s : pdr.take_steps()) steps.push_back(s);
  }
  pdr.finish();
  for (const auto& s : pdr.take_steps()) steps.push_back(s);
  return steps;
}

double angle_diff_deg(double a, double b) { return std::abs(rad_to_deg(wrap_pi(a - b))); }

}  // namespace

TEST(FirstSteps, NoHeadingJumpAfterTheFourthStepWhereDeclinationIsTenDegrees) {
  // Helsinki, mid 2025: WMM declination about +10.5 deg. The start position becomes known
  // while the bout gate still holds the first four steps (as when a session's start arrives
  // with its first steps); all steps must come out in the one true-north frame.
  const geo::Geodetic helsinki = geo::Geodetic::from_deg(60.17, 24.94, 0.0);
  const double decl = geo::magnetic_declination_rad(helsinki, kJuly2025UnixMs);
  ASSERT_NEAR(rad_to_deg(decl), 10.5, 1.0);
  test::WalkSpec spec = handheld_spec();
  spec.sway_yaw_deg = 0.0;  // no gait yaw sway: any step-to-step change is the frame's
  const auto walk = test::make_walk(spec, {{30.0, 0.0}});  // straight north
  Pdr pdr(handheld());
  bool located = false;
  const auto steps = run(pdr, walk, [&](std::size_t) {
    if (!located && pdr.step_count() >= 1) {
      pdr.set_location(helsinki, kJuly2025UnixMs);
      located = true;
    }
  });
  ASSERT_GE(steps.size(), 40u);
  for (std::size_t i = 1; i < steps.size(); ++i) {
    EXPECT_LT(angle_diff_deg(steps[i].heading_rad, steps[i - 1].heading_rad), 3.0) << "between steps " << i << " and " << i + 1;
  }
  // And the frame is true north: the walk goes magnetic north in the rotation vector, so the
  // true heading is the declination.
  EXPECT_LT(angle_diff_deg(steps[2].heading_rad, decl), 4.0);
  EXPECT_LT(angle_diff_deg(steps.back().heading_rad, decl), 4.0);
}

TEST(FirstSteps, HeldStepsKeepTheirOwnTimeAndHeading) {
  // A walk that turns 90 deg left while the bout gate holds its first steps: each released
  // step has its own time and the heading at that time, not the heading at the release.
  test::WalkSpec spec = handheld_spec();
  spec.turn_rate_dps = 60.0;
  const auto walk = test::make_walk(spec, {{0.3, 90.0}});  // turn from 0.3 s to 3.3 s
  PdrOptions opt = handheld();
  opt.detector.bout_min_steps_gyro = 0;  // hold four steps as without a gyro (see the next test)
  Pdr pdr(opt);
  std::vector<TimeNs> release_times;
  std::int64_t seen = 0;
  const auto steps = run(pdr, walk, [&](std::size_t i) {
    while (seen < pdr.step_count()) {
      release_times.push_back(walk.accel[i].t_ns);
      ++seen;
    }
  });
  ASSERT_GE(steps.size(), 8u);
  ASSERT_GE(release_times.size(), 4u);
  // The first four were released together, after the fourth step was taken.
  EXPECT_EQ(release_times[0], release_times[3]);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_LT(steps[i].t_ns, release_times[0] + 1) << i;
    if (i > 0) EXPECT_GT(ns_to_s(steps[i].t_ns - steps[i - 1].t_ns), 0.3) << i;
    // Heading at the step's own time: the rotation vector's heading at that instant.
    const std::size_t k = static_cast<std::size_t>(
        std::lower_bound(walk.accel.begin(), walk.accel.end(), steps[i].t_ns,
                         [](const AccelSample& a, TimeNs t) { return a.t_ns < t; }) -
        walk.accel.begin());
    const auto truth = rotation_vector_heading_rad(walk.rotation[k].quat_xyzw, forward_axis(Mount::kHandheld));
    ASSERT_TRUE(truth.has_value());
    EXPECT_LT(angle_diff_deg(steps[i].heading_rad, *truth), 3.0) << "step " << i + 1;
  }
  for (std::size_t i = 0; i < 5; ++i)
    std::printf("step %zu at %.2f s, heading %.1f deg, released at %.2f s\n", i + 1, ns_to_s(steps[i].t_ns),
                rad_to_deg(steps[i].heading_rad), ns_to_s(release_times[i]));
  // The turn is under way: the held steps' headings differ (at one release time they'd be equal).
  EXPECT_GT(angle_diff_deg(steps[0].heading_rad, steps[3].heading_rad), 15.0);
}

/// Times at which each step of `walk` left the engine (released by the bout gate).
std::vector<TimeNs> release_times_of(Pdr& pdr, const test::SyntheticWalk& walk, bool with_gyro) {
  std::vector<TimeNs> released;
  std::int64_t seen = 0;
  for (std::size_t i = 0; i < walk.accel.size(); ++i) {
    if (with_gyro) pdr.feed(walk.gyro[i]);
    pdr.feed(walk.rotation[i]);
    pdr.feed(walk.accel[i]);
    for (; seen < pdr.step_count(); ++seen) released.push_back(walk.accel[i].t_ns);
    (void)pdr.take_steps();
  }
  return released;
}

TEST(FirstSteps, WithALiveGyroTheBoutIsConfirmedAtTheSecondStep) {
  // Latency of the first steps: with a gyroscope the motion classifier refuses handling, so
  // the bout gate needs two regular steps, not four; the walker's position then keeps up from
  // the second step instead of lagging three steps behind at every start (docs/pdr.md
  // "Latency of the first steps"). Without a gyro (Oxford-like input) four are still needed.
  const auto walk = test::make_walk(handheld_spec(), {});
  Pdr with_gyro(handheld()), without_gyro(handheld());
  const auto fast = release_times_of(with_gyro, walk, true);
  const auto held = release_times_of(without_gyro, walk, false);
  ASSERT_GE(fast.size(), 8u);
  ASSERT_GE(held.size(), 8u);
  EXPECT_EQ(fast[0], fast[1]);   // the first two leave together, at the second step
  EXPECT_LT(fast[1], fast[2]);   // from then on, one at a time
  EXPECT_EQ(held[0], held[3]);   // without a gyro the first four are held
  EXPECT_LT(held[3], held[4]);
  EXPECT_LT(fast[0], held[0]);
  std::printf("first release: %.2f s with a gyro, %.2f s without\n", ns_to_s(fast[0]), ns_to_s(held[0]));
}

TEST(FirstSteps, AWalkShorterThanTheGateIsReportedWhenItEnds) {
  // Three steps (a 2 m walk: one |a| cycle per step, 0.55 s each) between 3 s and 4 s of
  // standing still; fewer than the gate's four.
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<AccelSample> accel;
  const double rate_hz = 100.0, step_s = 0.55, walk_from_s = 3.0;
  for (int i = 0; i < static_cast<int>((walk_from_s + 3 * step_s + 4.0) * rate_hz); ++i) {
    const double t = i / rate_hz;
    const bool walking = t >= walk_from_s && t < walk_from_s + 3 * step_s;
    const double m = kStandardGravity_mps2 + (walking ? 2.5 * std::sin(2 * kPi * (t - walk_from_s) / step_s) : 0.0) + noise(rng);
    accel.push_back(AccelSample{s_to_ns(1.0 + t), kMissingInt, Eigen::Vector3d(0.3 * m, 0.8 * m, 0.52 * m)});
  }
  const auto steps = detect_steps(accel, StepDetectorOptions{});
  StepDetectorOptions no_short;
  no_short.short_walk_min_steps = 0;
  const auto gated = detect_steps(accel, no_short);
  std::printf("short walk: %zu steps (%zu with the plain bout gate)\n", steps.size(), gated.size());
  EXPECT_GE(steps.size(), 3u);
  EXPECT_LE(steps.size(), 6u);
  // Streaming: Pdr reports them once the walk has ended, without waiting for finish().
  Pdr pdr;
  std::size_t streamed = 0;
  for (const auto& s : accel) {
    pdr.feed(s);
    streamed += pdr.take_steps().size();
  }
  EXPECT_EQ(streamed, steps.size());
}

TEST(BoutGate, ShortWalkReleasedWhenItEndsButTwoStepsAreNot) {
  BoutGate<int> gate(4, 1.0, 3);
  EXPECT_TRUE(gate.push(s_to_ns(0.0), 1).empty());
  EXPECT_TRUE(gate.push(s_to_ns(0.5), 2).empty());
  EXPECT_TRUE(gate.push(s_to_ns(1.0), 3).empty());
  EXPECT_TRUE(gate.expire(s_to_ns(1.5)).empty());  // not over yet
  EXPECT_EQ(gate.expire(s_to_ns(2.5)), (std::vector<int>{1, 2, 3}));
  EXPECT_TRUE(gate.push(s_to_ns(5.0), 4).empty());
  EXPECT_TRUE(gate.push(s_to_ns(5.5), 5).empty());
  EXPECT_TRUE(gate.finish().empty());  // two steps: as likely a jolt
  EXPECT_EQ(gate.discarded(), 2);
  EXPECT_EQ(gate.short_walk_steps(), 3);
  // Irregular "steps" (0.3 s then 0.9 s) are not a walk.
  EXPECT_TRUE(gate.push(s_to_ns(10.0), 6).empty());
  EXPECT_TRUE(gate.push(s_to_ns(10.3), 7).empty());
  EXPECT_TRUE(gate.push(s_to_ns(11.2), 8).empty());
  EXPECT_TRUE(gate.finish().empty());
}

namespace {
/// Standing, `n_steps` steps (one |a| cycle of 0.55 s each), standing; with or without a gyro
/// (a still phone: 0.02 rad/s noise, 0.005 rad/s bias per axis) at 100 Hz.
std::size_t steps_of_short_walk(int n_steps, bool with_gyro, PdrOptions opt) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.05), gyro_noise(0.0, 0.02);
  const double rate_hz = 100.0, step_s = 0.55, walk_from_s = 3.0;
  Pdr pdr(opt);
  std::size_t n = 0;
  for (int i = 0; i < static_cast<int>((walk_from_s + n_steps * step_s + 4.0) * rate_hz); ++i) {
    const double t = i / rate_hz;
    const bool walking = t >= walk_from_s && t < walk_from_s + n_steps * step_s;
    const double m =
        kStandardGravity_mps2 + (walking ? 2.5 * std::sin(2 * kPi * (t - walk_from_s) / step_s) : 0.0) + noise(rng);
    const TimeNs t_ns = s_to_ns(1.0 + t);
    if (with_gyro) {
      pdr.feed(GyroSample{t_ns, kMissingInt,
                          Eigen::Vector3d(0.005 + gyro_noise(rng), -0.005 + gyro_noise(rng), 0.005 + gyro_noise(rng))});
    }
    pdr.feed(AccelSample{t_ns, kMissingInt, Eigen::Vector3d(0.3 * m, 0.8 * m, 0.52 * m)});
    n += pdr.take_steps().size();
  }
  pdr.finish();
  return n + pdr.take_steps().size();
}
}  // namespace

TEST(FirstSteps, TwoStepsBetweenPausesCountWhenTheHandlingGateCanRefuseJolts) {
  // Stepping on to the next spot and stopping (ILC survey walks: 1-2 m to a waypoint). With a
  // live gyroscope the motion classifier refuses handling, so two regular steps are a walk;
  // without one (or with the handling gate off) two steps stay "as likely a jolt".
  const std::size_t with_gyro = steps_of_short_walk(2, true, PdrOptions{});
  const std::size_t accel_only = steps_of_short_walk(2, false, PdrOptions{});
  PdrOptions no_gate;
  no_gate.gate_handling = false;
  const std::size_t gyro_no_gate = steps_of_short_walk(2, true, no_gate);
  std::printf("two-step walk: %zu steps with a gyro, %zu accelerometer only, %zu with the handling gate off\n",
              with_gyro, accel_only, gyro_no_gate);
  EXPECT_EQ(with_gyro, 2u);
  EXPECT_EQ(accel_only, 0u);
  EXPECT_EQ(gyro_no_gate, 0u);
  // one step alone is never a walk
  EXPECT_EQ(steps_of_short_walk(1, true, PdrOptions{}), 0u);
}
