// Numerical robustness of the terrain particle filter (issue 9), through its public face:
// all weights underflowing, a DEM void everywhere, walking off the DEM, a stuck or jumping
// barometer, heading flipping by 180 degrees every step, garbage steps. After every input the
// estimate must be sane (finite, covariance positive semi-definite) and, where the answer is
// known (no terrain information = dead reckoning), close to the truth.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/geo/baro.h"
#include "pdnav/terrain/terrain_engine.h"
#include "robustness_support.h"

namespace pdnav::reliability {
namespace {

constexpr double kStepLength_m = 0.7;
constexpr TimeNs kStepPeriod_ns = 550'000'000;  // 1.8 steps/s
constexpr double kRefPressure_pa = 101325.0;

/// A walker on the hills: true position, time, and the engine it feeds.
class TerrainWalk {
 public:
  TerrainWalk(std::shared_ptr<const terrain::Dem> dem, terrain::TerrainOptions opt, std::uint64_t seed)
      : dem_(std::move(dem)), engine_(opt, dem_, seed) {
    engine_.initialize(dem_->to_geodetic(0.0, 0.0), 5.0, t_ns_);
    start_h_m_ = hill_elevation_m(0.0, 0.0);
  }

  /// One step of kStepLength_m along `heading_rad` (truth), reported with `reported_heading_rad`,
  /// followed by one pressure sample `pressure_offset_pa` away from the true altitude's.
  /// From now on every step reads this pressure (a stuck sensor); NaN = the true pressure.
  void stick_pressure(double p_pa) { stuck_pa_ = p_pa; }
  void step(double heading_rad, double pressure_offset_pa = 0.0, double reported_heading_rad = kNaN) {
    t_ns_ += kStepPeriod_ns;
    pos_ += kStepLength_m * Eigen::Vector2d(std::sin(heading_rad), std::cos(heading_rad));
    PdrStep s;
    s.t_ns = t_ns_;
    s.length_m = kStepLength_m;
    s.heading_rad = std::isnan(reported_heading_rad) ? heading_rad : reported_heading_rad;
    s.heading_sigma_rad = 5.0 * kDegToRad;
    s.length_sigma_m = 0.05;
    engine_.feed(s);
    pressure(std::isnan(stuck_pa_) ? true_pressure_pa() + pressure_offset_pa : stuck_pa_);
  }
  void pressure(double p_pa) {
    PressureSample p;
    p.t_ns = t_ns_ + 1;
    p.pressure_pa = p_pa;
    engine_.feed(p);
  }
  double true_pressure_pa() const {
    return geo::baro_pressure_pa(hill_elevation_m(pos_.x(), pos_.y()), kRefPressure_pa, start_h_m_);
  }
  double error_m() const { return (engine_.estimate().en_m - pos_).norm(); }
  terrain::TerrainEngine& engine() { return engine_; }
  TimeNs tick() { return t_ns_ += kStepPeriod_ns; }
  const Eigen::Vector2d& truth() const { return pos_; }

 private:
  std::shared_ptr<const terrain::Dem> dem_;
  terrain::TerrainEngine engine_;
  TimeNs t_ns_ = 10 * kNsPerS;
  Eigen::Vector2d pos_ = Eigen::Vector2d::Zero();
  double start_h_m_ = 0.0;
  double stuck_pa_ = kNaN;
};

/// Never confidently wrong: an estimate more than 100 m off must not claim kOk, and must not be
/// off by more than 5 reported sigmas.
::testing::AssertionResult honest(TerrainWalk& w) {
  const Estimate e = w.engine().estimate();
  const double err = w.error_m(), sigma = std::sqrt(e.cov_en_m2.trace());
  if (err > 100.0 && e.status == EstimateStatus::kOk)
    return ::testing::AssertionFailure() << "status ok while " << err << " m off (sigma " << sigma << " m)";
  if (err > 5.0 * sigma + 10.0)
    return ::testing::AssertionFailure() << err << " m off with a reported sigma of " << sigma << " m (" << e.reason << ")";
  return ::testing::AssertionSuccess();
}

terrain::TerrainOptions paper_options(int particles = 300) {
  auto o = terrain::TerrainOptions::paper();
  o.particles = particles;
  return o;
}

TEST(TerrainRobustness, AllWeightsUnderflowingIsHandledAndTrackingResumes) {
  auto opt = paper_options();
  opt.baro_jump_m = 0.0;  // no step compensation: the fault reaches the weights
  TerrainWalk w(hill_dem(), opt, 11);
  w.pressure(w.true_pressure_pa());
  for (int i = 0; i < 60; ++i) {
    w.step(0.3);
    ASSERT_TRUE(sane(w.engine().estimate())) << "consistent phase, step " << i;
  }
  // baro 250 hPa off (~2.5 km of altitude): every particle's likelihood underflows to 0
  for (int i = 0; i < 40; ++i) {
    w.step(0.3, -25000.0);
    ASSERT_TRUE(sane(w.engine().estimate())) << "inconsistent phase, step " << i;
  }
  const auto& st = w.engine().stats();
  EXPECT_GT(st.weight_underflows + st.recoveries, 0) << "underflow neither counted nor recovered";
  // no information from a baro that fits nowhere: the cloud must not jump anywhere either
  EXPECT_LT(w.error_m(), 30.0) << w.engine().estimate().reason;
  for (int i = 0; i < 80; ++i) {
    w.step(0.3);
    ASSERT_TRUE(honest(w)) << "recovery phase, step " << i;
    ASSERT_TRUE(sane(w.engine().estimate())) << "recovery phase, step " << i;
  }
  const Estimate e = w.engine().estimate();
  EXPECT_NE(e.status, EstimateStatus::kNotInitialized);
  for (const auto& p : w.engine().particles_en(100)) ASSERT_TRUE(p.allFinite());
}

TEST(TerrainRobustness, BarometerStepOf250hPaIsCompensatedAndTrackingContinues) {
  // The same fault with the default step compensation: the sensor jumps by -250 hPa for 40
  // steps and back; both steps are measured and subtracted, so the filter keeps tracking.
  TerrainWalk w(hill_dem(), paper_options(), 11);
  w.pressure(w.true_pressure_pa());
  double max_err = 0.0;
  for (int i = 0; i < 180; ++i) {
    w.step(0.3, i >= 60 && i < 100 ? -25000.0 : 0.0);
    ASSERT_TRUE(sane(w.engine().estimate())) << "step " << i;
    ASSERT_TRUE(honest(w)) << "step " << i;
    max_err = std::max(max_err, w.error_m());
  }
  const auto& st = w.engine().stats();
  EXPECT_EQ(st.baro_jumps, 2);
  // down and back up: the steps cancel up to the walker's own climb within each sample interval
  // (one sample per 0.55 s step here) and the hypsometric non-linearity; the bias state takes it
  EXPECT_NEAR(st.baro_jump_offset_m, 0.0, 3.0);
  EXPECT_EQ(st.weight_underflows, 0);
  EXPECT_EQ(w.engine().estimate().status, EstimateStatus::kOk) << w.engine().estimate().reason;
  EXPECT_LT(max_err, 30.0);
  std::printf("250 hPa step for 40 steps: max error %.1f m, final %.1f m\n", max_err, w.error_m());
}

TEST(TerrainRobustness, DemVoidEverywhereReducesToDeadReckoning) {
  TerrainWalk w(hill_dem(101, 30.0, true), paper_options(), 12);
  w.pressure(kRefPressure_pa);
  for (int i = 0; i < 150; ++i) {
    w.step(kPi / 2);  // east
    ASSERT_TRUE(sane(w.engine().estimate())) << "step " << i;
  }
  // no terrain information: the mean is dead reckoning, 105 m east (+- heading-bias spread)
  const Estimate e = w.engine().estimate();
  EXPECT_LT(w.error_m(), 15.0) << "estimate " << e.en_m.transpose() << " truth " << w.truth().transpose();
}

TEST(TerrainRobustness, WalkingOffTheDemStaysFiniteAndDeadReckons) {
  // 601 m square tile; the walk goes 840 m east, i.e. 540 m past its edge
  TerrainWalk w(hill_dem(21, 30.0), paper_options(), 13);
  w.pressure(w.true_pressure_pa());
  for (int i = 0; i < 1200; ++i) {
    w.step(kPi / 2);
    ASSERT_TRUE(sane(w.engine().estimate())) << "step " << i;
  }
  const Estimate e = w.engine().estimate();
  EXPECT_GT(w.engine().stats().off_dem_fraction, 0.5);
  EXPECT_LT(w.error_m(), 100.0) << "estimate " << e.en_m.transpose() << " truth " << w.truth().transpose();
}

TEST(TerrainRobustness, StuckBarometerIsDetectedAndUpdatesPause) {
  TerrainWalk w(hill_dem(), paper_options(), 14);
  w.pressure(w.true_pressure_pa());
  for (int i = 0; i < 20; ++i) w.step(0.8);
  w.stick_pressure(w.true_pressure_pa());  // the sensor freezes here, while the walker climbs
  const std::int64_t updates_before = w.engine().stats().updates;
  double max_err = 0.0;
  bool flagged = false;
  for (int i = 0; i < 400; ++i) {
    w.step(i < 200 ? 0.8 : 2.2);  // climbs 20-60 m while the sensor reads the same value
    ASSERT_TRUE(sane(w.engine().estimate())) << "step " << i;
    ASSERT_TRUE(honest(w)) << "step " << i;
    max_err = std::max(max_err, w.error_m());
    const Estimate e = w.engine().estimate();
    if (i >= 40) {  // 22 s at 1.8 steps/s: past the 20 s stuck limit
      ASSERT_TRUE(w.engine().stats().baro_stuck) << "step " << i;
      ASSERT_EQ(e.status, EstimateStatus::kDegraded) << e.reason;
      flagged = true;
    }
  }
  EXPECT_TRUE(flagged);
  EXPECT_EQ(w.engine().stats().baro_stuck_events, 1);
  // at most the 20 s before detection were used: the filter then dead-reckons
  EXPECT_LT(w.engine().stats().updates - updates_before, 40);
  EXPECT_LT(max_err, 80.0);  // measured 56 m; 130 m (and "ok", sigma 5 m) before detection existed
  // the sensor recovers: updates resume, status back to ok
  w.stick_pressure(kNaN);
  for (int i = 0; i < 30; ++i) w.step(2.2);
  EXPECT_FALSE(w.engine().stats().baro_stuck);
  EXPECT_EQ(w.engine().estimate().status, EstimateStatus::kOk) << w.engine().estimate().reason;
  std::printf("stuck barometer: max error %.1f m, final %.1f m, final sigma %.1f m\n", max_err, w.error_m(),
              std::sqrt(w.engine().estimate().cov_en_m2.trace()));
}

TEST(TerrainRobustness, BarometerJumping50hPaKeepsSaneEstimates) {
  TerrainWalk w(hill_dem(), paper_options(), 15);
  w.pressure(w.true_pressure_pa());
  for (int i = 0; i < 300; ++i) {
    const double jump = ((i / 20) % 2 == 1) ? 5000.0 : 0.0;  // +50 hPa for 20 steps, then back
    w.step(1.2, jump);
    ASSERT_TRUE(sane(w.engine().estimate())) << "step " << i;
    ASSERT_TRUE(honest(w)) << "step " << i;
  }
  EXPECT_EQ(w.engine().stats().baro_jumps, 14);  // 7 jumps up and 7 back down
  EXPECT_LT(w.error_m(), 30.0);
}

TEST(TerrainRobustness, HeadingFlipping180DegreesEveryStepStaysNearTheStart) {
  TerrainWalk w(hill_dem(), paper_options(), 16);
  w.pressure(w.true_pressure_pa());
  for (int i = 0; i < 400; ++i) {
    w.step(i % 2 == 0 ? 0.4 : 0.4 + kPi);
    ASSERT_TRUE(sane(w.engine().estimate())) << "step " << i;
  }
  EXPECT_LT(w.error_m(), 30.0);  // the truth oscillates around the start; so must the mean
}

TEST(TerrainRobustness, GarbageStepsAndPressuresNeverProduceNaN) {
  TerrainWalk w(hill_dem(), paper_options(), 17);
  w.pressure(w.true_pressure_pa());
  const double inf = std::numeric_limits<double>::infinity();
  const double bad[] = {kNaN, inf, -inf, -1.0, 0.0, 1e300, -1e300, 1e-300};
  for (double b : bad) {
    for (int field = 0; field < 4; ++field) {
      PdrStep s;
      const TimeNs t = w.tick();
      s.t_ns = t;
      s.length_m = field == 0 ? b : 0.7;
      s.heading_rad = field == 1 ? b : 1.0;
      s.heading_sigma_rad = field == 2 ? b : 0.1;
      s.length_sigma_m = field == 3 ? b : 0.05;
      w.engine().feed(s);
      ASSERT_TRUE(sane(w.engine().estimate())) << "step field " << field << " = " << b;
      PressureSample p;
      p.t_ns = t + 1;
      p.pressure_pa = b;
      w.engine().feed(p);
      ASSERT_TRUE(sane(w.engine().estimate())) << "pressure " << b;
    }
  }
  for (int i = 0; i < 50; ++i) w.step(1.0);  // still usable afterwards
  EXPECT_TRUE(sane(w.engine().estimate()));
  EXPECT_TRUE(w.engine().estimate().valid());
}

}  // namespace
}  // namespace pdnav::reliability
