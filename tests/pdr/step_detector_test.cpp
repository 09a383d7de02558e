// Step detection: the Oxford bar on real walks, synthetic cadences with known answers, bad
// input (NaN, duplicate/backwards timestamps, gaps), the bout gate, Android step events.
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../../core-cpp/cli/support/pdr_oxford.h"
#include "pdnav/pdr/pdr.h"
#include "pdnav/pdr/step_detector.h"
#include "pdnav/pdr/step_length.h"
#include "test_data.h"

using namespace pdnav;
using namespace pdnav::pdr;

namespace {

const char* const kOxfordFiles[] = {
    "steps-oxford/user1_armband_1506423438471.csv",    "steps-oxford/user1_backpocket_1506422470497.csv",
    "steps-oxford/user1_bag_1506423095164.csv",        "steps-oxford/user1_frontpocket_1506422223341.csv",
    "steps-oxford/user1_hand_1506421989895.csv",       "steps-oxford/user1_neckpouch_1506422851785.csv",
};

std::int64_t count_with_pdr(const std::vector<AccelSample>& samples, const PdrOptions& opt) {
  Pdr engine(opt);
  for (const auto& s : samples) engine.feed(s);
  return engine.step_count();
}

/// A synthetic walk's accelerometer: |a| = g + A sin(2 pi f t) + noise, on one axis mix.
std::vector<AccelSample> synthetic_steps(double cadence_hz, double duration_s, double amp, std::uint64_t seed,
                                         double rate_hz = 100.0, double t0_s = 1.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.15);
  std::vector<AccelSample> out;
  const auto n = static_cast<std::int64_t>(duration_s * rate_hz);
  for (std::int64_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / rate_hz;
    const double m = kStandardGravity_mps2 + amp * std::sin(2 * kPi * cadence_hz * t) + noise(rng);
    AccelSample s;
    s.t_ns = s_to_ns(t0_s + t);
    s.acc_mps2 = Eigen::Vector3d(0.3 * m, 0.8 * m, 0.52 * m);
    out.push_back(s);
  }
  return out;
}

}  // namespace

TEST(OxfordWalks, StepCountErrorMeetsTheBar) {
  // One parameter set (the defaults) for all six placements.
  double sum_abs = 0.0, worst = 0.0;
  for (const char* rel : kOxfordFiles) {
    const auto rec = cli::read_oxford_csv(test::shared_data(rel));
    ASSERT_GT(rec.truth_steps, 300) << rel;
    ASSERT_EQ(rec.skipped_lines, 0) << rec.first_issue;
    const std::int64_t detected = count_with_pdr(rec.samples, PdrOptions{});
    const double err = 100.0 * static_cast<double>(detected - rec.truth_steps) / static_cast<double>(rec.truth_steps);
    std::printf("%-50s truth %4lld detected %4lld error %+6.2f %%\n", rel, static_cast<long long>(rec.truth_steps),
                static_cast<long long>(detected), err);
    EXPECT_LE(std::abs(err), 8.0) << rel;  // bar: no file worse than 8 %
    sum_abs += std::abs(err);
    worst = std::max(worst, std::abs(err));
  }
  const double mean = sum_abs / 6.0;
  std::printf("mean |error| %.2f %%, worst %.2f %%\n", mean, worst);
  EXPECT_LE(mean, 3.0);  // bar: mean absolute error <= 3 %
  // Regression guard at the level measured on 2026-11-23 (0.44 % mean, 1.45 % worst).
  EXPECT_LE(mean, 1.0);
  EXPECT_LE(worst, 2.0);
}

TEST(OxfordWalks, PaperFormIsWorseOnPockets) {
  // APT's detector as published over-counts the pocket walks: the gates are needed.
  const auto rec = cli::read_oxford_csv(test::shared_data("steps-oxford/user1_frontpocket_1506422223341.csv"));
  PdrOptions paper;
  paper.detector = StepDetectorOptions::paper();
  const auto detected = count_with_pdr(rec.samples, paper);
  EXPECT_GT(std::abs(static_cast<double>(detected - rec.truth_steps)) / static_cast<double>(rec.truth_steps), 0.10);
}

TEST(OxfordWalks, RobustToHalfSampleRate) {
  // Decimate to ~50 Hz: the detector works in time units, not sample counts.
  const auto rec = cli::read_oxford_csv(test::shared_data("steps-oxford/user1_hand_1506421989895.csv"));
  std::vector<AccelSample> half;
  for (std::size_t i = 0; i < rec.samples.size(); i += 2) half.push_back(rec.samples[i]);
  const auto detected = count_with_pdr(half, PdrOptions{});
  EXPECT_NEAR(static_cast<double>(detected), static_cast<double>(rec.truth_steps), 0.03 * static_cast<double>(rec.truth_steps));
}

TEST(OxfordWalks, RobustToGentlerMotion) {
  // The same walk with a quarter of the motion (|a| - g scaled by 0.25): a gentle walker or a
  // padded bag must still be counted (the walking gate must not be tuned to this user).
  const auto rec = cli::read_oxford_csv(test::shared_data("steps-oxford/user1_hand_1506421989895.csv"));
  std::vector<AccelSample> gentle = rec.samples;
  for (auto& s : gentle) {
    const double m = s.acc_mps2.norm();
    if (m > 0.0) s.acc_mps2 *= (kStandardGravity_mps2 + 0.25 * (m - kStandardGravity_mps2)) / m;
  }
  const auto detected = count_with_pdr(gentle, PdrOptions{});
  EXPECT_NEAR(static_cast<double>(detected), static_cast<double>(rec.truth_steps), 0.03 * static_cast<double>(rec.truth_steps));
}

class SyntheticCadence : public ::testing::TestWithParam<double> {};

TEST_P(SyntheticCadence, CountsKnownSteps) {
  const double cadence = GetParam();
  const double duration = 60.0;
  const auto samples = synthetic_steps(cadence, duration, 2.5, 42);
  const auto steps = detect_steps(samples, StepDetectorOptions{});
  EXPECT_NEAR(static_cast<double>(steps.size()), cadence * duration, 2.0) << cadence << " Hz";
}

INSTANTIATE_TEST_SUITE_P(Cadences, SyntheticCadence, ::testing::Values(1.2, 1.6, 2.0, 2.5, 3.0));

TEST(StepDetector, StandingStillGivesNoSteps) {
  const auto samples = synthetic_steps(1.8, 60.0, 0.0, 3);  // noise only
  EXPECT_TRUE(detect_steps(samples, StepDetectorOptions{}).empty());
}

TEST(StepDetector, IsolatedJoltsAreRejectedByTheBoutGate) {
  auto samples = synthetic_steps(1.8, 30.0, 0.0, 5);
  // Three isolated jolts 4 s apart (e.g. putting the phone down): not a walk.
  for (double at : {5.0, 9.0, 13.0}) {
    for (auto& s : samples) {
      const double t = ns_to_s(s.t_ns) - 1.0;
      if (t > at && t < at + 0.3) s.acc_mps2 *= 1.0 + 0.6 * std::sin(kPi * (t - at) / 0.3);
    }
  }
  SampleCounters counters;
  EXPECT_TRUE(detect_steps(samples, StepDetectorOptions{}, &counters).empty());
}

TEST(StepDetector, BadSamplesAreSkippedAndCounted) {
  auto samples = synthetic_steps(2.0, 40.0, 2.5, 11);
  const std::size_t clean_steps = detect_steps(samples, StepDetectorOptions{}).size();
  // NaN values, a duplicated timestamp, a backwards timestamp.
  samples[500].acc_mps2.x() = kNaN;
  samples[900].acc_mps2.z() = std::numeric_limits<double>::infinity();
  samples.insert(samples.begin() + 1200, samples[1200]);
  AccelSample back = samples[2000];
  back.t_ns -= s_to_ns(0.5);
  samples.insert(samples.begin() + 2001, back);
  SampleCounters c;
  const auto steps = detect_steps(samples, StepDetectorOptions{}, &c);
  EXPECT_EQ(c.non_finite, 2);
  EXPECT_EQ(c.duplicate_time, 1);
  EXPECT_EQ(c.backwards_time, 1);
  EXPECT_EQ(c.gaps, 0);
  EXPECT_NEAR(static_cast<double>(steps.size()), static_cast<double>(clean_steps), 1.0);
}

TEST(StepDetector, GapResetsDetectorAndIsCounted) {
  const auto a = synthetic_steps(2.0, 20.0, 2.5, 1, 100.0, 1.0);
  const auto b = synthetic_steps(2.0, 20.0, 2.5, 2, 100.0, 31.0);  // 10 s gap
  std::vector<AccelSample> samples = a;
  samples.insert(samples.end(), b.begin(), b.end());
  SampleCounters c;
  const auto steps = detect_steps(samples, StepDetectorOptions{}, &c);
  EXPECT_EQ(c.gaps, 1);
  // Each part loses at most the warm-up of the running window (1.5 s = 3 steps).
  EXPECT_GE(static_cast<double>(steps.size()), 80.0 - 8.0);
  EXPECT_LE(static_cast<double>(steps.size()), 80.0 + 2.0);
  for (const auto& s : steps) {  // no step inside the gap
    const double t = ns_to_s(s.t_ns);
    EXPECT_FALSE(t > 21.0 && t < 31.0) << t;
  }
}

TEST(StepDetector, EmptyAndTinyInputs) {
  EXPECT_TRUE(detect_steps({}, StepDetectorOptions{}).empty());
  std::vector<AccelSample> one(1);
  EXPECT_TRUE(detect_steps(one, StepDetectorOptions{}).empty());
}

TEST(BoutGate, ReleasesAfterMinStepsAndDiscardsShortBouts) {
  BoutGate<int> gate(3, 1.0);
  EXPECT_TRUE(gate.push(s_to_ns(0.0), 1).empty());
  EXPECT_TRUE(gate.push(s_to_ns(0.5), 2).empty());
  EXPECT_EQ(gate.push(s_to_ns(1.0), 3), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(gate.push(s_to_ns(1.5), 4), (std::vector<int>{4}));
  EXPECT_TRUE(gate.push(s_to_ns(5.0), 5).empty());  // pause ends the bout
  EXPECT_TRUE(gate.push(s_to_ns(5.5), 6).empty());
  EXPECT_TRUE(gate.push(s_to_ns(9.0), 7).empty());  // 5, 6 never confirmed
  EXPECT_EQ(gate.discarded(), 2);
}

TEST(StepLength, AptHeightModelAndWeinberg) {
  EXPECT_DOUBLE_EQ(StepLengthModel::apt_male(1.80).length_m(kNaN), 0.415 * 1.80);
  EXPECT_DOUBLE_EQ(StepLengthModel::apt_female(1.60).length_m(3.0), 0.413 * 1.60);
  const auto w = StepLengthModel::weinberg(0.36);
  EXPECT_NEAR(w.length_m(16.0), 0.72, 1e-12);  // 0.36 * 16^(1/4)
  EXPECT_LT(w.length_m(4.0), w.length_m(9.0));
  EXPECT_DOUBLE_EQ(w.length_m(1e6), w.max_length_m);
  EXPECT_TRUE(std::isfinite(w.length_m(kNaN)));
  StepLengthModel c;
  c.kind = StepLengthKind::kConstant;
  c.constant_m = 0.65;
  EXPECT_DOUBLE_EQ(c.length_m(5.0), 0.65);
  EXPECT_DOUBLE_EQ(c.sigma_m(0.65), 0.065);
}

TEST(AndroidSteps, SourceSelectionAndConsistency) {
  const auto samples = synthetic_steps(2.0, 30.0, 2.5, 21);
  // Android events at the true cadence (2 Hz), and a second run where they are half as many.
  for (int variant = 0; variant < 2; ++variant) {
    PdrOptions opt;
    opt.source = StepSource::kAndroid;
    Pdr engine(opt);
    std::int64_t android = 0;
    TimeNs next_event = s_to_ns(1.25);
    const TimeNs period = variant == 0 ? s_to_ns(0.5) : s_to_ns(1.0);
    for (const auto& s : samples) {
      while (next_event <= s.t_ns) {
        engine.feed(StepDetectorSample{next_event, kMissingInt});
        next_event += period;
        ++android;
      }
      engine.feed(s);
    }
    EXPECT_EQ(engine.step_count(), android);  // output follows the selected source
    const auto c = engine.consistency();
    EXPECT_GT(c.accel_steps, 40);
    if (variant == 0) {
      EXPECT_TRUE(c.consistent) << c.relative_difference;
    } else {
      EXPECT_FALSE(c.consistent) << c.relative_difference;
      EXPECT_NEAR(c.relative_difference, 0.5, 0.1);
    }
  }
}

TEST(AndroidSteps, AutoFallsBackToAccelerometerWhenEventsStop) {
  const auto samples = synthetic_steps(2.0, 40.0, 2.5, 22);
  PdrOptions opt;
  opt.source = StepSource::kAuto;
  Pdr engine(opt);
  TimeNs next_event = s_to_ns(1.25);
  std::int64_t android = 0;
  for (const auto& s : samples) {
    while (next_event <= s.t_ns && next_event < s_to_ns(11.0)) {  // events only for the first 10 s
      engine.feed(StepDetectorSample{next_event, kMissingInt});
      next_event += s_to_ns(0.5);
      ++android;
    }
    engine.feed(s);
  }
  EXPECT_EQ(android, 20);
  EXPECT_NEAR(static_cast<double>(engine.step_count()), 80.0, 6.0);
  // Out-of-order Android events are counted and skipped.
  engine.feed(StepDetectorSample{s_to_ns(2.0), kMissingInt});
  EXPECT_EQ(engine.counters().step_detector.backwards_time, 1);
}

TEST(StepDetector, SuddenCadenceChangesAreFollowed) {
  // 20 s at 1.2 Hz then 20 s at 3.0 Hz then 20 s at 1.5 Hz: the adaptive refractory time must
  // not lock onto every other step after the speed-up.
  std::vector<AccelSample> samples;
  double t0 = 1.0;
  for (double cadence : {1.2, 3.0, 1.5}) {
    const auto part = synthetic_steps(cadence, 20.0, 2.5, static_cast<std::uint64_t>(cadence * 10), 100.0, t0);
    samples.insert(samples.end(), part.begin(), part.end());
    t0 += 20.0;
  }
  const auto steps = detect_steps(samples, StepDetectorOptions{});
  EXPECT_NEAR(static_cast<double>(steps.size()), 20.0 * (1.2 + 3.0 + 1.5), 4.0);
}
