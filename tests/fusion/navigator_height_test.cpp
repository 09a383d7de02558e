// The Navigator takes the user's height (APT step length, 0.415 h) from the configuration or,
// when that is unset, from a recorded session's Meta UserHeightMeters line, so a field session
// replays with the step length it was recorded with.
#include <cmath>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "pdnav/fusion/navigator.h"
#include "walk_fixtures.h"

namespace pdnav::fusion {
namespace {

MetaSample meta(TimeNs t, const std::string& key, const std::string& value) { return {t, key, value}; }

/// 100 Android step events walking north (phone flat, camera forward = north), start declared in
/// Meta lines; returns the dead-reckoned distance from the start.
double walked_m(NavigatorConfig cfg, const std::string& height_meta, std::string* ignored = nullptr) {
  cfg.mode = EngineMode::kDeadReckoning;
  Navigator nav(cfg, 1);
  TimeNs t = kNsPerS;
  nav.feed(meta(t, "StartLatitudeDegrees", "42.5"));
  nav.feed(meta(t, "StartLongitudeDegrees", "1.5"));
  if (!height_meta.empty()) nav.feed(meta(t, "UserHeightMeters", height_meta));
  // chest mount, camera forward (-Z) pointing north: device X east, Y up, Z south
  const Eigen::Quaterniond q(test::chest_facing_north());
  for (int k = 0; k < 100; ++k) {
    t += 550 * kNsPerMs;
    for (const Sample& s : test::step_events(t - kNsPerMs, t, q)) nav.feed(s);
  }
  if (ignored != nullptr)
    for (const auto& [why, n] : nav.ignored()) *ignored += why + ";";
  const Estimate e = nav.estimate();
  EXPECT_TRUE(e.valid()) << e.reason;
  return e.en_m.norm();
}

TEST(NavigatorHeight, FromTheLogWhenNotConfigured) {
  NavigatorConfig cfg;  // user_height_m unset
  EXPECT_NEAR(walked_m(cfg, ""), 100 * 0.415 * kDefaultUserHeightM, 0.5);
  EXPECT_NEAR(walked_m(cfg, "1.50"), 100 * 0.415 * 1.50, 0.5);
}

TEST(NavigatorHeight, ConfigurationWinsOverTheLog) {
  NavigatorConfig cfg;
  cfg.user_height_m = 1.90;
  EXPECT_NEAR(walked_m(cfg, "1.50"), 100 * 0.415 * 1.90, 0.5);
}

TEST(NavigatorHeight, AbsurdHeightIsCountedAndIgnored) {
  NavigatorConfig cfg;
  std::string ignored;
  EXPECT_NEAR(walked_m(cfg, "17.5", &ignored), 100 * 0.415 * kDefaultUserHeightM, 0.5);
  EXPECT_NE(ignored.find("Meta UserHeightMeters: not a height in 0.5-2.5 m"), std::string::npos) << ignored;
}

}  // namespace
}  // namespace pdnav::fusion
