// Robustness of the whole core through fusion::Navigator (issue 9): 10 hours of simulated
// walking at realistic sensor rates (no NaN, covariance finite and positive, heap flat, step
// count right), accelerometer rates 1..500 Hz, heading flipping by 180 degrees every step,
// a DEM that is void everywhere, and garbage samples of every type.
#include <cstddef>
#include <malloc.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "pdnav/fusion/navigator.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/terrain/dem.h"
#include "robustness_support.h"
#include "test_data.h"

#if defined(__SANITIZE_ADDRESS__)
#define PDNAV_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PDNAV_ASAN 1
#endif
#endif
#ifdef PDNAV_ASAN
// From the sanitizer runtime (GCC's libasan and clang's); GCC ships no header for it.
extern "C" std::size_t __sanitizer_get_current_allocated_bytes();
#endif

namespace pdnav::reliability {
namespace {

/// Bytes of heap in use now (allocator statistics; ASan's own when sanitized).
std::size_t heap_in_use_bytes() {
#ifdef PDNAV_ASAN
  return __sanitizer_get_current_allocated_bytes();
#else
  return mallinfo2().uordblks;
#endif
}

/// Resident set size in bytes (/proc/self/statm), for the record.
std::size_t rss_bytes() {
  std::ifstream f("/proc/self/statm");
  std::size_t pages = 0, resident = 0;
  f >> pages >> resident;
  return resident * 4096;
}

/// Rotation vector (phone -> ENU, x y z w) of a chest-mounted phone, camera facing the
/// walking direction `heading_rad` (clockwise from north): phone +Y up, phone -Z forward.
Eigen::Vector4d chest_quaternion(double heading_rad) {
  const double s = std::sin(heading_rad), c = std::cos(heading_rad);
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(c, -s, 0.0);   // phone +X (right)
  r.col(1) = Eigen::Vector3d(0.0, 0.0, 1.0);  // phone +Y (top) up
  r.col(2) = Eigen::Vector3d(-s, -c, 0.0);  // phone +Z (screen) backwards
  const Eigen::Quaterniond q(r);
  return {q.x(), q.y(), q.z(), q.w()};
}

/// Streams a simulated walker into a Navigator: accelerometer and gyroscope at `imu_hz`,
/// rotation vector at 10 Hz, barometer at 1 Hz (true altitude on the hills), walking at
/// 1.8 steps/s along `heading(t)`.
class NavigatorWalk {
 public:
  NavigatorWalk(fusion::Navigator& nav, double imu_hz, std::uint64_t seed) : nav_(nav), imu_hz_(imu_hz), rng_(seed) {}

  /// Simulates [t_, t_ + duration_s) with the heading given per time; calls `check` every
  /// check_every_s of simulated time.
  template <class Heading, class Check>
  void run(double duration_s, Heading heading, double check_every_s, Check check) {
    const double t_end = t_s_ + duration_s;
    const double dt = 1.0 / imu_hz_;
    double next_rv = t_s_, next_baro = t_s_, next_check = t_s_ + check_every_s;
    std::normal_distribution<double> noise(0.0, 0.15);
    for (; t_s_ < t_end; t_s_ += dt) {
      const double h = heading(t_s_);
      pos_ += (kStepLength_m * kCadence_hz * dt) * Eigen::Vector2d(std::sin(h), std::cos(h));
      const double ph = 2.0 * kPi * kCadence_hz * t_s_;
      AccelSample a;
      a.t_ns = ns(t_s_);
      a.acc_mps2 = Eigen::Vector3d(0.4 * std::sin(0.5 * ph + 0.3) + noise(rng_),
                                   kStandardGravity_mps2 + 2.2 * std::sin(ph) + 0.5 * std::sin(2.0 * ph + 0.7) + noise(rng_),
                                   0.8 * std::sin(ph + 1.1) + noise(rng_));
      nav_.feed(a);
      GyroSample g;
      g.t_ns = a.t_ns + 1;
      g.rate_radps = Eigen::Vector3d(0.02 * noise(rng_), 0.02 * noise(rng_), 0.02 * noise(rng_));
      nav_.feed(g);
      if (t_s_ >= next_rv) {
        RotationVectorSample r;
        r.t_ns = a.t_ns + 2;
        r.quat_xyzw = chest_quaternion(h);
        r.heading_accuracy_rad = 0.1;
        nav_.feed(r);
        next_rv += 0.1;
      }
      if (t_s_ >= next_baro) {
        PressureSample p;
        p.t_ns = a.t_ns + 3;
        p.pressure_pa = 101325.0 - 12.0 * (hill_elevation_m(pos_.x(), pos_.y()) - hill_elevation_m(0.0, 0.0));
        nav_.feed(p);
        next_baro += 1.0;
      }
      if (t_s_ >= next_check) {
        check(t_s_);
        next_check += check_every_s;
      }
    }
  }
  double t_s() const { return t_s_; }
  /// Leaves a gap of dt_s in the sensor stream (the walker stands still meanwhile).
  void skip(double dt_s) { t_s_ += dt_s; }
  const Eigen::Vector2d& truth() const { return pos_; }

  static constexpr double kStepLength_m = 0.7;
  static constexpr double kCadence_hz = 1.8;

 private:
  static TimeNs ns(double t_s) { return kNsPerS + static_cast<TimeNs>(t_s * 1e9); }
  fusion::Navigator& nav_;
  double imu_hz_;
  std::mt19937_64 rng_;
  double t_s_ = 0.0;
  Eigen::Vector2d pos_ = Eigen::Vector2d::Zero();
};

/// Every estimate the Navigator exposes is sane.
::testing::AssertionResult all_sane(const fusion::Navigator& nav) {
  const auto out = nav.output(50);
  if (auto r = sane(out.estimate); !r) return r << " (shown estimate)";
  for (const Estimate& e : out.engines)
    if (auto r = sane(e); !r) return r << " (engine " << to_string(e.engine) << ")";
  for (const auto& p : out.particles_en_m)
    if (!p.allFinite()) return ::testing::AssertionFailure() << "non-finite particle";
  return ::testing::AssertionSuccess();
}

fusion::NavigatorConfig config_with_dem(const std::string& dem_path, int particles) {
  fusion::NavigatorConfig cfg;
  cfg.mode = fusion::EngineMode::kAuto;
  cfg.dem_path = dem_path;
  cfg.particles = particles;
  cfg.start_lat_deg = kLat0;
  cfg.start_lon_deg = kLon0;
  return cfg;
}

/// A square loop of 200 m sides (~286 steps each), so the 10 h walk stays on the DEM.
double square_loop_heading(double t_s) {
  const double side_s = 200.0 / (NavigatorWalk::kStepLength_m * NavigatorWalk::kCadence_hz);
  return kPi / 2 * static_cast<double>(static_cast<std::int64_t>(t_s / side_s) % 4);
}

TEST(NavigatorRobustness, TenHoursOfWalkingStaysFiniteWithFlatMemory) {
  const auto dir = test::scratch_dir("reliability_ten_hours");
  const std::string dem = write_hill_pdem((dir / "hills.pdem").string(), 161, 30.0);
  fusion::Navigator nav(config_with_dem(dem, 200), 7);
  NavigatorWalk walk(nav, 50.0, 8);
  int checks = 0;
  auto check = [&](double t_s) {
    ++checks;
    ASSERT_TRUE(all_sane(nav)) << "at " << t_s << " s";
  };
  constexpr double kHalf_s = 5.0 * 3600.0;
  walk.run(600.0, square_loop_heading, 60.0, check);  // warm-up: containers reach their size
  const std::size_t heap_start = heap_in_use_bytes(), rss_start = rss_bytes();
  walk.run(kHalf_s - 600.0, square_loop_heading, 60.0, check);
  const std::size_t heap_half = heap_in_use_bytes();
  walk.run(kHalf_s, square_loop_heading, 60.0, check);
  const std::size_t heap_end = heap_in_use_bytes(), rss_end = rss_bytes();
  ASSERT_FALSE(HasFatalFailure());
  EXPECT_GE(checks, 590);

  const auto out = nav.output(10);
  EXPECT_TRUE(out.estimate.valid()) << out.estimate.reason;
  // 36000 s at 1.8 steps/s = 64800 steps
  EXPECT_NEAR(static_cast<double>(out.steps), 64800.0, 0.05 * 64800.0);
  // memory flat: the heap of the second 5 hours grows by less than 1 MB over the first
  const double growth_first = static_cast<double>(heap_half) - static_cast<double>(heap_start);
  const double growth_second = static_cast<double>(heap_end) - static_cast<double>(heap_half);
  EXPECT_LT(growth_second, 1.0e6) << "heap " << heap_start << " -> " << heap_half << " -> " << heap_end << " bytes";
  EXPECT_LT(growth_first, 1.0e6) << "heap " << heap_start << " -> " << heap_half << " -> " << heap_end << " bytes";
  RecordProperty("heap_start_bytes", std::to_string(heap_start));
  RecordProperty("heap_end_bytes", std::to_string(heap_end));
  std::printf("10 h: steps %lld, heap %zu -> %zu -> %zu bytes, RSS %zu -> %zu kB, shown engine %s\n",
              static_cast<long long>(out.steps), heap_start, heap_half, heap_end, rss_start / 1024, rss_end / 1024,
              to_string(out.estimate.engine));
}

TEST(NavigatorRobustness, AccelerometerRatesFrom1To500Hz) {
  for (double rate : {1.0, 10.0, 50.0, 100.0, 200.0, 500.0}) {
    fusion::NavigatorConfig cfg;
    cfg.mode = fusion::EngineMode::kDeadReckoning;
    cfg.start_lat_deg = kLat0;
    cfg.start_lon_deg = kLon0;
    fusion::Navigator nav(cfg, 9);
    NavigatorWalk walk(nav, rate, 10);
    walk.run(60.0, [](double) { return 0.5; }, 5.0, [&](double t) { ASSERT_TRUE(all_sane(nav)) << rate << " Hz, " << t << " s"; });
    ASSERT_FALSE(HasFatalFailure());
    const auto out = nav.output(0);
    const double truth = 60.0 * NavigatorWalk::kCadence_hz;  // 108 steps
    if (rate >= 50.0) {
      EXPECT_NEAR(static_cast<double>(out.steps), truth, 0.05 * truth) << rate << " Hz";
      ASSERT_TRUE(out.estimate.valid()) << rate << " Hz";
      // 75.6 m walked on heading 0.5 rad: dead reckoning within 15 % (the APT length model
      // gives 0.726 m for 1.75 m against the simulated 0.70 m; WMM declination)
      EXPECT_LT((out.estimate.en_m - walk.truth()).norm(), 11.3) << rate << " Hz: " << out.estimate.en_m.transpose()
                                                                << " vs " << walk.truth().transpose();
    } else {
      EXPECT_LE(static_cast<double>(out.steps), 1.05 * truth) << rate << " Hz";
    }
  }
}

TEST(NavigatorRobustness, HeadingFlipping180DegreesEveryStepStaysNearTheStart) {
  const auto dir = test::scratch_dir("reliability_heading_flip");
  const std::string dem = write_hill_pdem((dir / "hills.pdem").string(), 61, 30.0);
  fusion::Navigator nav(config_with_dem(dem, 200), 11);
  NavigatorWalk walk(nav, 100.0, 12);
  const double step_s = 1.0 / NavigatorWalk::kCadence_hz;
  walk.run(300.0, [&](double t) { return static_cast<std::int64_t>(t / step_s) % 2 == 0 ? 0.3 : 0.3 + kPi; }, 2.0,
           [&](double t) { ASSERT_TRUE(all_sane(nav)) << t << " s"; });
  ASSERT_FALSE(HasFatalFailure());
  const auto out = nav.output(0);
  EXPECT_GT(out.steps, 500);
  for (const Estimate& e : out.engines)
    if (e.valid()) {
      EXPECT_LT((e.en_m - walk.truth()).norm(), 40.0) << to_string(e.engine) << ": " << e.en_m.transpose();
    }
}

TEST(NavigatorRobustness, DemVoidEverywhereIsAClearErrorOrDeadReckoning) {
  const auto dir = test::scratch_dir("reliability_void_dem");
  const std::string dem = write_hill_pdem((dir / "void.pdem").string(), 41, 30.0, true);
  try {
    fusion::Navigator nav(config_with_dem(dem, 100), 13);
    NavigatorWalk walk(nav, 50.0, 14);
    walk.run(120.0, [](double) { return 1.0; }, 5.0, [&](double t) { ASSERT_TRUE(all_sane(nav)) << t << " s"; });
    ASSERT_FALSE(HasFatalFailure());
    const Estimate e = nav.estimate();
    ASSERT_TRUE(e.valid()) << e.reason;
    EXPECT_LT((e.en_m - walk.truth()).norm(), 0.1 * 151.2 + 5.0) << e.en_m.transpose() << " vs " << walk.truth().transpose();
  } catch (const std::exception& ex) {
    // refusing an all-void tile is fine, if the message names the file and the reason
    EXPECT_NE(std::string(ex.what()).find(dem), std::string::npos) << ex.what();
    EXPECT_NE(std::string(ex.what()).find("void"), std::string::npos) << ex.what();
  }
}

// Regression for the fuzz_navigator findings (docs/reliability.md): sample times anywhere in
// the int64 range (a corrupt log can hold any elapsedRealtimeNanos / TimeNanos). Differences
// of such times overflow int64 unless computed with care; the asan preset (UBSan, no
// recovery) turns such an overflow into a test failure.
TEST(NavigatorRobustness, ExtremeTimesAnywhereInTheInt64Range) {
  fusion::NavigatorConfig cfg;
  cfg.mode = fusion::EngineMode::kAuto;
  cfg.start_lat_deg = kLat0;
  cfg.start_lon_deg = kLon0;
  cfg.nav_paths.push_back(test::shared_data("gnss-mountainview/hour2350.16n"));
  fusion::Navigator nav(cfg, 17);
  constexpr TimeNs kMax = std::numeric_limits<TimeNs>::max(), kMin = std::numeric_limits<TimeNs>::min();
  const TimeNs times[] = {kMin + 1, kMax - 1, kMax};
  for (TimeNs t : times) {
    StepDetectorSample sd;  // an Android step event: a PdrStep at t (dead reckoning dt)
    sd.t_ns = t;
    nav.feed(sd);
    GnssRawSample raw;  // receiver clock at the extremes (GPS time = TimeNanos - FullBiasNanos)
    raw.t_ns = t;
    raw.time_nanos = t;
    raw.full_bias_nanos = t == kMax ? kMin + 1 : -t;
    raw.bias_nanos = 0.0;
    raw.svid = 5;
    raw.constellation_type = 1;
    raw.state = 16431;
    raw.received_sv_time_nanos = 1000;
    raw.cn0_dbhz = 40.0;
    nav.feed(raw);
    ASSERT_TRUE(all_sane(nav)) << "t = " << t;
  }
}

// fuzz_navigator finding 3 (docs/reliability.md): a start declared with an infinite or huge
// sigma must be refused or clamped, never give a "valid" estimate at infinity (it did: dead
// reckoning "ok" with an infinite covariance, until Navigator::Impl::start got kMaxStartSigmaM).
TEST(NavigatorRobustness, StartWithNonFiniteOrHugeSigma) {
  const auto dir = test::scratch_dir("reliability_start_sigma");
  const std::string dem = write_hill_pdem((dir / "hills.pdem").string(), 41, 30.0);
  for (double sigma : {std::numeric_limits<double>::infinity(), 1e300, 3e38}) {
    for (double lat : {kLat0, kLat0 + 1.0}) {  // on the DEM, and off it
      fusion::NavigatorConfig cfg = config_with_dem(dem, 100);
      cfg.start_lat_deg = kNaN;
      cfg.start_lon_deg = kNaN;
      fusion::Navigator nav(cfg, 18);
      nav.set_start(lat, kLon0, sigma, kNsPerS);
      NavigatorWalk walk(nav, 50.0, 19);
      walk.run(20.0, [](double) { return 1.0; }, 2.0,
               [&](double t) { ASSERT_TRUE(all_sane(nav)) << "sigma " << sigma << " lat " << lat << " at " << t << " s"; });
      ASSERT_FALSE(HasFatalFailure());
    }
  }
}

TEST(NavigatorRobustness, GarbageSamplesOfEveryTypeAreCountedNeverNaN) {
  const auto dir = test::scratch_dir("reliability_garbage");
  const std::string dem = write_hill_pdem((dir / "hills.pdem").string(), 41, 30.0);
  fusion::Navigator nav(config_with_dem(dem, 100), 15);
  NavigatorWalk walk(nav, 100.0, 16);
  walk.run(20.0, [](double) { return 2.0; }, 5.0, [](double) {});
  const double inf = std::numeric_limits<double>::infinity();
  TimeNs t = kNsPerS + s_to_ns(walk.t_s()) + kNsPerS;
  for (double b : {kNaN, inf, -inf, 1e300, -1e300, 0.0}) {
    t += 10'000'000;
    const Eigen::Vector3d v(b, b, b);
    AccelSample a; a.t_ns = t; a.acc_mps2 = v; nav.feed(a);
    GyroSample g; g.t_ns = t; g.rate_radps = v; nav.feed(g);
    MagSample m; m.t_ns = t; m.field_ut = v; nav.feed(m);
    RotationVectorSample r; r.t_ns = t; r.quat_xyzw = Eigen::Vector4d(b, b, b, b); r.heading_accuracy_rad = b; nav.feed(r);
    PressureSample p; p.t_ns = t; p.pressure_pa = b; nav.feed(p);
    FixSample f; f.t_ns = t; f.provider = "GPS"; f.lat_deg = b; f.lon_deg = b; f.accuracy_m = b; nav.feed(f);
    GnssRawSample raw; raw.t_ns = t; raw.cn0_dbhz = b; raw.bias_nanos = b; raw.svid = 5; raw.constellation_type = 1;
    raw.time_nanos = 1000; nav.feed(raw);
    MetaSample meta; meta.t_ns = t; meta.key = "StartLatitudeDegrees"; meta.value = std::to_string(b); nav.feed(meta);
    StepDetectorSample sd; sd.t_ns = t; nav.feed(sd);
    nav.set_start(b, b, b, t);
    ASSERT_TRUE(all_sane(nav)) << "garbage value " << b;
  }
  AccelSample back;  // time going backwards
  back.t_ns = kNsPerS;
  nav.feed(back);
  std::int64_t backwards = 0, invalid_start = 0;
  for (const auto& [why, n] : nav.ignored()) {
    if (why.find("backwards") != std::string::npos) backwards += n;
    if (why.find("start") != std::string::npos) invalid_start += n;
  }
  EXPECT_GE(backwards, 1);
  EXPECT_GE(invalid_start, 5);
  walk.skip(2.0);
  walk.run(30.0, [](double) { return 2.0; }, 5.0, [&](double s) { ASSERT_TRUE(all_sane(nav)) << s << " s"; });
  EXPECT_TRUE(nav.estimate().valid()) << nav.estimate().reason;
}

// Already-loaded data (NavigatorConfig::dem / ::ephemeris) shared read-only by several
// Navigators gives exactly what each Navigator loading its own copy from the paths gives,
// also when the sharing Navigators run interleaved (no state kept in the shared objects).
::testing::AssertionResult same_estimate(const Estimate& a, const Estimate& b) {
  if (a.valid() != b.valid() || a.engine != b.engine || a.status != b.status)
    return ::testing::AssertionFailure() << "valid/engine/status differ: " << a.reason << " vs " << b.reason;
  if (a.en_m != b.en_m || a.cov_en_m2 != b.cov_en_m2 || a.position.lat_rad != b.position.lat_rad ||
      a.position.lon_rad != b.position.lon_rad)
    return ::testing::AssertionFailure() << "position differs: " << a.en_m.transpose() << " vs " << b.en_m.transpose();
  return ::testing::AssertionSuccess();
}

TEST(NavigatorSharedData, PreloadedDemGivesTheSameWalkAsLoadingThePath) {
  const auto dir = test::scratch_dir("reliability_shared_dem");
  const std::string path = write_hill_pdem((dir / "hills.pdem").string(), 101, 30.0);
  fusion::NavigatorConfig loading = config_with_dem(path, 200);
  fusion::NavigatorConfig sharing = config_with_dem("", 200);
  sharing.dem = std::make_shared<const terrain::Dem>(terrain::Dem::load(path));
  fusion::Navigator own(loading, 3), shared_a(sharing, 3), shared_b(sharing, 3);
  NavigatorWalk walk_own(own, 50.0, 5), walk_a(shared_a, 50.0, 5), walk_b(shared_b, 50.0, 5);
  const auto heading = [](double t_s) { return t_s < 60.0 ? 0.3 : 1.9; };
  for (int leg = 0; leg < 12; ++leg) {  // 120 s, the sharing two interleaved every 10 s
    const auto none = [](double) {};
    walk_own.run(10.0, heading, 100.0, none);
    walk_a.run(10.0, heading, 100.0, none);
    walk_b.run(10.0, heading, 100.0, none);
    ASSERT_TRUE(same_estimate(own.estimate(), shared_a.estimate())) << "leg " << leg;
    ASSERT_TRUE(same_estimate(own.estimate(), shared_b.estimate())) << "leg " << leg;
  }
  const Estimate e = own.estimate();
  EXPECT_EQ(e.engine, EngineKind::kTerrain) << e.reason;
  EXPECT_GT(e.en_m.norm(), 100.0);  // it walked: ~120 s x 1.8 steps/s x 0.7 m
}

TEST(NavigatorSharedData, PreloadedEphemerisGivesTheSameFixesAsLoadingThePath) {
  const std::string nav_path = test::shared_data("gnss-mountainview/hour2350.16n");
  fusion::NavigatorConfig loading;
  loading.mode = fusion::EngineMode::kGnss;
  loading.nav_paths.push_back(nav_path);
  fusion::NavigatorConfig sharing;
  sharing.mode = fusion::EngineMode::kGnss;
  auto eph = std::make_shared<gnss::EphemerisStore>();
  eph->load_rinex_nav(nav_path);
  const std::size_t records = eph->size();
  sharing.ephemeris = eph;
  fusion::Navigator own(loading, 9), shared_a(sharing, 9), shared_b(sharing, 9);
  io::LogReader log(test::shared_data("gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt"));
  Sample s;
  int raw_rows = 0, valid = 0;
  while (raw_rows < 1500 && log.next(s)) {
    raw_rows += std::holds_alternative<GnssRawSample>(s) ? 1 : 0;
    own.feed(s);
    shared_a.feed(s);
    shared_b.feed(s);
    ASSERT_TRUE(same_estimate(own.estimate(), shared_a.estimate())) << "row " << raw_rows;
    ASSERT_TRUE(same_estimate(own.estimate(), shared_b.estimate())) << "row " << raw_rows;
    valid += own.estimate().valid() ? 1 : 0;
  }
  EXPECT_EQ(raw_rows, 1500);
  EXPECT_GT(valid, 0);  // the GNSS engine fixed from the shared broadcast orbits
  EXPECT_EQ(eph->size(), records);  // and left them as they were
  EXPECT_EQ(own.estimate().engine, EngineKind::kGnss);
}
}  // namespace
}  // namespace pdnav::reliability
