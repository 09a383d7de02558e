// Phone-session simulator on a synthetic DEM and street grid with the real GSDC 2021 GPS
// broadcast ephemeris: structure of the stream, GNSS Raw rows that the project's own GNSS
// engine solves near the truth, the scripted outage, terrain masking.
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/geo/frames.h"
#include "pdnav/gnss/gnss_engine.h"
#include "pdnav/phonesim/phone_session.h"
#include "synthetic_dem.h"
#include "test_data.h"

namespace pdnav::phonesim {
namespace {

/// Streets every `spacing` m over +-half_m around the DEM origin (same geodetic origin).
route::WalkGraph street_grid(double half_m, double spacing) {
  std::vector<Eigen::Vector2d> v;
  const int n = static_cast<int>(2 * half_m / spacing) + 1;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) v.emplace_back(-half_m + i * spacing, -half_m + j * spacing);
  std::vector<route::WalkGraph::Edge> edges;
  auto id = [n](int i, int j) { return static_cast<std::int32_t>(j * n + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      route::WalkGraph::Edge e;
      e.highway = (i + j) % 3 == 0 ? "residential" : "path";
      if (i + 1 < n) { e.from = id(i, j); e.to = id(i + 1, j); edges.push_back(e); }
      if (j + 1 < n) { e.from = id(i, j); e.to = id(i, j + 1); edges.push_back(e); }
    }
  return route::WalkGraph::build(geo::Geodetic::from_deg(42.5, 1.5, 0.0), v, edges);
}

const gnss::EphemerisStore& gsdc_ephemeris() {
  static const gnss::EphemerisStore eph = [] {
    gnss::EphemerisStore e;
    e.load_rinex_nav(test::shared_data("gnss-gsdc2021-pixel5/hour1180.21n"));
    return e;
  }();
  return eph;
}

SessionOptions short_session() {
  SessionOptions o;
  o.lead_s = 150.0;
  o.outage_min_s = 90.0;
  o.outage_max_s = 100.0;
  o.tail_s = 60.0;
  o.degraded_segments = 1;
  return o;
}

/// short_session() in the open: no degraded segment, no forest.
SessionOptions open_sky_session() {
  SessionOptions o = short_session();
  o.degraded_segments = 0;
  o.dem_error.forest_fraction = 0.0;
  return o;
}

TEST(PhoneSession, StreamHasEveryPhoneLineTypeInTimeOrderAndAnOutage) {
  const terrain::Dem dem = test::synthetic_dem(534, 534, 30.0, test::hills);
  const route::WalkGraph graph = street_grid(5000.0, 200.0);
  const PhoneSession s = simulate_session(dem, graph, gsdc_ephemeris(), short_session(), 4);
  std::map<std::size_t, std::size_t> by_type;
  TimeNs last = 0;
  std::size_t raw_in_outage = 0, fix_in_outage = 0;
  for (const Sample& x : s.samples) {
    ++by_type[x.index()];
    const TimeNs t = sample_time_ns(x);
    EXPECT_GE(t, last);
    last = t;
    const bool in_outage = t >= s.outage_start_ns && t < s.outage_end_ns;
    if (in_outage && std::holds_alternative<GnssRawSample>(x)) ++raw_in_outage;
    if (in_outage && std::holds_alternative<FixSample>(x)) ++fix_in_outage;
  }
  for (const Sample proto : {Sample(AccelSample{}), Sample(GyroSample{}), Sample(RotationVectorSample{}),
                             Sample(PressureSample{}), Sample(StepDetectorSample{}), Sample(GnssRawSample{}),
                             Sample(FixSample{}), Sample(TruthSample{}), Sample(MetaSample{})})
    EXPECT_GT(by_type[proto.index()], 0u) << "line type index " << proto.index();
  EXPECT_EQ(raw_in_outage, 0u);
  EXPECT_EQ(fix_in_outage, 0u);
  EXPECT_NEAR(ns_to_s(s.outage_end_ns - s.outage_start_ns), 95.0, 5.1);
  EXPECT_EQ(by_type[Sample(TruthSample{}).index()], s.truth.size());
  EXPECT_EQ(static_cast<std::int64_t>(s.truth.size()), s.stats.steps);
  // ~1.3 m/s walking, ~1.8 steps/s over the whole session.
  EXPECT_GT(s.stats.length_m / s.stats.duration_s, 0.9);
  EXPECT_LT(s.stats.length_m / s.stats.duration_s, 1.8);
  EXPECT_GE(s.stats.mean_sats_tracked, 6.0);
  // Reproducible; another seed is another walk.
  const PhoneSession again = simulate_session(dem, graph, gsdc_ephemeris(), short_session(), 4);
  ASSERT_EQ(again.truth.size(), s.truth.size());
  EXPECT_EQ(again.truth.back().en_m, s.truth.back().en_m);
  const PhoneSession other = simulate_session(dem, graph, gsdc_ephemeris(), short_session(), 5);
  EXPECT_NE(other.truth.front().en_m, s.truth.front().en_m);
}

/// Horizontal errors (east, north) of the GNSS engine's SPP fixes against the session's truth
/// (interpolated between its steps).
std::vector<Eigen::Vector2d> spp_errors_en(const PhoneSession& s, const terrain::Dem& dem) {
  gnss::GnssEngine engine(gnss::GnssOptions{}, std::make_shared<gnss::EphemerisStore>(gsdc_ephemeris()), 1);
  for (const Sample& x : s.samples)
    if (const auto* r = std::get_if<GnssRawSample>(&x)) engine.feed(*r);
  engine.flush();
  std::vector<Eigen::Vector2d> err;
  for (const gnss::EpochSolution& sol : engine.take_solutions()) {
    if (!sol.spp_ok) continue;
    auto it = std::lower_bound(s.truth.begin(), s.truth.end(), sol.t_ns,
                               [](const TruthPoint& p, TimeNs t) { return p.t_ns < t; });
    if (it == s.truth.begin() || it == s.truth.end()) continue;
    const TruthPoint& b = *it;
    const TruthPoint& a = *(it - 1);
    const double w = ns_to_s(sol.t_ns - a.t_ns) / ns_to_s(b.t_ns - a.t_ns);
    err.push_back(dem.to_local(geo::to_geodetic(sol.spp)) - (a.en_m + w * (b.en_m - a.en_m)));
  }
  return err;
}

// The Raw rows are real Android measurements of the real broadcast sky: the project's GNSS
// engine (which knows nothing of the simulator) solves them near the truth in open sky.
TEST(PhoneSession, GnssEngineSolvesTheRawRowsNearTheTruth) {
  const terrain::Dem dem = test::synthetic_dem(534, 534, 30.0, [](double, double) { return 1200.0; });
  const route::WalkGraph graph = street_grid(5000.0, 200.0);
  const PhoneSession s = simulate_session(dem, graph, gsdc_ephemeris(), open_sky_session(), 11);
  std::vector<double> err;
  for (const Eigen::Vector2d& e : spp_errors_en(s, dem)) err.push_back(e.norm());
  ASSERT_GT(err.size(), 150u);
  std::sort(err.begin(), err.end());
  const double p50 = err[err.size() / 2], p95 = err[err.size() * 95 / 100];
  EXPECT_LT(p50, 6.0);
  EXPECT_GT(p50, 0.3);  // the world's errors are there (multipath, iono model error, noise)
  EXPECT_LT(p95, 20.0);
}

/// Mean of spp_errors_en; n = how many fixes.
Eigen::Vector2d mean_spp_error(const PhoneSession& s, const terrain::Dem& dem, std::size_t* n) {
  const std::vector<Eigen::Vector2d> err = spp_errors_en(s, dem);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& e : err) sum += e;
  *n = err.size();
  return err.empty() ? sum : Eigen::Vector2d(sum / static_cast<double>(err.size()));
}

// The ionosphere's horizontal gradient (a delay growing toward one side of the sky, which the
// Klobuchar-shaped error cannot give) moves the fixes away from that side for the whole session;
// the session's other draws are the same with and without it (its own random stream).
TEST(PhoneSession, TheIonosphericGradientBiasesTheFixesAwayFromIt) {
  const terrain::Dem dem = test::synthetic_dem(534, 534, 30.0, [](double, double) { return 1200.0; });
  const route::WalkGraph graph = street_grid(5000.0, 200.0);
  SessionOptions o = open_sky_session();
  o.gnss.iono_gradient_sd_m_per_km = 0.0;
  const PhoneSession flat = simulate_session(dem, graph, gsdc_ephemeris(), o, 11);
  o.gnss.iono_gradient_sd_m_per_km = 3e-3;
  const PhoneSession tilted = simulate_session(dem, graph, gsdc_ephemeris(), o, 11);
  ASSERT_EQ(flat.truth.size(), tilted.truth.size());
  EXPECT_EQ(flat.truth.back().en_m, tilted.truth.back().en_m);
  EXPECT_EQ(flat.stats.iono_gradient_m_per_km, Eigen::Vector2d::Zero());
  const Eigen::Vector2d g = tilted.stats.iono_gradient_m_per_km;
  ASSERT_GT(g.norm(), 1e-3);
  std::size_t n0 = 0, n1 = 0;
  const Eigen::Vector2d shift = mean_spp_error(tilted, dem, &n1) - mean_spp_error(flat, dem, &n0);
  ASSERT_GT(n0, 150u);
  ASSERT_GT(n1, 150u);
  // about 1 m of horizontal bias per mm/km (pierce points 200-1000 km out, obliquity 1-2.5,
  // partly taken up by the clock and height): 0.9 m here
  EXPECT_GT(shift.norm(), 0.5 * 1e3 * g.norm()) << shift.transpose() << " for " << g.transpose();
  EXPECT_LT(shift.norm(), 5.0 * 1e3 * g.norm()) << shift.transpose() << " for " << g.transpose();
  EXPECT_LT(shift.normalized().dot(g.normalized()), -0.8) << shift.transpose() << " for " << g.transpose();
}

// A deep, narrow canyon hides most of the sky; the open plateau does not.
TEST(PhoneSession, TerrainMasksSatellitesInACanyon) {
  const route::WalkGraph graph = street_grid(5000.0, 200.0);
  SessionOptions o = short_session();
  o.degraded_segments = 0;
  o.dem_error.forest_fraction = 0.0;
  const terrain::Dem flat = test::synthetic_dem(534, 534, 30.0, [](double, double) { return 1200.0; });
  // Ridges every 400 m, 500 m high: the streets run in trenches.
  const terrain::Dem canyon = test::synthetic_dem(534, 534, 30.0, [](double e, double n) {
    const double de = std::abs(std::remainder(e, 200.0)), dn = std::abs(std::remainder(n, 200.0));
    return 1200.0 + 500.0 * std::min(1.0, std::max(0.0, (std::min(de, dn) - 20.0) / 60.0));
  });
  const PhoneSession a = simulate_session(flat, graph, gsdc_ephemeris(), o, 21);
  const PhoneSession b = simulate_session(canyon, graph, gsdc_ephemeris(), o, 21);
  EXPECT_EQ(a.stats.masked_by_terrain, 0);
  EXPECT_GT(b.stats.masked_by_terrain, 1000);
  EXPECT_LT(b.stats.mean_sats_tracked, 0.7 * a.stats.mean_sats_tracked);
}

TEST(PhoneSession, ClearErrors) {
  const terrain::Dem dem = test::synthetic_dem(534, 534, 30.0, test::hills);
  const route::WalkGraph far_graph = [] {
    std::vector<Eigen::Vector2d> v = {{0, 0}, {100, 0}};
    route::WalkGraph::Edge e;
    e.from = 0;
    e.to = 1;
    return route::WalkGraph::build(geo::Geodetic::from_deg(45.0, 5.0, 0.0), v, {e});
  }();
  EXPECT_THROW(simulate_session(dem, far_graph, gsdc_ephemeris(), short_session(), 1), std::runtime_error);
  const gnss::EphemerisStore empty;
  EXPECT_THROW(simulate_session(dem, street_grid(5000.0, 200.0), empty, short_session(), 1), std::runtime_error);
  SessionOptions bad = short_session();
  bad.outage_max_s = 10.0;
  EXPECT_THROW(simulate_session(dem, street_grid(5000.0, 200.0), gsdc_ephemeris(), bad, 1), std::invalid_argument);
}

}  // namespace
}  // namespace pdnav::phonesim
