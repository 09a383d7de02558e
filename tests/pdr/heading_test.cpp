// Heading: APT gyro re-orientation turns on synthetic walks (known answers), rotation-vector
// heading with the WMM declination, the compass fallback.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/geo/wmm.h"
#include "pdnav/pdr/heading.h"
#include "pdnav/pdr/pdr.h"
#include "synthetic_imu.h"

using namespace pdnav;
using namespace pdnav::pdr;
using pdnav::test::make_walk;
using pdnav::test::TurnSegment;
using pdnav::test::WalkSpec;

namespace {

std::vector<PdrTurn> run_turns(const pdnav::test::SyntheticWalk& w, const TurnOptions& opt = {}) {
  GyroTurnTracker tracker(opt);
  std::vector<PdrTurn> turns;
  for (std::size_t i = 0; i < w.accel.size(); ++i) {
    tracker.feed(w.accel[i]);
    tracker.feed(w.gyro[i]);
    for (const auto& t : tracker.take_turns()) turns.push_back(t);
  }
  return turns;
}

}  // namespace

class TurnsAtTilt : public ::testing::TestWithParam<double> {};

TEST_P(TurnsAtTilt, RecoversKnownTurnsWithinTenDegrees) {
  const std::vector<TurnSegment> segs = {{10, 90}, {8, -45}, {8, 180}, {8, -90}, {8, 45}, {8, -180}};
  WalkSpec spec;
  spec.tilt_deg = GetParam();
  spec.mount_yaw_deg = 20.0;
  spec.seed = 7 + static_cast<std::uint64_t>(GetParam());
  const auto walk = make_walk(spec, segs);
  const auto turns = run_turns(walk);
  ASSERT_EQ(turns.size(), segs.size()) << "tilt " << spec.tilt_deg;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    EXPECT_NEAR(rad_to_deg(turns[i].angle_rad), segs[i].angle_deg, 10.0)
        << "turn " << i << " tilt " << spec.tilt_deg;
    EXPECT_LT(turns[i].start_ns, turns[i].t_ns);
  }
}

INSTANTIATE_TEST_SUITE_P(Tilts, TurnsAtTilt, ::testing::Values(0.0, 30.0, 50.0, 70.0));

TEST(Turns, NoTurnOnStraightWalksWithBiasAndNoise) {
  for (double tilt : {0.0, 35.0, 70.0}) {
    WalkSpec spec;
    spec.tilt_deg = tilt;
    spec.final_straight_s = 120.0;
    spec.gyro_bias_radps = Eigen::Vector3d(0.01, -0.01, 0.01);  // ~0.6 deg/s per axis
    spec.seed = 100 + static_cast<std::uint64_t>(tilt);
    const auto walk = make_walk(spec, {});
    EXPECT_TRUE(run_turns(walk).empty()) << "tilt " << tilt;
  }
}

TEST(Turns, SmallHeadingChangesAreNotReported) {
  WalkSpec spec;
  spec.tilt_deg = 20;
  const auto walk = make_walk(spec, {{10, 20}, {10, -20}});
  EXPECT_TRUE(run_turns(walk).empty());
}

TEST(Turns, GyroGapIsCountedAndDoesNotCreateTurns) {
  WalkSpec spec;
  auto walk = make_walk(spec, {{10, 90}});
  // Drop 2 s of gyro in the straight part after the turn and add bad samples.
  std::vector<GyroSample> gyro;
  for (const auto& g : walk.gyro) {
    const double t = ns_to_s(g.t_ns) - 1.0;
    if (t > 15.5 && t < 17.5) continue;
    gyro.push_back(g);
  }
  gyro.insert(gyro.begin() + 50, gyro[50]);  // duplicate
  gyro[60].rate_radps.x() = kNaN;             // NaN
  walk.gyro.swap(gyro);
  GyroTurnTracker tracker;
  std::vector<PdrTurn> turns;
  std::size_t gi = 0;
  for (const auto& a : walk.accel) {
    tracker.feed(a);
    while (gi < walk.gyro.size() && walk.gyro[gi].t_ns <= a.t_ns) tracker.feed(walk.gyro[gi++]);
    for (const auto& t : tracker.take_turns()) turns.push_back(t);
  }
  ASSERT_EQ(turns.size(), 1u);
  EXPECT_NEAR(rad_to_deg(turns[0].angle_rad), 90.0, 10.0);
  EXPECT_EQ(tracker.gyro_counters().gaps, 1);
  EXPECT_EQ(tracker.gyro_counters().duplicate_time, 1);
  EXPECT_EQ(tracker.gyro_counters().non_finite, 1);
}

TEST(RotationVectorHeading, ForwardAxisProjectedOnHorizontal) {
  // Phone upright on the chest (top up, camera facing forward), walker facing east.
  // Phone axes in ENU: +X = south (right of an east-facing walker), +Y = up, +Z = west (screen
  // toward the walker), so the forward axis -Z points east: heading 90 deg.
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(0, -1, 0);
  r.col(1) = Eigen::Vector3d(0, 0, 1);
  r.col(2) = Eigen::Vector3d(-1, 0, 0);
  const Eigen::Quaterniond q(r);
  const Eigen::Vector4d qv(q.x(), q.y(), q.z(), q.w());
  const auto h = rotation_vector_heading_rad(qv, forward_axis(Mount::kChestCameraOut));
  ASSERT_TRUE(h.has_value());
  EXPECT_NEAR(rad_to_deg(*h), 90.0, 1e-9);
  EXPECT_NEAR(rad_to_deg(*rotation_vector_heading_rad(qv, forward_axis(Mount::kChestScreenOut))), 270.0, 1e-9);
  // Handheld flat, top pointing north-west: +Y = (-1, 1, 0)/sqrt2.
  const Eigen::Quaterniond flat(Eigen::AngleAxisd(45 * kDegToRad, Eigen::Vector3d::UnitZ()));
  EXPECT_NEAR(rad_to_deg(*rotation_vector_heading_rad(Eigen::Vector4d(flat.x(), flat.y(), flat.z(), flat.w()),
                                                      forward_axis(Mount::kHandheld))),
              315.0, 1e-9);
  // Chest mount with the phone lying flat: -Z is vertical, no heading.
  EXPECT_FALSE(rotation_vector_heading_rad(Eigen::Vector4d(0, 0, 0, 1), forward_axis(Mount::kChestCameraOut)));
  EXPECT_FALSE(rotation_vector_heading_rad(Eigen::Vector4d(kNaN, 0, 0, 1), Eigen::Vector3d::UnitY()));
}

TEST(CompassHeading, TiltCompensated) {
  // Field pointing north and down (inclination 60 deg); phone flat, top pointing east.
  const Eigen::Quaterniond q(Eigen::AngleAxisd(-90 * kDegToRad, Eigen::Vector3d::UnitZ()));  // +Y -> east
  const Eigen::Vector3d field_enu(0, 20, -35);
  const Eigen::Vector3d field_phone = q.inverse() * field_enu;
  const Eigen::Vector3d up_phone = q.inverse() * Eigen::Vector3d::UnitZ();
  const auto h = compass_heading_rad(field_phone, up_phone, Eigen::Vector3d::UnitY());
  ASSERT_TRUE(h.has_value());
  EXPECT_NEAR(rad_to_deg(*h), 90.0, 1e-6);
}

TEST(PdrHeading, StepsCarryTrueNorthHeadingFromRotationVectorAndWmm) {
  // Walk north, handheld flat (mount +Y forward), rotation vector available.
  WalkSpec spec;
  spec.tilt_deg = 0.0;
  spec.mount_yaw_deg = -90.0;  // phone +Y along the walking direction
  spec.final_straight_s = 30.0;
  const auto walk = make_walk(spec, {});
  PdrOptions opt;
  opt.heading.mount = Mount::kHandheld;
  Pdr engine(opt);
  const geo::Geodetic boulder = geo::Geodetic::from_deg(40.0, -105.3, 1600.0);
  const std::int64_t utc_ms = 1767225600000;  // 2026-01-01
  engine.set_location(boulder, utc_ms);
  const double decl = geo::magnetic_declination_rad(boulder, utc_ms);
  EXPECT_GT(std::abs(rad_to_deg(decl)), 5.0);  // Colorado: about 7.5 deg east
  std::vector<PdrStep> steps;
  for (std::size_t i = 0; i < walk.accel.size(); ++i) {
    engine.feed(walk.rotation[i]);
    engine.feed(walk.gyro[i]);
    engine.feed(walk.accel[i]);
    for (const auto& s : engine.take_steps()) steps.push_back(s);
  }
  ASSERT_GT(steps.size(), 40u);
  EXPECT_NEAR(static_cast<double>(steps.size()), 30.0 * spec.cadence_hz, 3.0);
  for (const auto& s : steps) {
    // sway is +-3 deg about the walking direction (north = 0 in the RV frame); the heading is
    // gyro-dominant (issue 16: the rotation vector only corrects the gyro's offset), so the
    // synthetic gyro bias (~0.4 deg/s per axis) adds up to ~1 deg while its drift is learned
    EXPECT_NEAR(rad_to_deg(wrap_pi(s.heading_rad - decl)), 0.0, 5.0);
    EXPECT_NEAR(s.length_m, 0.415 * 1.75, 1e-9);
    EXPECT_GT(s.heading_sigma_rad, 0.0);
  }
}

TEST(PdrHeading, GyroOnlyHeadingFollowsTurnsFromInitialHeading) {
  WalkSpec spec;
  spec.tilt_deg = 40.0;
  const auto walk = make_walk(spec, {{10, 90}});  // north, then a left turn: west (270 deg)
  PdrOptions opt;
  opt.heading.initial_heading_rad = 0.0;  // true north
  Pdr engine(opt);
  std::vector<PdrStep> steps;
  for (std::size_t i = 0; i < walk.accel.size(); ++i) {
    engine.feed(walk.gyro[i]);
    engine.feed(walk.accel[i]);
    for (const auto& s : engine.take_steps()) steps.push_back(s);
  }
  ASSERT_FALSE(steps.empty());
  EXPECT_NEAR(rad_to_deg(wrap_pi(steps.back().heading_rad - 270.0 * kDegToRad)), 0.0, 10.0);
  const auto turns = engine.take_turns();
  ASSERT_EQ(turns.size(), 1u);
  EXPECT_GT(turns[0].angle_rad, 0.0);  // left
}

TEST(Turns, PrintAnglesForTheRecord) {
  // Not a bar by itself: prints the recovered angles per tilt (docs/pdr.md quotes them).
  const std::vector<TurnSegment> segs = {{10, 90}, {8, -45}, {8, 180}, {8, -90}, {8, 45}, {8, -180}};
  double worst = 0.0;
  for (double tilt : {0.0, 30.0, 50.0, 70.0}) {
    WalkSpec spec;
    spec.tilt_deg = tilt;
    spec.mount_yaw_deg = 20.0;
    spec.seed = 7 + static_cast<std::uint64_t>(tilt);
    const auto turns = run_turns(make_walk(spec, segs));
    ASSERT_EQ(turns.size(), segs.size());
    std::printf("tilt %2.0f:", tilt);
    for (std::size_t i = 0; i < turns.size(); ++i) {
      std::printf(" %+.1f", rad_to_deg(turns[i].angle_rad));
      worst = std::max(worst, std::abs(rad_to_deg(turns[i].angle_rad) - segs[i].angle_deg));
    }
    std::printf("\n");
  }
  std::printf("worst turn-angle error %.2f deg\n", worst);
  EXPECT_LT(worst, 10.0);
}

TEST(PdrHeading, BadRotationVectorAndMagSamplesAreCountedNotUsed) {
  PdrOptions opt;
  opt.heading.mount = Mount::kHandheld;
  Pdr engine(opt);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(-30 * kDegToRad, Eigen::Vector3d::UnitZ()));  // +Y -> 30 deg
  engine.feed(RotationVectorSample{s_to_ns(1.0), kMissingInt, Eigen::Vector4d(q.x(), q.y(), q.z(), q.w()), kNaN});
  EXPECT_NEAR(rad_to_deg(engine.heading_rad()), 30.0, 1e-9);
  engine.feed(RotationVectorSample{s_to_ns(1.1), kMissingInt, Eigen::Vector4d(kNaN, 0, 0, 1), kNaN});
  engine.feed(RotationVectorSample{s_to_ns(0.9), kMissingInt, Eigen::Vector4d(0, 0, 0, 1), kNaN});  // backwards
  engine.feed(MagSample{s_to_ns(1.2), kMissingInt, Eigen::Vector3d(kNaN, 1, 1)});
  engine.feed(MagSample{s_to_ns(1.3), kMissingInt, Eigen::Vector3d(0, 20, -30)});
  engine.feed(MagSample{s_to_ns(1.3), kMissingInt, Eigen::Vector3d(0, 20, -30)});  // duplicate
  EXPECT_NEAR(rad_to_deg(engine.heading_rad()), 30.0, 1e-9);  // bad samples did not move it
  const PdrCounters c = engine.counters();
  EXPECT_EQ(c.rotation_vector.non_finite, 1);
  EXPECT_EQ(c.rotation_vector.backwards_time, 1);
  EXPECT_EQ(c.mag.non_finite, 1);
  EXPECT_EQ(c.mag.duplicate_time, 1);
  EXPECT_EQ(c.total_skipped(), 4);
  EXPECT_TRUE(std::isfinite(engine.heading_sigma_rad()));
}

TEST(Turns, AxisYawHasNoConingDriftOnATwoAxisSwing) {
  // A phone swung like a thigh in a pocket: pitch +-30 deg and roll +-5 deg at 1 Hz, a quarter
  // cycle apart (R = Rx(roll) Ry(pitch), no yaw). The heading of its +Y axis never changes, but
  // the integral of the vertical angular rate gains the swept area, mean(pitch' sin(roll)) =
  // A_pitch A_roll w / 2 = 8 deg/s (coning). The attitude-based yaw of the axis must stay put.
  const double a_pitch = 30 * kDegToRad, a_roll = 5 * kDegToRad, w = 2 * kPi * 1.0;
  const auto rot = [&](double t) {
    return Eigen::Matrix3d(Eigen::AngleAxisd(a_roll * std::sin(w * t), Eigen::Vector3d::UnitX()) *
                           Eigen::AngleAxisd(a_pitch * std::cos(w * t), Eigen::Vector3d::UnitY()));
  };
  GyroTurnTracker tracker;
  tracker.set_yaw_axis(Eigen::Vector3d::UnitY());
  const double dt = 0.01, h = 1e-5;
  double axis0 = kNaN, yaw0 = kNaN;
  for (int k = 0; k <= 6200; ++k) {
    const double t = k * dt;
    const TimeNs t_ns = s_to_ns(t);
    const Eigen::Matrix3d r = rot(t);
    tracker.feed(AccelSample{t_ns, kMissingInt, r.transpose() * Eigen::Vector3d(0, 0, kStandardGravity_mps2)});
    const Eigen::AngleAxisd d(rot(t - h).transpose() * rot(t + h));  // body rate, central difference
    tracker.feed(GyroSample{t_ns + 1000, kMissingInt, d.axis() * d.angle() / (2 * h)});
    if (k == 200) axis0 = tracker.axis_yaw_rad(), yaw0 = tracker.yaw_rad();
  }
  const double axis_drift_deg = (tracker.axis_yaw_rad() - axis0) / kDegToRad;
  const double rate_drift_deg = (tracker.yaw_rad() - yaw0) / kDegToRad;
  std::printf("60 s two-axis swing: axis yaw %+.2f deg, vertical-rate integral %+.1f deg\n", axis_drift_deg,
              rate_drift_deg);
  EXPECT_LT(std::abs(axis_drift_deg), 2.0);  // measured +0.65 (trapezoidal rates at 100 Hz)
  EXPECT_GT(std::abs(rate_drift_deg), 300.0);  // the mechanism is there: ~8 deg/s x 60 s
}
