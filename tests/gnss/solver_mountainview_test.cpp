// The issue-7 bar on the real Mountain View log (207 s static, GPS nav file, surveyed truth):
// SPP horizontal p50 <= 4.0 m, p95 <= 8.0 m; KF horizontal RMS <= 2.5 m; 1 s TDCP RMS <= 3 cm
// per axis. Also the same log without carrier phase (Doppler fallback).
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/gnss/gnss_engine.h"
#include "pdnav/gnss/solver_metrics.h"
#include "pdnav/io/log_reader.h"
#include "test_data.h"

namespace pdnav::gnss {
namespace {

const geo::Geodetic kTruth = geo::Geodetic::from_deg(37.422578, -122.081678, -28.0);

struct LogRun {
  std::vector<EpochSolution> sols;
  std::map<std::string, std::int64_t> excluded;
  Estimate last;
};

LogRun run_mountainview(bool strip_adr, GnssOptions options = {}) {
  auto store = std::make_shared<EphemerisStore>();
  store->load_rinex_nav(test::shared_data("gnss-mountainview/hour2350.16n"));
  GnssEngine engine(options, store, 7);
  io::LogReader reader(test::shared_data("gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt"));
  Sample s;
  while (reader.next(s)) {
    if (auto* raw = std::get_if<GnssRawSample>(&s)) {
      if (strip_adr) {
        raw->accumulated_delta_range_state = 0;
        raw->accumulated_delta_range_m = kNaN;
      }
      engine.feed(*raw);
    }
  }
  engine.flush();
  LogRun r;
  r.sols = engine.take_solutions();
  r.excluded = engine.exclusions();
  r.last = engine.estimate();
  return r;
}

void print(const StaticAccuracy& a) {
  std::printf("SPP p50 %.2f p95 %.2f rms %.2f (n=%d) | KF rms %.2f p50 %.2f p95 %.2f (n=%d) | "
              "TDCP cm %.2f %.2f %.2f (n=%d) | Doppler cm %.2f %.2f %.2f (n=%d)\n",
              a.spp_p50_h_m, a.spp_p95_h_m, a.spp_rms_h_m, a.spp_epochs, a.kf_rms_h_m, a.kf_p50_h_m, a.kf_p95_h_m,
              a.kf_epochs, a.tdcp_rms_enu_m.x() * 100, a.tdcp_rms_enu_m.y() * 100, a.tdcp_rms_enu_m.z() * 100,
              a.tdcp_epochs, a.doppler_rms_enu_m.x() * 100, a.doppler_rms_enu_m.y() * 100,
              a.doppler_rms_enu_m.z() * 100, a.doppler_epochs);
}

TEST(SolverMountainView, MeetsTheIssueBar) {
  const LogRun r = run_mountainview(false);
  const StaticAccuracy a = evaluate_static(r.sols, kTruth);
  print(a);
  for (const auto& [why, n] : r.excluded) std::printf("  %-70s %lld\n", why.c_str(), static_cast<long long>(n));
  ASSERT_GE(r.sols.size(), 200u);          // 207 s at 1 Hz
  EXPECT_GE(a.spp_epochs, 190);
  EXPECT_LE(a.spp_p50_h_m, 4.0);
  EXPECT_LE(a.spp_p95_h_m, 8.0);
  EXPECT_LE(a.kf_rms_h_m, 2.5);
  EXPECT_GE(a.tdcp_epochs, 150);
  EXPECT_LE(a.tdcp_rms_enu_m.maxCoeff(), 0.03);
  EXPECT_TRUE(r.last.valid());
  EXPECT_LT(horizontal_distance_m(r.last.position, kTruth), 5.0);
  for (const auto& s : r.sols) {
    ASSERT_TRUE(s.kf.p_m.allFinite());
    ASSERT_TRUE(s.kf_cov_enu.allFinite());
  }
}

// The code noise model is learned on raw code; the fix uses carrier-smoothed code. Weighted as
// raw code, the SPP's stated sigma on this static phone is ~4x the realised error (0.25 sigma
// per axis); with what smoothing leaves of each code's white (C/N0) noise
// (GnssOptions::smoothed_code_white_noise, the default) it is 0.59 (the elevation term, learned
// with the GSDC car's multipath, stays pessimistic for this open-sky site). Either way the fit's
// a-posteriori variance factor chi2/dof sees it: sqrt(mean chi2/dof) and the realised per-axis
// error in stated sigmas agree within 40 % (0.33 / 0.25 raw, 0.74 / 0.59 smoothed when written).
struct StatedSigmaCheck {
  double realised = 0.0, predicted = 0.0;
};

StatedSigmaCheck stated_sigma_check(bool smoothed_white_noise) {
  GnssOptions o;
  o.smoothed_code_white_noise = smoothed_white_noise;
  const LogRun r = run_mountainview(false, o);
  const geo::LocalFrame frame(kTruth);
  double sum_d2 = 0.0, sum_vf = 0.0;
  int n = 0, n_vf = 0;
  for (const auto& s : r.sols) {
    if (!s.spp_ok) continue;
    const Eigen::Vector3d e = frame.to_enu(s.spp).p_m;
    sum_d2 += e.x() * e.x() / s.spp_cov_enu(0, 0) + e.y() * e.y() / s.spp_cov_enu(1, 1);
    ++n;
    if (std::isfinite(s.spp_variance_factor)) { sum_vf += s.spp_variance_factor; ++n_vf; }
  }
  EXPECT_GE(n, 190);
  EXPECT_GE(n_vf, 190);
  StatedSigmaCheck c;
  c.realised = std::sqrt(sum_d2 / (2.0 * std::max(n, 1)));  // per-axis RMS error in stated sigmas
  c.predicted = std::sqrt(sum_vf / std::max(n_vf, 1));
  std::printf("smoothed white noise %d: realised %.3f predicted %.3f sigma\n", smoothed_white_noise ? 1 : 0,
              c.realised, c.predicted);
  return c;
}

TEST(SolverMountainView, TheSmoothedCodesStatedSigmaIsNearerItsErrorAndTheVarianceFactorSeesTheRest) {
  const StatedSigmaCheck raw = stated_sigma_check(false), smoothed = stated_sigma_check(true);
  EXPECT_LT(raw.realised, 0.5);            // weighted as raw code: pessimistic
  EXPECT_GT(smoothed.realised, 2.0 * raw.realised);
  EXPECT_LT(smoothed.realised, 1.0);
  for (const StatedSigmaCheck& c : {raw, smoothed}) {
    EXPECT_GT(c.predicted / c.realised, 1.0 / 1.4);
    EXPECT_LT(c.predicted / c.realised, 1.4);
  }
}

// GnssOptions::fix_bias_sigma_h_m: the fixes' common bias is a consider variance on the KF's
// reported horizontal covariance; the estimate itself does not move. The bias is there in this
// log: the SPP's mean east error over its 200 s is about 1 m (1.04 m; the default is the RMS
// of such per-log means over this log and the GSDC drive, docs/gnss.md).
TEST(SolverMountainView, TheFixBiasIsAConsiderVarianceOnTheReportedCovarianceAlone) {
  GnssOptions without;
  without.fix_bias_sigma_h_m = 0.0;
  const LogRun a = run_mountainview(false, without);
  const LogRun b = run_mountainview(false);  // the default, 1.0 m
  ASSERT_EQ(a.sols.size(), b.sols.size());
  int compared = 0;
  double east_sum = 0.0;
  int spp = 0;
  const geo::LocalFrame frame(kTruth);
  for (std::size_t i = 0; i < a.sols.size(); ++i) {
    const EpochSolution &x = a.sols[i], &y = b.sols[i];
    if (x.spp_ok) east_sum += frame.to_enu(x.spp).e_m(), ++spp;
    ASSERT_EQ(x.kf_ok, y.kf_ok);
    if (!x.kf_ok) continue;
    ++compared;
    EXPECT_EQ(x.kf.p_m, y.kf.p_m);
    const Eigen::Matrix3d d = y.kf_cov_enu - x.kf_cov_enu;
    EXPECT_NEAR(d(0, 0), 1.0, 1e-9);
    EXPECT_NEAR(d(1, 1), 1.0, 1e-9);
    EXPECT_NEAR(d(2, 2), 0.0, 1e-12);
    EXPECT_NEAR(d(0, 1), 0.0, 1e-12);
  }
  EXPECT_GT(compared, 150);
  ASSERT_GT(spp, 150);
  EXPECT_GT(east_sum / spp, 0.5);
  EXPECT_LT(east_sum / spp, 1.5);
}

TEST(SolverMountainView, DopplerFallbackWithoutCarrierPhase) {
  const LogRun r = run_mountainview(true);
  const StaticAccuracy a = evaluate_static(r.sols, kTruth);
  print(a);
  EXPECT_EQ(a.tdcp_epochs, 0);
  EXPECT_GE(a.doppler_epochs, 150);
  // Doppler velocity noise of a phone: a few cm/s per axis; the static displacement stays small
  EXPECT_LE(a.doppler_rms_enu_m.maxCoeff(), 0.30);
  EXPECT_LE(a.spp_p50_h_m, 4.0);
  EXPECT_LE(a.kf_rms_h_m, 4.0);
}

}  // namespace
}  // namespace pdnav::gnss
