// Robustness of the PDR, route and GNSS engines through their public faces (issue 9):
// accelerometer rates from 1 to 500 Hz, heading flipping by 180 degrees every step, garbage
// events, GNSS epochs with fewer than 4 satellites and rows with NaN / missing fields.
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/gnss_engine.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/pdr/pdr.h"
#include "pdnav/route/route_engine.h"
#include "pdnav/route/walk_graph.h"
#include "robustness_support.h"
#include "test_data.h"

namespace pdnav::reliability {
namespace {

// ---------------------------------------------------------------------------------------------
// PDR: sensor rates
// ---------------------------------------------------------------------------------------------

/// Steps the PDR engine counts on 60 s of simulated walking (1.8 Hz -> 108 steps between
/// 3 s and 63 s of a 66 s trace) at an accelerometer (and gyro) rate of `rate_hz`.
std::int64_t pdr_steps_at(double rate_hz, pdr::Pdr& pdr) {
  const AccelTrace tr = walking_accel(rate_hz, 66.0, 3.0, 63.0, 1.8, 42);
  for (std::size_t i = 0; i < tr.t_ns.size(); ++i) {
    AccelSample a;
    a.t_ns = tr.t_ns[i];
    a.acc_mps2 = tr.acc_mps2[i];
    pdr.feed(a);
    GyroSample g;
    g.t_ns = tr.t_ns[i] + 1;
    g.rate_radps = Eigen::Vector3d(0.0, 0.01, 0.0);
    pdr.feed(g);
  }
  for (const PdrStep& s : pdr.take_steps()) {
    EXPECT_TRUE(std::isfinite(s.length_m) && s.length_m > 0.0) << rate_hz << " Hz: length " << s.length_m;
    EXPECT_TRUE(std::isfinite(s.heading_rad)) << rate_hz << " Hz";
  }
  EXPECT_TRUE(std::isfinite(pdr.heading_rad())) << rate_hz << " Hz";
  return pdr.step_count();
}

TEST(PdrRates, CountsStepsWithin5PercentFrom50To500Hz) {
  constexpr std::int64_t kTruth = 108;
  for (double rate : {50.0, 100.0, 200.0, 500.0}) {
    pdr::Pdr pdr;
    const std::int64_t n = pdr_steps_at(rate, pdr);
    EXPECT_NEAR(static_cast<double>(n), static_cast<double>(kTruth), 0.05 * kTruth) << rate << " Hz";
    EXPECT_EQ(pdr.counters().total_skipped(), 0) << rate << " Hz";
  }
}

TEST(PdrRates, LowRatesDoNotCrashOrInventSteps) {
  for (double rate : {1.0, 10.0}) {
    pdr::Pdr pdr;
    const std::int64_t n = pdr_steps_at(rate, pdr);
    // below the Nyquist rate of the gait nothing sensible can be counted, but never more
    // steps than were walked, and nothing non-finite
    EXPECT_LE(n, 113) << rate << " Hz";
    EXPECT_GE(n, 0) << rate << " Hz";
  }
}

TEST(PdrRates, GarbageSamplesAreCountedNotPropagated) {
  pdr::Pdr pdr;
  const double inf = std::numeric_limits<double>::infinity();
  TimeNs t = kNsPerS;
  for (double b : {kNaN, inf, -inf}) {
    AccelSample a;
    a.t_ns = (t += 10'000'000);
    a.acc_mps2 = Eigen::Vector3d(b, 9.8, 0.0);
    pdr.feed(a);
    GyroSample g;
    g.t_ns = t + 1;
    g.rate_radps = Eigen::Vector3d(0.0, b, 0.0);
    pdr.feed(g);
    RotationVectorSample r;
    r.t_ns = t + 2;
    r.quat_xyzw = Eigen::Vector4d(b, 0.0, 0.0, 1.0);
    pdr.feed(r);
    MagSample m;
    m.t_ns = t + 3;
    m.field_ut = Eigen::Vector3d(b, 20.0, -40.0);
    pdr.feed(m);
  }
  AccelSample back;  // backwards and duplicate times
  back.t_ns = kNsPerS;
  back.acc_mps2 = Eigen::Vector3d(0.0, 9.8, 0.0);
  pdr.feed(back);
  pdr.feed(back);
  EXPECT_GE(pdr.counters().accel.non_finite, 3);
  EXPECT_GE(pdr.counters().accel.backwards_time + pdr.counters().accel.duplicate_time, 1);
  EXPECT_TRUE(std::isfinite(pdr.heading_rad()));
  EXPECT_TRUE(std::isfinite(pdr.heading_sigma_rad()));
  // and it still counts a walk afterwards
  const std::int64_t n = pdr_steps_at(100.0, pdr);
  EXPECT_NEAR(static_cast<double>(n), 108.0, 6.0);
}

// ---------------------------------------------------------------------------------------------
// Route engine
// ---------------------------------------------------------------------------------------------

/// A 6 x 6 street grid, 60 m blocks, centred on the origin.
std::shared_ptr<const route::WalkGraph> grid_graph() {
  std::vector<Eigen::Vector2d> v;
  std::vector<route::WalkGraph::Edge> edges;
  constexpr int n = 6;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) v.emplace_back(-150.0 + 60.0 * i, -150.0 + 60.0 * j);
  auto add = [&](int a, int b) {
    route::WalkGraph::Edge e;
    e.from = a;
    e.to = b;
    e.highway = "footway";
    edges.push_back(e);
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (i + 1 < n) add(j * n + i, j * n + i + 1);
      if (j + 1 < n) add(j * n + i, (j + 1) * n + i);
    }
  return std::make_shared<const route::WalkGraph>(
      route::WalkGraph::build(geo::Geodetic::from_deg(kLat0, kLon0, 0.0), std::move(v), std::move(edges)));
}

PositionFix fix_at(const route::WalkGraph& g, double e_m, double n_m, TimeNs t_ns, double sigma_m) {
  const geo::Geodetic p = g.frame().to_geodetic(geo::Enu(e_m, n_m, 0.0));
  PositionFix f;
  f.t_ns = t_ns;
  f.lat_deg = p.lat_deg();
  f.lon_deg = p.lon_deg();
  f.h_m = 0.0;
  f.horizontal_sigma_m = sigma_m;
  return f;
}

TEST(RouteRobustness, HeadingFlipping180DegreesEveryStepStaysBoundedAndSane) {
  const auto graph = grid_graph();
  route::RouteEngine engine({}, graph, 1);
  TimeNs t = kNsPerS;
  engine.feed(fix_at(*graph, -30.0, -30.0, t, 8.0));  // on the street between two junctions
  for (int i = 0; i < 300; ++i) {
    t += 550'000'000;
    PdrStep s;
    s.t_ns = t;
    s.length_m = 0.7;
    s.heading_rad = i % 2 == 0 ? kPi / 2 : 3 * kPi / 2;
    s.heading_sigma_rad = 0.1;
    s.length_sigma_m = 0.05;
    engine.feed(s);
    PdrTurn turn;
    turn.start_ns = t - 400'000'000;
    turn.t_ns = t;
    turn.angle_rad = i % 2 == 0 ? kPi : -kPi;
    engine.feed(turn);
    ASSERT_TRUE(sane(engine.estimate())) << "step " << i;
    ASSERT_LE(engine.route_count(), engine.options().max_routes) << "step " << i;
  }
  // the walker never left the start (+- 0.7 m): any estimate must stay in that block
  const Estimate e = engine.estimate();
  if (e.valid()) {
    EXPECT_LT((e.en_m - Eigen::Vector2d(-30.0, -30.0)).norm(), 60.0) << e.en_m.transpose();
  }
}

TEST(RouteRobustness, GarbageEventsNeverProduceNaN) {
  const auto graph = grid_graph();
  route::RouteEngine engine({}, graph, 2);
  const double inf = std::numeric_limits<double>::infinity();
  TimeNs t = kNsPerS;
  engine.feed(fix_at(*graph, 30.0, -150.0, t, 5.0));
  for (double b : {kNaN, inf, -inf, -5.0, 0.0, 1e12}) {
    t += kNsPerS;
    PositionFix f = fix_at(*graph, 30.0, -150.0, t, 5.0);
    f.lat_deg = std::isfinite(b) ? f.lat_deg : b;
    f.horizontal_sigma_m = b;
    engine.feed(f);
    ASSERT_TRUE(sane(engine.estimate())) << "fix " << b;
    PdrStep s;
    s.t_ns = t + 1;
    s.length_m = b;
    s.heading_rad = b;
    s.heading_sigma_rad = b;
    engine.feed(s);
    ASSERT_TRUE(sane(engine.estimate())) << "step " << b;
    PdrTurn turn;
    turn.t_ns = t + 2;
    turn.start_ns = t - 2 * kNsPerS;
    turn.angle_rad = b;
    engine.feed(turn);
    ASSERT_TRUE(sane(engine.estimate())) << "turn " << b;
    ASSERT_LE(engine.route_count(), engine.options().max_routes);
  }
}

// ---------------------------------------------------------------------------------------------
// GNSS engine
// ---------------------------------------------------------------------------------------------

/// The real Mountain View Raw rows (GnssLogger 1.4, 207 s static) and its GPS ephemeris.
struct MountainView {
  std::vector<GnssRawSample> raw;
  std::shared_ptr<gnss::EphemerisStore> eph = std::make_shared<gnss::EphemerisStore>();
};

const MountainView& mountain_view() {
  static const MountainView mv = [] {
    MountainView m;
    io::LogReader reader(test::shared_data("gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt"));
    for (Sample s; reader.next(s);)
      if (const auto* r = std::get_if<GnssRawSample>(&s)) m.raw.push_back(*r);
    m.eph->load_rinex_nav(test::shared_data("gnss-mountainview/hour2350.16n"));
    return m;
  }();
  return mv;
}

constexpr double kTruthLat = 37.422578, kTruthLon = -122.081678, kTruthH = -28.0;  // surveyed site

/// Feeds rows (already filtered/mangled) and returns the engine's epoch solutions.
std::vector<gnss::EpochSolution> run_gnss(gnss::GnssEngine& engine, const std::vector<GnssRawSample>& rows) {
  std::vector<gnss::EpochSolution> out;
  for (const auto& r : rows) {
    engine.feed(r);
    EXPECT_TRUE(sane(engine.estimate()));
    for (auto& s : engine.take_solutions()) out.push_back(std::move(s));
  }
  engine.flush();
  for (auto& s : engine.take_solutions()) out.push_back(std::move(s));
  return out;
}

TEST(GnssRobustness, ControlAllGpsRowsGiveFixes) {
  const auto& mv = mountain_view();
  ASSERT_GT(mv.raw.size(), 1000u);
  std::vector<GnssRawSample> gps;
  for (const auto& r : mv.raw)
    if (r.constellation_type == 1) gps.push_back(r);
  gnss::GnssEngine engine({}, mv.eph, 1);
  const auto sols = run_gnss(engine, gps);
  int ok = 0;
  for (const auto& s : sols) ok += s.spp_ok ? 1 : 0;
  EXPECT_GT(ok, 100) << "of " << sols.size() << " epochs";
  const Estimate e = engine.estimate();
  ASSERT_TRUE(e.valid());
  const double d = geo::horizontal_distance_m(geo::Geodetic::from_deg(kTruthLat, kTruthLon, kTruthH), e.position);
  EXPECT_LT(d, 50.0);
}

TEST(GnssRobustness, FewerThanFourSatellitesNeverGiveAFix) {
  const auto& mv = mountain_view();
  std::vector<GnssRawSample> three;
  std::map<std::int64_t, int> per_epoch;
  for (const auto& r : mv.raw)
    if (r.constellation_type == 1 && per_epoch[r.time_nanos]++ < 3) three.push_back(r);
  ASSERT_GT(three.size(), 300u);
  gnss::GnssEngine engine({}, mv.eph, 2);
  const auto sols = run_gnss(engine, three);
  EXPECT_GT(sols.size(), 100u);
  for (const auto& s : sols) {
    ASSERT_FALSE(s.spp_ok) << "SPP with " << s.sats_used << " satellites at t=" << s.t_ns;
    ASSERT_LE(s.sats_used, 3);
  }
  EXPECT_NE(engine.estimate().status, EstimateStatus::kOk);
}

TEST(GnssRobustness, NaNAndMissingFieldsAreExcludedNotPropagated) {
  const auto& mv = mountain_view();
  std::vector<GnssRawSample> rows;
  int i = 0;
  for (GnssRawSample r : mv.raw) {
    if (r.constellation_type != 1) continue;
    switch (i++ % 7) {  // mangle one field in most rows, keep some rows clean
      case 0: r.cn0_dbhz = kNaN; break;
      case 1: r.received_sv_time_nanos = kMissingInt; break;
      case 2: r.full_bias_nanos = kMissingInt; break;
      case 3: r.bias_nanos = kNaN; r.time_offset_nanos = kNaN; break;
      case 4: r.pseudorange_rate_mps = std::numeric_limits<double>::infinity(); r.accumulated_delta_range_m = kNaN; break;
      default: break;
    }
    rows.push_back(r);
  }
  GnssRawSample all_missing;  // a row with nothing but a time
  all_missing.t_ns = rows.back().t_ns + kNsPerS;
  rows.push_back(all_missing);
  gnss::GnssEngine engine({}, mv.eph, 3);
  const auto sols = run_gnss(engine, rows);
  EXPECT_FALSE(engine.exclusions().empty());
  for (const auto& s : sols) {
    ASSERT_TRUE(!s.spp_ok || s.spp.p_m.allFinite()) << "t=" << s.t_ns;
    ASSERT_TRUE(!s.kf_ok || (s.kf.p_m.allFinite() && s.kf_cov_enu.allFinite())) << "t=" << s.t_ns;
  }
}

}  // namespace
}  // namespace pdnav::reliability
