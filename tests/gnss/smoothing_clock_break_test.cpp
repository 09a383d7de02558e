// A hardware clock discontinuity (issue 15: "Doppler-aided code smoothing where the carrier
// phase is ... broken by clock discontinuities"): the carrier phase is lost and the code jumps
// by a common clock step. The smoother keeps every satellite, propagates by Doppler and takes the
// jump with its common-step removal, so the smoothed code stays as quiet as before the break;
// restarting (the behaviour before) gives the raw code noise back.
#include <cmath>
#include <string>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/gnss/solver_smoothing.h"

namespace pdnav::gnss {
namespace {

/// RMS error of the smoothed code over the 9 epochs after a break at epoch 60 (of 70), against
/// the true range plus the clock step, the common part of all satellites removed (a clock term);
/// code noise 3 m white, carrier garbage at the break.
double rms_after_break(bool carrier_broken_path) {
  CodeSmoother sm{SmoothingOptions{}};
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 3.0);
  double sum2 = 0.0;
  int n = 0;
  for (int k = 0; k < 70; ++k) {
    const bool brk = k == 60;
    if (k == 0) sm.begin_epoch(0.0, 0.0);
    else if (brk && carrier_broken_path) sm.begin_epoch(1.0, 0.0, /*carrier_broken=*/true);
    else if (brk) sm.begin_epoch(0.0, 0.0);  // restart, as a gap
    else sm.begin_epoch(1.0, 0.0);
    const double clock_step_m = k >= 60 ? 2.4e4 : 0.0;  // re-set receiver clock (80 us)
    std::vector<SmoothingInput> in;
    std::vector<double> truth;
    for (int i = 0; i < 7; ++i) {
      const double rate = -400.0 + 130.0 * i;
      const double range = 2.1e7 + 1.0e5 * i + rate * k;
      const double adr = brk ? 1.0e6 * (i + 1) : range;  // carrier meaningless at the break
      in.push_back(SmoothingInput{SatId{Constellation::kGps, i + 1}, range + clock_step_m + noise(rng), adr, rate});
      truth.push_back(range + clock_step_m);
    }
    const std::vector<double> out = sm.smooth_epoch(in);
    if (k > 60) {  // a common error of all satellites is a receiver clock term: SPP absorbs it
      double mean = 0.0;
      for (std::size_t i = 0; i < out.size(); ++i) mean += (out[i] - truth[i]) / static_cast<double>(out.size());
      for (std::size_t i = 0; i < out.size(); ++i) {
        sum2 += (out[i] - truth[i] - mean) * (out[i] - truth[i] - mean);
        ++n;
      }
    }
  }
  return std::sqrt(sum2 / n);
}

TEST(SmoothingClockBreak, DopplerKeepsTheSmoothingThroughAHardwareClockDiscontinuity) {
  const double kept = rms_after_break(true);
  const double restarted = rms_after_break(false);
  EXPECT_LT(kept, 0.6) << "smoothed code after the break (code noise 3 m)";
  RecordProperty("kept_rms_m", std::to_string(kept));
  RecordProperty("restarted_rms_m", std::to_string(restarted));
  EXPECT_GT(restarted, 1.0) << "a restart gives back the code noise";
  EXPECT_LT(kept, 0.5 * restarted);
}

}  // namespace
}  // namespace pdnav::gnss
