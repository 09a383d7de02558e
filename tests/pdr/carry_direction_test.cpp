// Issue 27: walking direction relative to the phone in every carry, on the real TYREX
// motion-capture recordings (../shared/data/pdr-tyrex-guillaume, one walker, LG Nexus 5).
// The accelerometer and calibrated gyroscope of each recording go through a Pdr (auto mount);
// the walking direction of its longest placement bout is compared with the truth.
//
// Truth: the direction of travel in phone axes from the motion capture, i.e. R(t)^T v(t) with
// R the captured rigid-body rotation (body = phone axes, checked: captured and measured angular
// rates correlate 0.7-0.98 per axis) and v the horizontal velocity of the 1.2 s-smoothed
// captured position, averaged over the samples where the walker moves faster than 0.25 m/s
// (capture time = phone time + timeAlignment.txt), projected on the horizontal plane of the
// mean gravity. The mean resultant length of that direction is 0.89-0.97 for these carries: one
// constant direction per bout is a fair model even for pockets and a swinging hand.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "pdnav/pdr/pdr.h"
#include "pdnav/phonesim/sample_rate.h"
#include "pdnav/phonesim/walk_speed.h"
#include "test_data.h"

using namespace pdnav;
using namespace pdnav::pdr;

namespace {

struct Recording {
  std::vector<AccelSample> accel;
  std::vector<GyroSample> gyro;
  std::vector<MagSample> mag;
};

/// "t x y z [...]" lines (t in seconds since the start); t + 1 s as the sample time.
template <typename F>
void read_txyz(const std::string& path, F&& add) {
  std::ifstream in(path);
  ASSERT_TRUE(in.good()) << path;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    double t = 0, x = 0, y = 0, z = 0;
    if (!(ss >> t >> x >> y >> z)) continue;
    add(static_cast<TimeNs>(std::llround((t + 1.0) * 1e9)), Eigen::Vector3d(x, y, z));
    ++n;
  }
  ASSERT_GT(n, 1000) << path;
}

Recording read_tyrex(const std::string& name) {
  const std::string dir = pdnav::test::shared_data("pdr-tyrex-guillaume/datasets/android/" + name);
  Recording r;
  read_txyz(dir + "/accelerometer.txt",
            [&](TimeNs t, const Eigen::Vector3d& v) { r.accel.push_back({t, kMissingInt, v}); });
  read_txyz(dir + "/gyroscope-calibrated.txt",
            [&](TimeNs t, const Eigen::Vector3d& v) { r.gyro.push_back({t, kMissingInt, v}); });
  read_txyz(dir + "/magnetometer-calibrated.txt",
            [&](TimeNs t, const Eigen::Vector3d& v) { r.mag.push_back({t, kMissingInt, v}); });
  return r;
}

/// Feeds the recording's accelerometer (and gyroscope, and magnetometer) samples in time order
/// up to until_ns.
void feed(Pdr& pdr, const Recording& r, bool with_gyro, TimeNs until_ns = std::numeric_limits<TimeNs>::max(),
          bool with_mag = false) {
  std::size_t g = 0, m = 0;
  for (const auto& a : r.accel) {
    if (a.t_ns > until_ns) break;
    while (with_gyro && g < r.gyro.size() && r.gyro[g].t_ns <= a.t_ns) pdr.feed(r.gyro[g++]);
    while (with_mag && m < r.mag.size() && r.mag[m].t_ns <= a.t_ns) pdr.feed(r.mag[m++]);
    pdr.feed(a);
  }
}

/// A whole TYREX recording (accelerometer and gyroscope; without_gyro: accelerometer and
/// magnetometer, a phone without a gyroscope) through a Pdr in auto mount, finished.
std::unique_ptr<Pdr> replayed(const std::string& name, PdrOptions o = {}, bool without_gyro = false) {
  o.heading.mount = Mount::kAuto;
  const Recording r = read_tyrex(name);
  auto pdr = std::make_unique<Pdr>(o);
  feed(*pdr, r, !without_gyro, std::numeric_limits<TimeNs>::max(), without_gyro);
  pdr->finish();
  return pdr;
}

/// A TYREX recording with the step count of its motion capture and the span that count covers
/// (tools/tyrex2log's Meta TruthSteps / TruthStepsFrom,ToNanos; the recordings' time + 1 s, as
/// read_txyz reads them).
struct CapturedWalk {
  const char* name;
  double from_s, to_s;
  int capture_steps;
};

/// The steps the Pdr has emitted inside the span the capture counts.
int steps_in_span(Pdr& pdr, const CapturedWalk& w) {
  int n = 0;
  for (const PdrStep& st : pdr.take_steps())
    if (st.t_ns >= s_to_ns(w.from_s) && st.t_ns <= s_to_ns(w.to_s)) ++n;
  return n;
}

/// Walking direction (phone axes) of the longest placement bout after feeding the recording up
/// to until_s (the walker lowers the phone at the very end of some recordings).
PlacementBout longest_bout(const Recording& r, bool with_gyro, double until_s = 110.0,
                           double rotation_axis_max_ratio = PlacementOptions{}.rotation_axis_max_ratio,
                           double step_band_q = PlacementOptions{}.step_band_q, bool with_mag = false,
                           double mag_rate_lowpass_hz = PlacementOptions{}.mag_rate_lowpass_hz) {
  PdrOptions o;
  o.heading.mount = Mount::kAuto;
  o.placement.rotation_axis_max_ratio = rotation_axis_max_ratio;
  o.placement.step_band_q = step_band_q;
  o.placement.mag_rate_lowpass_hz = mag_rate_lowpass_hz;
  Pdr pdr(o);
  feed(pdr, r, with_gyro, s_to_ns(until_s), with_mag);
  PlacementBout best;
  for (const PlacementBout& b : pdr.placements())
    if (b.t_end_ns - b.t_start_ns > best.t_end_ns - best.t_start_ns) best = b;
  return best;
}

/// Angle (deg) between the horizontal parts of two phone-axis directions under "up".
double angle_about_up_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  const Eigen::Vector3d ah = a - a.dot(u) * u, bh = b - b.dot(u) * u;
  return std::atan2(ah.cross(bh).dot(u), ah.dot(bh)) / kDegToRad;
}

struct Case {
  const char* name;
  Eigen::Vector3d truth_forward;  // phone axes, from the motion capture (header)
  Eigen::Vector3d truth_up;       // mean gravity direction (up) in phone axes while walking
  double tolerance_deg;
};

// Tolerances: the estimate's measured error plus ~10-15 deg. Measured: trouser pockets -17..-4
// deg (the perpendicular of the gait rotation axis; the correlation direction alone sits 22-25
// deg to the side), phone at the ear -4..-3 (step band; -6..+10 broadband), swinging hand +1..+15, texting -6..-3. Before
// issue 27 (2 s mean gravity, upright prior -Z): front pocket 158 deg off, phone at the ear
// 94-99 deg, swinging (NoDist) 114 deg.
const Case kCases[] = {
    {"Guillaume_Nexus5_NoDist_FrontPocket", {0.305, -0.247, 0.92}, {0.28, 0.95, 0.16}, 30.0},
    {"Guillaume_Nexus5_Dist_FrontPocket", {0.318, -0.251, 0.914}, {0.28, 0.95, 0.16}, 30.0},
    {"Guillaume_Nexus5_NoDist_BackPocket", {0.376, -0.388, -0.842}, {0.13, 0.92, -0.37}, 30.0},
    {"Guillaume_Nexus5_Dist_BackPocket", {0.381, -0.409, -0.829}, {0.2, 0.91, -0.36}, 30.0},
    {"Guillaume_Nexus5_NoDist_Phoning", {0.861, -0.504, 0.069}, {0.49, 0.8, -0.35}, 25.0},
    {"Guillaume_Nexus5_Dist_Phoning", {0.89, -0.433, 0.143}, {0.45, 0.79, -0.41}, 25.0},
    {"Guillaume_Nexus5_NoDist_Swinging", {-0.921, 0.039, 0.387}, {0.11, -0.93, 0.35}, 25.0},
    {"Guillaume_Nexus5_Dist_Swinging", {-0.107, 0.992, -0.067}, {-0.99, -0.11, -0.03}, 25.0},
    {"Guillaume_Nexus5_NoDist_Texting", {-0.105, 0.993, -0.057}, {-0.07, 0.05, 1.0}, 20.0},
    {"Guillaume_Nexus5_Dist_Texting", {-0.051, 0.997, -0.051}, {-0.08, 0.05, 1.0}, 20.0},
};

}  // namespace

TEST(PdrCarryDirection, WalkingDirectionInEveryCarryMatchesTheMotionCapture) {
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.name);
    const Recording r = read_tyrex(c.name);
    const PlacementBout b = longest_bout(r, true);
    ASSERT_GT(ns_to_s(b.t_end_ns - b.t_start_ns), 20.0);  // one carry for a good part of the walk
    const double err = angle_about_up_deg(c.truth_forward, b.forward_phone, c.truth_up);
    std::printf("%-38s %-8s forward (%.2f %.2f %.2f) error %+6.1f deg\n", c.name, to_string(b.placement),
                b.forward_phone.x(), b.forward_phone.y(), b.forward_phone.z(), err);
    EXPECT_LT(std::abs(err), c.tolerance_deg);
  }
}

TEST(PdrCarryDirection, WithoutTheGyroscopeAPocketWalkIsNotLevelled) {
  // The same front-pocket walk without gyroscope samples: the vertical/horizontal split falls back
  // to the 2 s mean of the accelerometer, where the thigh's tilt leaks gravity into the
  // horizontal acceleration; the direction found is then far from the truth (it was 158 deg off
  // before issue 27). This is the tilt filter's contribution, measured on the same data.
  const Case& c = kCases[0];
  const Recording r = read_tyrex(c.name);
  const double with = angle_about_up_deg(c.truth_forward, longest_bout(r, true).forward_phone, c.truth_up);
  const double without = angle_about_up_deg(c.truth_forward, longest_bout(r, false).forward_phone, c.truth_up);
  std::printf("front pocket: error %+.1f deg levelled, %+.1f deg with the 2 s mean\n", with, without);
  EXPECT_LT(std::abs(with), 40.0);
  EXPECT_GT(std::abs(without), 60.0);
}

TEST(PdrCarryDirection, WithoutTheGyroscopeTheMagnetometersTurningLevelsTheLimbCarries) {
  // A phone without a gyroscope (accelerometer + magnetometer): the field's turning in phone
  // axes stands in for the angular rate (PlacementOptions::mag_rate_lowpass_hz), so the pockets
  // and the swinging hand are levelled and their gait rotation axis is read as with a gyroscope.
  // Measured per recording, with / without the magnetometer's rate (the 2 s mean), deg: front
  // pockets -7.5 / -9.1 vs +158.8 / +157.9 (reversed), back pockets -15.9 / -5.1 vs +25.2 /
  // +27.4, swinging hand +19.6 / +4.0 vs -14.6 / +15.4; the pockets are held to the gyroscope's
  // tolerances, the six together to half the error without.
  double with_sum = 0.0, without_sum = 0.0;
  for (int i = 0; i < 8; ++i) {
    const Case& c = kCases[i];
    if (i == 4 || i == 5) continue;  // at the ear: no limb swing to level
    SCOPED_TRACE(c.name);
    const Recording r = read_tyrex(c.name);
    const PlacementOptions d;
    const PlacementBout with_rate = longest_bout(r, false, 110.0, d.rotation_axis_max_ratio, d.step_band_q, true);
    const PlacementBout without_rate =
        longest_bout(r, false, 110.0, d.rotation_axis_max_ratio, d.step_band_q, true, 0.0);
    const double with = angle_about_up_deg(c.truth_forward, with_rate.forward_phone, c.truth_up);
    const double without = angle_about_up_deg(c.truth_forward, without_rate.forward_phone, c.truth_up);
    std::printf("%-38s error %+6.1f deg with the magnetometer's rate (tilt swing %.1f deg), %+6.1f deg without\n",
                c.name, with, with_rate.tilt_swing_deg, without);
    EXPECT_TRUE(std::isfinite(with_rate.tilt_swing_deg));  // levelled
    EXPECT_FALSE(std::isfinite(without_rate.tilt_swing_deg));
    if (i < 4) EXPECT_LT(std::abs(with), c.tolerance_deg);  // pockets
    with_sum += std::abs(with);
    without_sum += std::abs(without);
  }
  EXPECT_LT(with_sum, 0.5 * without_sum);
}

TEST(PdrCarryDirection, InTrouserPocketsTheGaitRotationAxisBeatsTheCorrelationDirection) {
  // The four pocket recordings, once with the rotation axis (default) and once with the lagged
  // correlation vector alone (rotation_axis_max_ratio = 0): the thigh swings about the body's
  // medio-lateral axis, and the walking direction is square to it. Measured: mean |error| 10.4
  // deg with the axis (-11, -17, -10, -4), 23.2 deg without (+25, -22, -23, -23, the second being the
  // upright prior that the axis replaces).
  double with_sum = 0.0, without_sum = 0.0;
  for (int i = 0; i < 4; ++i) {
    const Case& c = kCases[i];
    SCOPED_TRACE(c.name);
    const Recording r = read_tyrex(c.name);
    const double with = angle_about_up_deg(c.truth_forward, longest_bout(r, true).forward_phone, c.truth_up);
    const double without =
        angle_about_up_deg(c.truth_forward, longest_bout(r, true, 110.0, 0.0).forward_phone, c.truth_up);
    std::printf("%-38s error %+6.1f deg with the rotation axis, %+6.1f deg with the correlation alone\n", c.name,
                with, without);
    EXPECT_LT(std::abs(with), 20.0);
    with_sum += std::abs(with);
    without_sum += std::abs(without);
  }
  EXPECT_LT(with_sum / 4.0, 14.0);
  EXPECT_LT(with_sum, 0.7 * without_sum);
}

TEST(PdrMotion, ARunThatTurnsIsNotHandling) {
  // The two TYREX runs (hand, pocket; ~310 steps each in a 5 x 5 m room): at every turn the foot
  // strikes lose their 4 s periodicity for a few seconds while the phone keeps turning at 3-7
  // rad/s in the gait's rhythm. Once the run is established it lasts while that rhythm does
  // (MotionClassifier: hysteresis on the strikes' periodicity, the hold after it as for
  // handling). Measured, accelerometer + gyroscope as here: refused as handling 17 + 22 steps
  // before (the run dropped to handling whenever the strikes' periodicity dipped), 6 + 14 now.
  // Steps against the capture's count over the span it counts: before a single stride-like
  // interval of a run was split (StepDetectorOptions::running_single_stride) 268 / 266
  // (-14.4 / -14.5 %), now within 10 %.
  const CapturedWalk runs[] = {{"Guillaume_Nexus5_NoDist_RunningHand", 6.67, 121.17, 313},
                               {"Guillaume_Nexus5_NoDist_RunningPocket", 6.29, 120.79, 311}};
  std::int64_t refused = 0;
  for (const CapturedWalk& run : runs) {
    SCOPED_TRACE(run.name);
    const auto pdr = replayed(run.name);
    const PdrCounters c = pdr->counters();
    const int in_span = steps_in_span(*pdr, run);
    const double err_pct = 100.0 * (in_span - run.capture_steps) / run.capture_steps;
    std::printf("%-38s steps in the capture's span %d of %d (%+.1f %%), refused as handling %lld\n", run.name,
                in_span, run.capture_steps, err_pct, static_cast<long long>(c.steps_discarded_by_motion));
    refused += c.steps_discarded_by_motion;
    EXPECT_LE(std::abs(err_pct), 10.0);
  }
  EXPECT_LE(refused, 25);
}

TEST(PdrSteps, TheSwingOfAStrideIsReadFromTheGyroscope) {
  // A stride is split only when the phone swings at 1/I (stage 4). A phone in a swinging hand is
  // a pendulum: its specific force stays along the arm, so the accelerometer's tilt moves a few
  // degrees while the phone turns +-15-25 deg; a phone held flat for texting sways those same
  // few degrees at every step of a slow walk. The angular rate tells them apart. TYREX, steps
  // over the capture's span (texting 103 / 109, swinging with magnets 169).
  const auto run = [](const CapturedWalk& w, double min_rotation_radps, std::int64_t* added) {
    PdrOptions o;
    o.detector.stride_min_rotation_radps = min_rotation_radps;
    const auto pdr = replayed(w.name, o);
    *added = pdr->counters().steps_added_at_stride_midpoints;
    const int in_span = steps_in_span(*pdr, w);
    std::printf("%-36s rotation test %s: %lld steps added at stride midpoints, %d of %d steps\n", w.name,
                min_rotation_radps > 0.0 ? "on " : "off", static_cast<long long>(*added), in_span, w.capture_steps);
    return in_span;
  };
  // Texting (flat, 1.1-1.15 steps/s): the tilt test split 18 and 10 "strides" of 0.8-0.95 s,
  // i.e. single steps (Dist: 107 steps, 99 before the capture's aperiodic windows were counted); the gyroscope splits none.
  for (const CapturedWalk& w : {CapturedWalk{"Guillaume_Nexus5_Dist_Texting", 7.09, 121.59, 103},
                                CapturedWalk{"Guillaume_Nexus5_NoDist_Texting", 7.46, 121.96, 109}}) {
    SCOPED_TRACE(w.name);
    std::int64_t added_tilt = 0, added_gyro = 0;
    run(w, 0.0, &added_tilt);
    run(w, StepDetectorOptions{}.stride_min_rotation_radps, &added_gyro);
    EXPECT_GE(added_tilt, 8);
    EXPECT_EQ(added_gyro, 0);
  }
  // Swinging hand with magnets: one crossing per stride of 1.3-1.5 s for seconds at a time; the
  // tilt test split 9 of them (139 steps), the gyroscope 26 (159 steps; 15 and 145 before a
  // single stride of the bout's cadence was split, the test below).
  const CapturedWalk swing{"Guillaume_Nexus5_Dist_Swinging", 6.44, 120.94, 169};
  std::int64_t added_tilt = 0, added_gyro = 0;
  const int steps_tilt = run(swing, 0.0, &added_tilt);
  const int steps_gyro = run(swing, StepDetectorOptions{}.stride_min_rotation_radps, &added_gyro);
  EXPECT_GT(added_gyro, added_tilt);
  EXPECT_GT(steps_gyro, steps_tilt);
  EXPECT_LE(steps_gyro, swing.capture_steps);
}

TEST(PdrSteps, WithoutAGyroscopeTheSwingOfAStrideIsReadFromTheMagnetometer) {
  // The test above on a phone without a gyroscope: the magnetometer's turning stands in for the
  // angular rate (PlacementOptions::mag_rate_lowpass_hz), so the texting phone's sway no longer
  // splits its steps. Measured, steps added at stride midpoints with / without the magnetometer's
  // rate: texting with magnets 4 / 17 (107 / 118 steps of the capture's 103), without magnets
  // 0 / 10 (85 / 95 of 109: there the false splits had stood in for gentle steps the detector
  // misses, as with the gyroscope: 87).
  for (const CapturedWalk& w : {CapturedWalk{"Guillaume_Nexus5_Dist_Texting", 7.09, 121.59, 103},
                                CapturedWalk{"Guillaume_Nexus5_NoDist_Texting", 7.46, 121.96, 109}}) {
    SCOPED_TRACE(w.name);
    PdrOptions off;
    off.placement.mag_rate_lowpass_hz = 0.0;
    const auto with = replayed(w.name, {}, true);
    const auto without = replayed(w.name, off, true);
    const std::int64_t added_with = with->counters().steps_added_at_stride_midpoints;
    const std::int64_t added_without = without->counters().steps_added_at_stride_midpoints;
    std::printf("%-36s accel + mag: %lld steps added at stride midpoints with the magnetometer's rate (%d of %d "
                "steps), %lld without (%d)\n",
                w.name, static_cast<long long>(added_with), steps_in_span(*with, w), w.capture_steps,
                static_cast<long long>(added_without), steps_in_span(*without, w));
    EXPECT_GE(added_without, 8);
    EXPECT_LE(2 * added_with, added_without);
  }
}

TEST(PdrSteps, AStrideOfTheBoutsOwnCadenceHoldsTheStepItMissed) {
  // Swinging hand with magnets (capture: 169 steps at 1.46 steps/s, cross-checks 163 / 160):
  // in a steady bout of ~0.69 s steps the weak heel strike of one arm is missed now and then,
  // leaving single intervals of 1.2-1.4 s. One such interval alone was not split (it might be a
  // pause); when it is twice the bout's running interval (StepDetectorOptions::
  // walking_single_stride_tol) and passes the stride tests (step power in |a|, the phone
  // swinging at 1/I), it holds a step. Measured: 145 of 169 (-14.2 %) -> 159 (-5.9 %).
  const CapturedWalk swing{"Guillaume_Nexus5_Dist_Swinging", 6.44, 120.94, 169};
  PdrOptions off;
  off.detector.walking_single_stride_tol = 0.0;
  const auto with = replayed(swing.name);
  const auto without = replayed(swing.name, off);
  const int n_with = steps_in_span(*with, swing), n_without = steps_in_span(*without, swing);
  std::printf("%s: %d steps with single strides of the bout's cadence split, %d without (capture %d)\n", swing.name,
              n_with, n_without, swing.capture_steps);
  EXPECT_LT(n_without, 0.9 * swing.capture_steps);  // the defect
  EXPECT_GE(n_with, 0.9 * swing.capture_steps);
  EXPECT_LE(n_with, 1.1 * swing.capture_steps);
}

TEST(PdrSteps, GentleStepsAreCountedFromTheForwardAcceleration) {
  // A slow shuffle with the phone held in front (texting) or at the ear (phoning) moves |a| by
  // less than the walking gate (sigma 0.1-0.3 m/s^2 over 1.5 s) while the phone's forward
  // acceleration still swings +-0.4-0.8 m/s^2 once a step (Zijlstra & Hof 2003). The forward
  // channel (PdrOptions::forward_steps) counts those steps while |a| is below its gate; where both
  // channels see a step, it is counted once. TYREX, steps over the capture's span.
  const auto count = [](const CapturedWalk& w, bool forward) {
    PdrOptions o;
    o.forward_steps = forward;
    const auto pdr = replayed(w.name, o);
    const std::int64_t from_forward = pdr->counters().forward_channel_candidates;
    const int n = steps_in_span(*pdr, w);
    std::printf("%-34s forward channel %s: %d of %d steps (%lld candidates from it)\n", w.name, forward ? "on " : "off", n,
                w.capture_steps, static_cast<long long>(from_forward));
    return n;
  };
  for (const CapturedWalk& w : {CapturedWalk{"Guillaume_Nexus5_Dist_Texting", 7.09, 121.59, 103},
                                CapturedWalk{"Guillaume_Nexus5_Dist_Phoning", 6.19, 120.69, 107}}) {
    SCOPED_TRACE(w.name);
    const int off = count(w, false), on = count(w, true);
    EXPECT_LT(off, 0.9 * w.capture_steps);  // the defect: gentle steps under the gate
    EXPECT_GE(on, 0.9 * w.capture_steps);
    EXPECT_LE(on, 1.1 * w.capture_steps);   // not counted twice where both channels see a step
  }
  // Without magnets the texting walk has longer gentle stretches (cross-checks of the capture's
  // count 107 / 112): still short, but by fewer steps.
  const CapturedWalk texting{"Guillaume_Nexus5_NoDist_Texting", 7.46, 121.96, 109};
  const int off = count(texting, false), on = count(texting, true);
  EXPECT_GE(on, off + 8);
  EXPECT_LE(on, 1.1 * texting.capture_steps);
}

/// The recording's streams as one sample list, and back.
std::vector<Sample> samples_of(const Recording& r) {
  std::vector<Sample> all;
  all.reserve(r.accel.size() + r.gyro.size() + r.mag.size());
  for (const AccelSample& a : r.accel) all.emplace_back(a);
  for (const GyroSample& g : r.gyro) all.emplace_back(g);
  for (const MagSample& m : r.mag) all.emplace_back(m);
  return all;
}
Recording recording_of(const std::vector<Sample>& samples) {
  Recording out;
  for (const Sample& s : samples) {
    if (const auto* a = std::get_if<AccelSample>(&s)) out.accel.push_back(*a);
    else if (const auto* g = std::get_if<GyroSample>(&s)) out.gyro.push_back(*g);
    else if (const auto* m = std::get_if<MagSample>(&s)) out.mag.push_back(*m);
  }
  return out;
}

/// The recording as a phone sampling its motion sensors at rate_hz would give it: what
/// `pdnav eval-pdr --rate` replays (phonesim::at_sample_rate, the sensor's own block average
/// before decimation).
Recording at_rate(const Recording& r, double rate_hz) { return recording_of(phonesim::at_sample_rate(samples_of(r), rate_hz)); }

TEST(PdrSteps, TheSameWalkCountsTheSameStepsAtAnyAccelerometerRate) {
  // The detector low-passes |a| (StepDetectorOptions::lowpass_hz). Its former discretisation,
  // alpha = dt / (tau + dt), put the cut-off of a nominal 3 Hz at 2.86 Hz at 200 Hz and 2.55 Hz
  // at 50 Hz, and the gentle steps of a slow walk hang on it: these recordings at 200 Hz and
  // block-averaged to 50 Hz (what a phone at SENSOR_DELAY_GAME, Sensor Logger's default, gives)
  // counted 74 / 62, 80 / 72 and 102 / 86 steps (accelerometer and gyroscope, this cut-off; 50 Hz
  // as averages of every 4 samples). Now alpha = 1 - exp(-dt / tau): 80 / 83, 85 / 83, 105 / 103
  // (50 Hz on eval-pdr --rate's time grid, phonesim::at_sample_rate).
  for (const CapturedWalk& w : {CapturedWalk{"Guillaume_Nexus5_NoDist_Phoning", 6.86, 121.36, 102},
                                CapturedWalk{"Guillaume_Nexus5_NoDist_Texting", 7.46, 121.96, 109},
                                CapturedWalk{"Guillaume_Nexus5_Dist_Texting", 7.09, 121.59, 103}}) {
    SCOPED_TRACE(w.name);
    const Recording r200 = read_tyrex(w.name);
    const Recording r50 = at_rate(r200, 50.0);
    PdrOptions o;
    o.heading.mount = Mount::kAuto;
    Pdr at200(o), at50(o);
    feed(at200, r200, true);
    feed(at50, r50, true);
    at200.finish();
    at50.finish();
    const int n200 = steps_in_span(at200, w), n50 = steps_in_span(at50, w);
    std::printf("%-34s steps at 200 Hz %d, at 50 Hz %d (capture %d)\n", w.name, n200, n50, w.capture_steps);
    EXPECT_NEAR(n50, n200, 0.05 * n200);
  }
}

TEST(PdrDirection, AStepTakenBeforeItsBoutBeganWaitsForThatBoutsDirection) {
  // A handling ends the placement bout; the steps taken after it, before the next bout's gravity
  // is known, belong to the next bout (Pdr::hold). They used to go out at once with the previous
  // bout's walking direction: on the pocket run the phone turned in the pocket (handling, 74.8 s),
  // and four steps left 110-130 deg off, moving the track 8 m (final error 12.6 -> 9.8 m,
  // eval-pdr). Now they wait for their bout's direction like the bout's own first steps.
  const char* const names[] = {"Guillaume_Nexus5_NoDist_RunningPocket", "Guillaume_Nexus5_NoDist_RunningHand",
                               "Guillaume_Nexus5_NoDist_BackPocket", "Guillaume_Nexus5_Dist_Phoning"};
  for (const char* name : names) {
    SCOPED_TRACE(name);
    const auto pdr = replayed(name);
    const PdrCounters c = pdr->counters();
    std::printf("%-38s %zu steps, %lld out before their bout's direction, longest wait %.2f s\n", name,
                pdr->take_steps().size(), static_cast<long long>(c.steps_before_their_bouts_direction),
                c.max_step_delay_s);
    EXPECT_EQ(c.steps_before_their_bouts_direction, 0);
    EXPECT_LE(c.max_step_delay_s, PlacementOptions{}.max_direction_wait_s + 0.5);  // the wait stays bounded
  }
}

TEST(PdrVehicle, AWalkerHoldingThePhoneUpIsNotInAVehicle) {
  // The held-up phone ("AR", no magnets): a slow shuffle (0.1-0.5 m/s, 42 captured steps in
  // 115 s) while the phone is turned about in the hand, |a| aperiodic at +-0.3 m/s^2 and turning
  // slower than 0.4 rad/s: the vibration evidence alone reaches the vehicle score (at 20 s) and
  // the gait exit never comes, so every step was refused. A vehicle must also change speed or
  // turn as no walker does (MotionClassifierOptions::kinematic_min_mps2, Hemminki et al. 2013);
  // here the sustained horizontal acceleration peaks at 0.73 m/s^2 (accelerometer bias and
  // scale leaking as the phone turns), the synthesised rides reach 1.0-1.8 (vehicle_test.cpp;
  // printed there as the peak before each is classed, 0.9-1.0).
  const char* name = "Guillaume_Nexus5_NoDist_AR";
  const auto pdr = replayed(name);
  const PdrCounters c = pdr->counters();
  std::printf("%s: %lld steps, %zu vehicle spans, score max %.2f s, kinematic max %.2f m/s^2\n", name,
              static_cast<long long>(pdr->step_count()), pdr->vehicle_spans().size(), c.vehicle_max_score_s,
              c.vehicle_kinematic_max_mps2);
  EXPECT_TRUE(pdr->vehicle_spans().empty());
  EXPECT_EQ(c.steps_discarded_by_vehicle, 0);
  EXPECT_GE(pdr->step_count(), 10);
  EXPECT_LT(c.vehicle_kinematic_max_mps2, MotionClassifierOptions{}.kinematic_min_mps2);
  EXPECT_GE(c.vehicle_max_score_s, MotionClassifierOptions{}.vehicle_enter_s);  // the score alone would say vehicle
  // control: without the kinematic evidence the same walk is a ride
  PdrOptions o;
  o.motion.kinematic_min_mps2 = 0.0;
  const auto without = replayed(name, o);
  std::printf("  without the kinematic evidence: %lld steps, %zu vehicle spans\n",
              static_cast<long long>(without->step_count()), without->vehicle_spans().size());
  EXPECT_FALSE(without->vehicle_spans().empty());
  EXPECT_LT(without->step_count(), pdr->step_count());
}

TEST(PdrVehicle, NoMotionCaptureRecordingIsARide) {
  // every carry, running included, with and without magnets: no vehicle span, no step refused
  // as riding (the ILC, Oxford and ETH walks: vehicle_test.cpp); also from the accelerometer
  // alone (a phone without a gyroscope), where the vibration score took the slow shuffles for
  // rides from start to end (texting with magnets: 77 of its steps refused) and no kinematic
  // evidence can be had
  const char* names[] = {"Guillaume_Nexus5_Dist_AR", "Guillaume_Nexus5_Dist_BackPocket", "Guillaume_Nexus5_Dist_FrontPocket",
                         "Guillaume_Nexus5_Dist_Phoning", "Guillaume_Nexus5_Dist_Swinging", "Guillaume_Nexus5_Dist_Texting",
                         "Guillaume_Nexus5_NoDist_AR", "Guillaume_Nexus5_NoDist_BackPocket", "Guillaume_Nexus5_NoDist_FrontPocket",
                         "Guillaume_Nexus5_NoDist_Phoning", "Guillaume_Nexus5_NoDist_RunningHand",
                         "Guillaume_Nexus5_NoDist_RunningPocket", "Guillaume_Nexus5_NoDist_Swinging", "Guillaume_Nexus5_NoDist_Texting"};
  int accel_only_above_score = 0;
  for (const char* name : names) {
    const auto pdr = replayed(name);
    const PdrCounters c = pdr->counters();
    std::printf("%-40s score max %5.2f s, kinematic max %.2f m/s^2\n", name, c.vehicle_max_score_s, c.vehicle_kinematic_max_mps2);
    EXPECT_TRUE(pdr->vehicle_spans().empty()) << name;
    EXPECT_EQ(c.steps_discarded_by_vehicle, 0) << name;
    PdrOptions o;
    o.heading.mount = Mount::kAuto;
    Pdr accel_only(o);
    feed(accel_only, read_tyrex(name), false);
    accel_only.finish();
    const PdrCounters ca = accel_only.counters();
    std::printf("%-40s accelerometer only: score max %5.2f s\n", "", ca.vehicle_max_score_s);
    EXPECT_TRUE(accel_only.vehicle_spans().empty()) << name << " (accelerometer only)";
    EXPECT_EQ(ca.steps_discarded_by_vehicle, 0) << name << " (accelerometer only)";
    accel_only_above_score += ca.vehicle_max_score_s >= MotionClassifierOptions{}.vehicle_enter_s;
  }
  // the case is real: several recordings reach the vibration score without a gyroscope
  EXPECT_GE(accel_only_above_score, 3);
}

TEST(PdrCarryDirection, AtTheEarTheStepBandHoldsTheWalkingDirectionThroughTheWalk) {
  // The phone at the ear has no dominant gait rotation axis (head motion): its walking direction
  // is the lagged vertical-horizontal correlation itself. Broadband (0.6 Hz high-pass), the
  // head's medio-lateral sway at the stride frequency enters it and the direction wanders by
  // tens of degrees as the walk goes on; about the step frequency (PlacementOptions::step_band_q,
  // Kourogi & Kurata 2014) only the anterior-posterior part, which leads the vertical, remains.
  // The direction of the open bout every 10 s from 25 to 105 s against the capture's.
  for (int i : {4, 5}) {
    const Case& c = kCases[i];
    SCOPED_TRACE(c.name);
    const Recording r = read_tyrex(c.name);
    double band_max = 0.0, band_sum = 0.0, broad_sum = 0.0;
    int n = 0;
    for (double until_s = 25.0; until_s <= 105.0; until_s += 10.0, ++n) {
      const PlacementOptions def;
      const double band = angle_about_up_deg(c.truth_forward, longest_bout(r, true, until_s).forward_phone, c.truth_up);
      const double broad = angle_about_up_deg(
          c.truth_forward, longest_bout(r, true, until_s, def.rotation_axis_max_ratio, 0.0).forward_phone, c.truth_up);
      std::printf("%-32s %5.0f s: error %+6.1f deg in the step band, %+6.1f deg broadband\n", c.name, until_s, band,
                  broad);
      band_max = std::max(band_max, std::abs(band));
      band_sum += std::abs(band);
      broad_sum += std::abs(broad);
    }
    std::printf("%-32s mean |error| %.1f deg in the step band, %.1f deg broadband\n", c.name, band_sum / n, broad_sum / n);
    EXPECT_LT(band_max, 20.0);
    EXPECT_LT(band_sum, 0.6 * broad_sum);
  }
}

TEST(PdrCarryDirection, StepsOutBeforeTheirDirectionIsDecidedSaySo) {
  // The running pocket with its magnetometer (a compass heading, so the steps' heading sigma is
  // the fusion's few degrees): twice the phone settles in the pocket after the run has begun,
  // and steps wait max_direction_wait_s for the bout's direction in vain. They go out with the
  // prior axis, and their heading sigma is the undecided direction's
  // (PlacementOptions::undecided_direction_sigma_rad); every other step keeps the heading's own.
  const std::string name = "Guillaume_Nexus5_NoDist_RunningPocket";
  const Recording r = read_tyrex(name);
  std::vector<MagSample> mag;
  read_txyz(pdnav::test::shared_data("pdr-tyrex-guillaume/datasets/android/" + name) + "/magnetometer-calibrated.txt",
            [&](TimeNs t, const Eigen::Vector3d& v) { mag.push_back({t, kMissingInt, v}); });
  PdrOptions o;
  o.heading.mount = Mount::kAuto;
  Pdr pdr(o);
  std::size_t g = 0, m = 0;
  for (const auto& a : r.accel) {
    while (g < r.gyro.size() && r.gyro[g].t_ns <= a.t_ns) pdr.feed(r.gyro[g++]);
    while (m < mag.size() && mag[m].t_ns <= a.t_ns) pdr.feed(mag[m++]);
    pdr.feed(a);
  }
  pdr.finish();
  const double undecided = PlacementOptions{}.undecided_direction_sigma_rad;
  int wide = 0, total = 0;
  double max_other_deg = 0.0;
  for (const PdrStep& st : pdr.take_steps()) {
    ++total;
    if (st.heading_sigma_rad >= undecided) ++wide;
    else max_other_deg = std::max(max_other_deg, st.heading_sigma_rad / kDegToRad);
  }
  const std::int64_t counted = pdr.counters().steps_with_undecided_direction;
  std::printf("running pocket: %d of %d steps out with an undecided direction (counter %lld); the others' heading "
              "sigma at most %.1f deg\n", wide, total, static_cast<long long>(counted), max_other_deg);
  EXPECT_EQ(wide, counted);
  EXPECT_GE(counted, 5);
  EXPECT_LT(counted, total / 5);
  EXPECT_LT(max_other_deg, 45.0);
}

namespace {
/// The recording taken k times faster (phonesim::at_walk_speed, eval-pdr --speed), and the
/// capture's span moved with it.
Recording at_speed(const Recording& r, double k, CapturedWalk* span) {
  const std::vector<Sample> all = samples_of(r);
  TimeNs t0 = std::numeric_limits<TimeNs>::max();
  for (const Sample& s : all) t0 = std::min(t0, sample_time_ns(s));
  const double t0_s = ns_to_s(t0);
  span->from_s = t0_s + (span->from_s - t0_s) / k;
  span->to_s = t0_s + (span->to_s - t0_s) / k;
  return recording_of(phonesim::at_walk_speed(all, k));
}
}  // namespace

TEST(PdrSteps, ARunFasterThanThreeStepsASecondStillCountsItsSteps) {
  // The shared runs are at 2.7 steps/s; issue 27 asks for cadences up to 3.3. Taken 1.2 times
  // faster (3.26 steps/s), the hand run's level crossings skip runs of steps: the detector's
  // 2.75 Hz low-pass leaves the arm swing, at the stride, over the steps. Running, an interval
  // of n steps of the run's own period (half the stride lag of |a|'s autocorrelation) holds the
  // n - 1 steps missed (StepDetectorOptions::running_period_window_s). As recorded it adds 3
  // steps (295 -> 298 of 313 in eval-pdr); faster, 231 -> 263 (the capture: 313).
  const CapturedWalk hand{"Guillaume_Nexus5_NoDist_RunningHand", 6.67, 121.17, 313};
  const Recording recorded = read_tyrex(hand.name);
  CapturedWalk fast_span = hand;
  const Recording fast = at_speed(recorded, 1.2, &fast_span);
  PdrOptions with;
  with.heading.mount = Mount::kAuto;
  PdrOptions without = with;
  without.detector.running_period_window_s = 0.0;
  const auto count = [](const PdrOptions& o, const Recording& r, const CapturedWalk& span) {
    Pdr pdr(o);
    feed(pdr, r, true);
    pdr.finish();
    return steps_in_span(pdr, span);
  };
  const int as_recorded = count(with, recorded, hand), as_recorded_without = count(without, recorded, hand);
  const int faster = count(with, fast, fast_span), faster_without = count(without, fast, fast_span);
  std::printf("running hand, steps in the capture's span (%d): as recorded %d (without the run's period %d), "
              "1.2 x faster %d (%d)\n", hand.capture_steps, as_recorded, as_recorded_without, faster, faster_without);
  EXPECT_GE(faster, faster_without + 0.06 * hand.capture_steps);
  EXPECT_GE(faster, 0.80 * hand.capture_steps);
  EXPECT_GE(as_recorded, as_recorded_without);
  EXPECT_LE(as_recorded, 1.03 * hand.capture_steps);  // the filled steps do not count steps twice
}
