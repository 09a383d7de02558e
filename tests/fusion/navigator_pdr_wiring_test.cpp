// The Navigator's wiring of the PDR features of issues #19/#20: the declination applies from
// the first drained step (#20.2), dead reckoning's "relative heading only" reaches the output
// (#19.1), the declination's model and warning are exposed (#19.2), every step gives its own
// estimate at its own time and a walk shorter than the bout gate is released by finish()
// (#19.3 / #19.6).
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "pdnav/fusion/navigator.h"

namespace pdnav::fusion {
namespace {

MetaSample meta(TimeNs t, const std::string& key, const std::string& value) { return {t, key, value}; }

constexpr std::int64_t kUtc2026Ms = 1780272000000;  // 2026-06-01T00:00:00Z
constexpr TimeNs kStepNs = 550 * kNsPerMs;

struct Walk {
  EngineMode mode = EngineMode::kDeadReckoning;
  double lat_deg = 34.05, lon_deg = -118.25;  // Los Angeles: declination ~ +11 deg (WMM2025)
  int steps = 12;
  bool rotation_vector = true;  // absolute (magnetic) heading; false = step events only
  bool utc = true;
  bool finish = false;
  bool accel = false;  // steps from the APT detector on the accelerometer (bout gate) instead of
                       // Android step events; 2 s standing before, after_s after
  double after_s = 3.0;
};

struct Result {
  std::vector<Estimate> per_step;  // take_step_estimates() after every sample
  std::vector<TimeNs> step_t_ns;
  NavigatorOutput out;
  std::int64_t steps_before_finish = 0;
};

/// Android step events walking magnetic north (phone flat, camera forward = magnetic north),
/// start declared in Meta lines.
Result walk(const Walk& w) {
  NavigatorConfig cfg;
  cfg.mode = w.mode;
  Navigator nav(cfg, 1);
  Result r;
  TimeNs t = kNsPerS;
  nav.feed(meta(t, "StartLatitudeDegrees", std::to_string(w.lat_deg)));
  nav.feed(meta(t, "StartLongitudeDegrees", std::to_string(w.lon_deg)));
  Eigen::Matrix3d rot;  // device X east, Y up, Z south
  rot.col(0) = Eigen::Vector3d(1, 0, 0);
  rot.col(1) = Eigen::Vector3d(0, 0, 1);
  rot.col(2) = Eigen::Vector3d(0, -1, 0);
  const Eigen::Quaterniond q(rot);
  auto take = [&] {
    for (Estimate& e : nav.take_step_estimates()) r.per_step.push_back(std::move(e));
  };
  auto feed_rv = [&](TimeNs at) {
    RotationVectorSample rv;
    rv.t_ns = at;
    if (w.utc) rv.utc_ms = kUtc2026Ms + (at - kNsPerS) / kNsPerMs;
    rv.quat_xyzw = Eigen::Vector4d(q.x(), q.y(), q.z(), q.w());
    rv.heading_accuracy_rad = 0.1;
    nav.feed(rv);
    take();
  };
  if (w.accel) {
    // |a| bounces 2 m/s^2 at 1.8 steps/s (one step per period), gravity along device +Y (up)
    constexpr double kCadenceHz = 1.8;
    const TimeNs walk_from = t + 2 * kNsPerS;
    const TimeNs walk_to = walk_from + static_cast<TimeNs>(w.steps / kCadenceHz * 1e9);
    const TimeNs end = walk_to + static_cast<TimeNs>(w.after_s * 1e9);
    for (int i = 0; t < end; ++i) {
      t += 10 * kNsPerMs;
      if (w.rotation_vector && i % 2 == 0) feed_rv(t - kNsPerMs);
      const double ts = static_cast<double>(t - walk_from) * 1e-9;
      const double bounce = t >= walk_from && t < walk_to ? 2.0 * std::sin(2.0 * kPi * kCadenceHz * ts) : 0.0;
      AccelSample a;
      a.t_ns = t;
      if (w.utc) a.utc_ms = kUtc2026Ms + (t - kNsPerS) / kNsPerMs;
      a.acc_mps2 = Eigen::Vector3d(0.0, 9.81 + bounce, 0.0);
      nav.feed(a);
      take();
    }
  }
  for (int k = 0; k < w.steps && !w.accel; ++k) {
    t += kStepNs;
    if (w.rotation_vector) feed_rv(t - kNsPerMs);
    StepDetectorSample sd;
    sd.t_ns = t;
    if (w.utc) sd.utc_ms = kUtc2026Ms + (t - kNsPerS) / kNsPerMs;
    nav.feed(sd);
    r.step_t_ns.push_back(t);
    take();
  }
  r.steps_before_finish = nav.output(0).steps;
  if (w.finish) {
    nav.finish();
    take();
  }
  r.out = nav.output(0);
  return r;
}

double bearing_deg(const Eigen::Vector2d& d_en) { return rad_to_deg(std::atan2(d_en.x(), d_en.y())); }

void expect_no_heading_jump(const Result& r, const char* what) {
  ASSERT_GE(r.per_step.size(), 12u) << what;
  ASSERT_TRUE(r.out.declination_known) << what;
  const double d_deg = rad_to_deg(r.out.declination.declination_rad);
  ASSERT_GT(d_deg, 8.0) << what << ": the test needs a place with ~10 deg declination";
  // start -> 4th step (the first drained steps) and 4th -> 12th step: one straight line at the
  // true bearing of magnetic north
  const double first = bearing_deg(r.per_step[3].en_m);
  const double later = bearing_deg(r.per_step[11].en_m - r.per_step[3].en_m);
  EXPECT_NEAR(first, later, 0.5) << what << ": heading jump after the fourth step";
  EXPECT_NEAR(first, d_deg, 1.0) << what;
  // every step's own row moves the same way
  for (std::size_t k = 1; k < r.per_step.size(); ++k)
    EXPECT_NEAR(bearing_deg(r.per_step[k].en_m - r.per_step[k - 1].en_m), d_deg, 1.0) << what << " step " << k;
}

TEST(NavigatorPdrWiring, DeclinationAppliesFromTheFirstDrainedStep) {
  Walk w;
  expect_no_heading_jump(walk(w), "dr, step events");
  w.mode = EngineMode::kAuto;
  expect_no_heading_jump(walk(w), "fused, step events");
  w.accel = true;  // the bout gate releases the first four steps at once
  w.steps = 16;
  expect_no_heading_jump(walk(w), "fused, accelerometer");
  w.mode = EngineMode::kDeadReckoning;
  expect_no_heading_jump(walk(w), "dr, accelerometer");
}

TEST(NavigatorPdrWiring, OneEstimatePerStepAtItsOwnTime) {
  Walk w;
  const Result r = walk(w);
  // the bout gate releases the first four steps at once: still four estimates
  ASSERT_EQ(r.per_step.size(), r.step_t_ns.size());
  for (std::size_t k = 0; k < r.per_step.size(); ++k) EXPECT_EQ(r.per_step[k].t_ns, r.step_t_ns[k]) << k;
  for (std::size_t k = 1; k < r.per_step.size(); ++k) EXPECT_GT((r.per_step[k].en_m - r.per_step[k - 1].en_m).norm(), 0.3) << k;
}

TEST(NavigatorPdrWiring, RelativeHeadingOnlyReachesTheOutput) {
  Walk w;
  w.rotation_vector = false;  // step events only: the heading is relative
  Result r = walk(w);
  EXPECT_NE(r.out.estimate.reason.find("relative heading only"), std::string::npos) << r.out.estimate.reason;
  w.mode = EngineMode::kAuto;
  r = walk(w);
  EXPECT_NE(r.out.estimate.reason.find("relative heading only"), std::string::npos) << r.out.estimate.reason;
  // with an absolute heading it is not said
  w.rotation_vector = true;
  r = walk(w);
  EXPECT_EQ(r.out.estimate.reason.find("relative heading only"), std::string::npos) << r.out.estimate.reason;
  w.mode = EngineMode::kDeadReckoning;
  r = walk(w);
  EXPECT_EQ(r.out.estimate.reason.find("relative heading only"), std::string::npos) << r.out.estimate.reason;
}

TEST(NavigatorPdrWiring, DeclinationModelAndWarningExposed) {
  Walk w;
  Result r = walk(w);
  EXPECT_TRUE(r.out.declination_known);
  EXPECT_FALSE(r.out.declination.model.empty());
  EXPECT_TRUE(r.out.declination.warning.empty()) << r.out.declination.warning;
  w.utc = false;  // no wall clock in the log
  r = walk(w);
  EXPECT_TRUE(r.out.declination_known);
  EXPECT_FALSE(r.out.declination.model.empty());
  EXPECT_NE(r.out.declination.warning.find("no UTC"), std::string::npos) << r.out.declination.warning;
}

TEST(NavigatorPdrWiring, AcceleratorStepsEachAtTheirOwnTime) {
  Walk w;
  w.accel = true;
  w.steps = 16;
  const Result r = walk(w);
  ASSERT_GE(r.out.steps, 12);
  // the bout gate releases the first four steps in one sample: four estimates, four times
  ASSERT_EQ(r.per_step.size(), static_cast<std::size_t>(r.out.steps));
  for (std::size_t k = 1; k < r.per_step.size(); ++k) {
    const double dt_s = static_cast<double>(r.per_step[k].t_ns - r.per_step[k - 1].t_ns) * 1e-9;
    EXPECT_NEAR(dt_s, 1.0 / 1.8, 0.1) << k;
  }
}

TEST(NavigatorPdrWiring, ShortWalkReportedAtFinish) {
  Walk w;
  w.accel = true;
  w.steps = 3;
  w.after_s = 0.5;  // the log ends before the pause that ends the walk (max_step_interval_s)  // shorter than the bout gate (4), long enough for a short walk (3)
  Result r = walk(w);
  EXPECT_EQ(r.steps_before_finish, 0);
  EXPECT_EQ(r.out.steps, 0);
  w.finish = true;
  r = walk(w);
  EXPECT_EQ(r.steps_before_finish, 0);
  EXPECT_EQ(r.out.steps, 3);
  ASSERT_EQ(r.per_step.size(), 3u);
  for (std::size_t k = 1; k < 3; ++k) EXPECT_GT(r.per_step[k].t_ns, r.per_step[k - 1].t_ns) << k;
  EXPECT_GT(r.out.estimate.en_m.norm(), 1.5);
}

}  // namespace
}  // namespace pdnav::fusion
