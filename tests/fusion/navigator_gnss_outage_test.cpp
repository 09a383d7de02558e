// The fused estimate through a GNSS outage on the real Mountain View log (issue 14): a 60 s gap
// cut into its Raw rows (and, in the harder variant, into its Fix rows too). Bars: no shown
// jump above 3 sigma of the combined covariance of consecutive estimates, and after the gap
// the error against the surveyed antenna position is no worse than GNSS alone.
#include <algorithm>
#include <cmath>
#include <iterator>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "pdnav/fusion/navigator.h"
#include "pdnav/io/log_reader.h"
#include "test_data.h"
#include "walk_fixtures.h"

namespace pdnav::fusion {
namespace {

const geo::Geodetic kSurveyed = geo::Geodetic::from_deg(37.422578, -122.081678, -28.0);

std::vector<Sample> read_log() {
  io::LogReader log(test::shared_data("gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt"));
  std::vector<Sample> out;
  Sample s;
  while (log.next(s)) out.push_back(s);
  return out;
}

/// Time of the log's first Raw row (-1 without one); the gap is cut from kGapStart after it.
TimeNs first_raw_ns(const std::vector<Sample>& log) {
  for (const Sample& s : log)
    if (std::holds_alternative<GnssRawSample>(s)) return sample_time_ns(s);
  return -1;
}
constexpr TimeNs kGapStart = 90 * kNsPerS, kGapLength = 60 * kNsPerS;

struct OutageRun {
  double max_jump_sigma = 0.0;
  double max_jump_m = 0.0;
  double after_gap_mean_err_m = 0.0;  // shown estimate, epochs from the gap end to the log end
  double gap_mean_err_m = 0.0;
  int after_gap_epochs = 0;
  std::vector<ModeChange> changes;
};

/// Replays the log with [gap_from, gap_to) cut (Raw rows; Fix rows too when cut_fix).
OutageRun replay(const std::vector<Sample>& log, EngineMode mode, TimeNs gap_from, TimeNs gap_to, bool cut_fix) {
  NavigatorConfig cfg;
  cfg.mode = mode;
  cfg.nav_paths.push_back(test::shared_data("gnss-mountainview/hour2350.16n"));
  Navigator nav(cfg, 7);
  const geo::LocalFrame truth(kSurveyed);
  OutageRun r;
  bool have_prev = false;
  Estimate prev;
  double sum_after = 0.0, sum_gap = 0.0;
  int n_gap = 0;
  for (const Sample& s : log) {
    const TimeNs t = sample_time_ns(s);
    const bool in_gap = t >= gap_from && t < gap_to;
    if (in_gap && (std::holds_alternative<GnssRawSample>(s) || (cut_fix && std::holds_alternative<FixSample>(s)))) continue;
    nav.feed(s);
    const Estimate e = nav.estimate();
    if (!e.valid() || (have_prev && e.t_ns == prev.t_ns)) continue;
    const Eigen::Vector2d p = truth.to_enu(e.position).p_m.head<2>();
    if (have_prev) {
      const Eigen::Vector2d d = p - truth.to_enu(prev.position).p_m.head<2>();
      const Eigen::Matrix2d c = e.cov_en_m2 + prev.cov_en_m2;
      const double k = std::sqrt(d.dot(c.inverse() * d));
      r.max_jump_sigma = std::max(r.max_jump_sigma, k);
      r.max_jump_m = std::max(r.max_jump_m, d.norm());
    }
    if (e.t_ns >= gap_to) {
      sum_after += p.norm();
      ++r.after_gap_epochs;
    } else if (e.t_ns >= gap_from) {
      sum_gap += p.norm();
      ++n_gap;
    }
    prev = e;
    have_prev = true;
  }
  r.after_gap_mean_err_m = r.after_gap_epochs ? sum_after / r.after_gap_epochs : kNaN;
  r.gap_mean_err_m = n_gap ? sum_gap / n_gap : kNaN;
  r.changes = nav.mode_changes();
  return r;
}

class MountainViewGap : public ::testing::TestWithParam<bool> {};

TEST_P(MountainViewGap, NoShownJumpAbove3SigmaAndAfterTheGapNoWorseThanGnssAlone) {
  const bool cut_fix = GetParam();
  const std::vector<Sample> log = read_log();
  const TimeNs first_raw = first_raw_ns(log);
  ASSERT_GE(first_raw, 0);
  const TimeNs gap_from = first_raw + kGapStart, gap_to = gap_from + kGapLength;
  const OutageRun fused = replay(log, EngineMode::kAuto, gap_from, gap_to, cut_fix);
  const OutageRun gnss = replay(log, EngineMode::kGnss, gap_from, gap_to, cut_fix);
  std::printf("cut_fix=%d fused: max jump %.2f sigma (%.1f m), gap err %.1f m, after-gap err %.2f m (%d epochs); "
              "GNSS alone: max jump %.2f sigma (%.1f m), after-gap err %.2f m\n",
              cut_fix, fused.max_jump_sigma, fused.max_jump_m, fused.gap_mean_err_m, fused.after_gap_mean_err_m,
              fused.after_gap_epochs, gnss.max_jump_sigma, gnss.max_jump_m, gnss.after_gap_mean_err_m);
  for (const ModeChange& c : fused.changes)
    std::printf("  %.1f s %s -> %s: %s\n", static_cast<double>(c.t_ns - first_raw) * 1e-9, to_string(c.from), to_string(c.to),
                c.reason.c_str());
  ASSERT_GT(fused.after_gap_epochs, 30);
  EXPECT_LE(fused.max_jump_sigma, 3.0);
  EXPECT_LE(fused.after_gap_mean_err_m, gnss.after_gap_mean_err_m);
  // the outage and the return are logged with reasons (a log without any sample in the gap
  // tells the Navigator of the outage with its first sample after it)
  bool lost = false, back = false;
  for (const ModeChange& c : fused.changes) {
    if (c.t_ns >= gap_from && c.to == FusionMode::kPdr) lost = c.reason.find("no usable GNSS for 6") != std::string::npos;
    if (lost && c.t_ns >= gap_to - kNsPerS && c.to == FusionMode::kGnss) back = c.reason.find("re-acquired") != std::string::npos;
  }
  if (cut_fix) {
    EXPECT_TRUE(lost) << "the outage is not in the mode log";
    EXPECT_TRUE(back) << "the return of GNSS is not in the mode log";
  }
}

INSTANTIATE_TEST_SUITE_P(RawGapAndRawPlusFixGap, MountainViewGap, ::testing::Values(false, true));

/// The GNSS engine's own estimate, as Navigator::output() lists it (engines.csv, the app's dots).
Estimate gnss_engine(const Navigator& nav) {
  for (const Estimate& e : nav.output(0).engines)
    if (e.engine == EngineKind::kGnss) return e;
  return Estimate{};
}

// When GNSS epochs stop altogether (a tunnel, a jammer) the GNSS engine's newest estimate is that
// of its last epoch: it used to stay "ok" with that epoch's metre-level covariance however long
// the walker walked on (a simulated 1071 s outage: "ok", 2 m semi-major, 870-950 m off). It is
// lost once no epoch came for 3 s, in the engines list and as the shown estimate of the GNSS-only
// mode, and tracking again with the first epoch after the gap. The log's Fix rows go on through
// the gap (the time advances without Raw epochs).
TEST(NavigatorGnssEngineOutput, NoEpochForThreeSecondsIsLostNotOk) {
  const std::vector<Sample> log = read_log();
  const TimeNs first_raw = first_raw_ns(log);
  ASSERT_GE(first_raw, 0);
  const TimeNs gap_from = first_raw + kGapStart, gap_to = gap_from + kGapLength;
  for (const EngineMode mode : {EngineMode::kAuto, EngineMode::kGnss}) {
    NavigatorConfig cfg;
    cfg.mode = mode;
    cfg.nav_paths.push_back(test::shared_data("gnss-mountainview/hour2350.16n"));
    Navigator nav(cfg, 7);
    int ok_before = 0, lost_in_gap = 0, ok_in_gap = 0, ok_after = 0, checked_in_gap = 0;
    std::string gap_reason;
    for (const Sample& s : log) {
      const TimeNs t = sample_time_ns(s);
      if (t >= gap_from && t < gap_to && std::holds_alternative<GnssRawSample>(s)) continue;
      nav.feed(s);
      if (!std::holds_alternative<FixSample>(s)) continue;  // look once a Fix row (1 Hz)
      const Estimate g = gnss_engine(nav);
      if (t >= gap_from - 10 * kNsPerS && t < gap_from) ok_before += g.status == EstimateStatus::kOk;
      if (t >= gap_from + 5 * kNsPerS && t < gap_to) {
        ++checked_in_gap;
        lost_in_gap += g.status == EstimateStatus::kLost;
        ok_in_gap += g.status == EstimateStatus::kOk;
        gap_reason = g.reason;
        EXPECT_TRUE(std::isfinite(g.position.lat_deg())) << "the last epoch's position is kept";
        if (mode == EngineMode::kGnss) EXPECT_FALSE(nav.estimate().valid()) << "GNSS-only shows a stale fix as valid";
      }
      if (t >= gap_to + 10 * kNsPerS && t < gap_to + 20 * kNsPerS) ok_after += g.valid();
    }
    std::printf("mode %s: GNSS engine ok %d of the 10 s before the gap; in the gap (%d looks) lost %d, ok %d (\"%s\"); "
                "valid %d of 10 s after it\n",
                mode == EngineMode::kAuto ? "auto" : "gnss", ok_before, checked_in_gap, lost_in_gap, ok_in_gap,
                gap_reason.c_str(), ok_after);
    EXPECT_GE(ok_before, 8);
    ASSERT_GE(checked_in_gap, 45);
    EXPECT_EQ(lost_in_gap, checked_in_gap);
    EXPECT_EQ(ok_in_gap, 0);
    EXPECT_NE(gap_reason.find("no epoch for"), std::string::npos);
    EXPECT_GE(ok_after, 8);
  }
}

}  // namespace
}  // namespace pdnav::fusion

namespace pdnav::fusion {
namespace {

struct ThinnedRun {
  int epochs = 0, gnss_mode_epochs = 0, degraded_epochs = 0;
  std::int64_t mode_changes = 0;
  double shortest_degraded_s = 1e9;  // shortest stay in "gnss-degraded" before "gnss"
  double mean_err_m = 0.0;
  TimeNs max_lag_ns = 0;  // shown time behind the last Raw row fed, at each Raw epoch's completion
};

/// The Mountain View log thinned: every `keep_every`-th Raw epoch (duty cycling), and at most
/// `max_sats` GPS rows per epoch (a degraded sky); Fix rows dropped (Raw only).
ThinnedRun thinned(int keep_every, int max_sats, double degraded_hold_s = FusionOptions{}.degraded_hold_s) {
  const std::vector<Sample> log = read_log();
  NavigatorConfig cfg;
  cfg.fusion.degraded_hold_s = degraded_hold_s;
  cfg.nav_paths.push_back(test::shared_data("gnss-mountainview/hour2350.16n"));
  Navigator nav(cfg, 3);
  const geo::LocalFrame truth(kSurveyed);
  ThinnedRun r;
  std::int64_t epoch_time = kMissingInt;
  int epoch_index = -1, rows_in_epoch = 0;
  double sum = 0.0;
  TimeNs last_t = -1;
  for (const Sample& s : log) {
    if (std::holds_alternative<FixSample>(s)) continue;
    if (const auto* raw = std::get_if<GnssRawSample>(&s)) {
      if (raw->time_nanos != epoch_time) {
        epoch_time = raw->time_nanos;
        ++epoch_index;
        rows_in_epoch = 0;
      }
      if (epoch_index % keep_every != 0) continue;
      // the log's navigation file is GPS only: count (and keep) GPS rows (CONSTELLATION_GPS = 1)
      if (max_sats < 1000 && (raw->constellation_type != 1 || ++rows_in_epoch > max_sats)) continue;
    }
    nav.feed(s);
    const Estimate e = nav.estimate();
    if (!e.valid() || e.t_ns == last_t) continue;
    last_t = e.t_ns;
    ++r.epochs;
    r.gnss_mode_epochs += e.engine == EngineKind::kGnss ? 1 : 0;
    r.degraded_epochs += e.reason.rfind("fused (gnss-degraded)", 0) == 0 ? 1 : 0;
    sum += truth.to_enu(e.position).p_m.head<2>().norm();
  }
  r.mean_err_m = r.epochs ? sum / r.epochs : kNaN;
  r.mode_changes = nav.output(0).mode_change_count;
  TimeNs entered = -1;
  for (const ModeChange& c : nav.mode_changes()) {
    if (c.to == FusionMode::kGnssDegraded) entered = c.t_ns;
    if (c.from == FusionMode::kGnssDegraded && c.to == FusionMode::kGnss && entered >= 0)
      r.shortest_degraded_s = std::min(r.shortest_degraded_s, ns_to_s(c.t_ns - entered));
  }
  if (r.epochs == 0)
    for (const Estimate& e : nav.output(0).engines) std::printf("  engine %s: %s\n", to_string(e.engine), e.reason.c_str());
  return r;
}

TEST(NavigatorDutyCycledGnss, EpochsEighteenSecondsApartKeepTheGnssMode) {
  const ThinnedRun r = thinned(18, 1000);
  std::printf("duty-cycled (1 epoch in 18): %d shown epochs, %d in a GNSS mode, mean error %.1f m\n", r.epochs,
              r.gnss_mode_epochs, r.mean_err_m);
  ASSERT_GE(r.epochs, 8);
  EXPECT_GE(r.gnss_mode_epochs, r.epochs - 2);  // all but the start
  EXPECT_LT(r.mean_err_m, 15.0);
}

TEST(NavigatorDutyCycledGnss, FewerThanSixUsedSatellitesStillFeedTheFilterAsDegraded) {
  // 6 GPS rows per epoch, of which the engine uses fewer than 6 in most epochs (exclusions)
  const ThinnedRun r = thinned(1, 6);
  std::printf("6 GPS rows: %d shown epochs, %d in a GNSS mode (%d degraded), mean error %.1f m\n", r.epochs,
              r.gnss_mode_epochs, r.degraded_epochs, r.mean_err_m);
  ASSERT_GE(r.epochs, 50);
  EXPECT_GE(r.degraded_epochs, r.epochs / 2);
  EXPECT_LT(r.mean_err_m, 30.0);
}

TEST(NavigatorDutyCycledGnss, ASatelliteCountAtTheThresholdDoesNotFlipTheShownMode) {
  // 8 GPS rows: the used count crosses min_sats_ok (6) now and then. The label holds
  // "gnss-degraded" for degraded_hold_s after the last degraded epoch; without the hold it
  // follows each epoch's count (the demo's simulated session: 45 -> 11 mode changes).
  const ThinnedRun held = thinned(1, 8);
  const ThinnedRun flipping = thinned(1, 8, 0.0);
  std::printf("mode changes: %lld with the %.0f s hold (shortest degraded stay %.0f s), %lld without (%.0f s)\n",
              static_cast<long long>(held.mode_changes), FusionOptions{}.degraded_hold_s, held.shortest_degraded_s,
              static_cast<long long>(flipping.mode_changes), flipping.shortest_degraded_s);
  EXPECT_LT(held.mode_changes, flipping.mode_changes);
  EXPECT_LT(flipping.shortest_degraded_s, FusionOptions{}.degraded_hold_s);
  EXPECT_GE(held.shortest_degraded_s, FusionOptions{}.degraded_hold_s);
  EXPECT_NEAR(held.mean_err_m, flipping.mean_err_m, 0.5);  // the label only: the estimate is the same
}

}  // namespace
}  // namespace pdnav::fusion

namespace pdnav::fusion {
namespace {

/// The contrived disagreement: the static Mountain View log plus synthetic step events
/// walking north (PDR says 1.3 m/s, GNSS says standing), a 60 s Raw + Fix gap cut in. Before
/// the fused estimate the shown position jumped 95 m when GNSS went and 165 m when it came back.
TEST(NavigatorContrivedDisagreement, StepsNorthOnAStaticLogNeverJumpAbove3Sigma) {
  std::vector<Sample> log = read_log();
  TimeNs first_raw = -1, last_t = 0;
  for (const Sample& s : log) {
    if (first_raw < 0 && std::holds_alternative<GnssRawSample>(s)) first_raw = sample_time_ns(s);
    last_t = std::max(last_t, sample_time_ns(s));
  }
  ASSERT_GE(first_raw, 0);
  const Eigen::Quaterniond q(test::chest_facing_north());
  std::vector<Sample> steps;
  for (TimeNs t = first_raw + 20 * kNsPerS; t < last_t; t += 550 * kNsPerMs) {
    for (const Sample& s : test::step_events(t - kNsPerMs, t, q)) steps.push_back(s);
  }
  std::vector<Sample> merged;
  std::merge(log.begin(), log.end(), steps.begin(), steps.end(), std::back_inserter(merged),
             [](const Sample& a, const Sample& b) { return sample_time_ns(a) < sample_time_ns(b); });
  const TimeNs gap_from = first_raw + 90 * kNsPerS, gap_to = gap_from + 60 * kNsPerS;
  const OutageRun fused = replay(merged, EngineMode::kAuto, gap_from, gap_to, /*cut_fix=*/true);
  std::printf("contrived: max shown jump %.2f sigma (%.1f m), mean error in the gap %.1f m, after it %.1f m\n",
              fused.max_jump_sigma, fused.max_jump_m, fused.gap_mean_err_m, fused.after_gap_mean_err_m);
  for (const ModeChange& c : fused.changes)
    std::printf("  %.1f s %s -> %s: %s\n", static_cast<double>(c.t_ns - first_raw) * 1e-9, to_string(c.from), to_string(c.to),
                c.reason.c_str());
  EXPECT_LE(fused.max_jump_sigma, 3.0);
  // GNSS + TDCP say the walker stands: the residual scale state learns that these steps carry no
  // displacement, so the estimate barely walks off in the gap and comes back to GNSS level
  const OutageRun gnss = replay(merged, EngineMode::kGnss, gap_from, gap_to, true);
  std::printf("contrived: GNSS alone after the gap %.1f m\n", gnss.after_gap_mean_err_m);
  EXPECT_LE(fused.after_gap_mean_err_m, 1.5 * gnss.after_gap_mean_err_m);
}

}  // namespace
}  // namespace pdnav::fusion
