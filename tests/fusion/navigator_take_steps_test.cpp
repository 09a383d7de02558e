// Navigator::take_steps (issue 29, the app's per-step estimates through JNI navTakeSteps): one
// entry per step with its heading and the distance walked; the estimate moves by each step
// along its heading; steps before the start position carry an invalid estimate and
// take_step_estimates() (the replay's rows) shares the queue but keeps only valid ones.
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "pdnav/fusion/navigator.h"

namespace pdnav::fusion {
namespace {

constexpr TimeNs kStepNs = 550 * kNsPerMs;
constexpr std::int64_t kUtc2026Ms = 1780272000000;  // 2026-06-01T00:00:00Z

/// Android step events, phone upright on the chest (the default mount) facing yaw_deg
/// clockwise from magnetic north (rotation vector, as in navigator_pdr_wiring_test).
void walk(Navigator& nav, TimeNs& t, int steps, double yaw_deg) {
  Eigen::Matrix3d rot;  // device X east, Y up, Z south: facing magnetic north
  rot.col(0) = Eigen::Vector3d(1, 0, 0);
  rot.col(1) = Eigen::Vector3d(0, 0, 1);
  rot.col(2) = Eigen::Vector3d(0, -1, 0);
  const Eigen::Quaterniond q =
      Eigen::AngleAxisd(-yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()) * Eigen::Quaterniond(rot);
  for (int k = 0; k < steps; ++k) {
    t += kStepNs;
    RotationVectorSample rv;
    rv.t_ns = t - kNsPerMs;
    rv.utc_ms = kUtc2026Ms + t / kNsPerMs;
    rv.quat_xyzw = Eigen::Vector4d(q.x(), q.y(), q.z(), q.w());
    rv.heading_accuracy_rad = 0.1;
    nav.feed(rv);
    StepDetectorSample sd;
    sd.t_ns = t;
    sd.utc_ms = kUtc2026Ms + t / kNsPerMs;
    nav.feed(sd);
  }
}

TEST(NavigatorTakeSteps, HeadingAndDistanceFollowTheSteps) {
  NavigatorConfig cfg;
  cfg.mode = EngineMode::kDeadReckoning;
  cfg.start_lat_deg = 46.5;
  cfg.start_lon_deg = 7.5;
  Navigator nav(cfg, 1);
  TimeNs t = kNsPerS;
  walk(nav, t, 10, 0.0);
  walk(nav, t, 10, 90.0);  // then turn to magnetic east
  const std::vector<StepEstimate> steps = nav.take_steps();
  ASSERT_EQ(steps.size(), 20u);
  EXPECT_EQ(nav.output(0).steps, 20);
  EXPECT_TRUE(nav.take_steps().empty());
  EXPECT_TRUE(nav.take_step_estimates().empty()) << "one queue";
  for (std::size_t k = 1; k < steps.size(); ++k) {
    const StepEstimate& a = steps[k - 1];
    const StepEstimate& b = steps[k];
    ASSERT_TRUE(b.estimate.valid());
    const double len = b.distance_m - a.distance_m;
    EXPECT_GT(len, 0.3) << k;
    EXPECT_LT(len, 1.2) << k;
    const Eigen::Vector2d d = b.estimate.en_m - a.estimate.en_m;
    EXPECT_NEAR(d.norm(), len, 1e-6 * len + 1e-9) << "the estimate moves by the step, step " << k;
    const double bearing = std::atan2(d.x(), d.y());
    EXPECT_NEAR(std::remainder(bearing - b.heading_rad, 2.0 * kPi), 0.0, 1e-6) << "along its heading, step " << k;
    EXPECT_GE(b.heading_rad, 0.0);
    EXPECT_LT(b.heading_rad, 2.0 * kPi);
  }
  // the turn: 90 deg between the last northward and the last eastward step (declination cancels)
  EXPECT_NEAR(std::remainder(steps[19].heading_rad - steps[9].heading_rad, 2.0 * kPi), kPi / 2, 0.05);
}

TEST(NavigatorTakeSteps, StepsBeforeAStartCarryAnInvalidEstimate) {
  NavigatorConfig cfg;
  cfg.mode = EngineMode::kDeadReckoning;  // no start position, none in the log
  Navigator nav(cfg, 1);
  TimeNs t = kNsPerS;
  walk(nav, t, 5, 0.0);
  const std::vector<StepEstimate> steps = nav.take_steps();
  ASSERT_EQ(steps.size(), 5u);
  for (const StepEstimate& s : steps) EXPECT_FALSE(s.estimate.valid());
  EXPECT_GT(steps.back().distance_m, steps.front().distance_m);
  walk(nav, t, 3, 0.0);
  EXPECT_TRUE(nav.take_step_estimates().empty()) << "the replay's rows keep valid estimates only";
  EXPECT_TRUE(nav.take_steps().empty()) << "taken by take_step_estimates (one queue)";
}

}  // namespace
}  // namespace pdnav::fusion
