// A real recording as a phone sampling its motion sensors at a lower rate would have given it
// (issue 27 "every phone": 200 Hz captures replayed at 100 / 50 / 25 Hz). No file I/O.
#pragma once
#include <vector>

#include "pdnav/geo/samples.h"

namespace pdnav::phonesim {

/// Each accelerometer, gyroscope and magnetometer stream (and their uncalibrated twins, bias
/// and drift included) averaged over consecutive blocks of 1 / rate_hz s on a fixed grid from
/// the stream's first sample, each block stamped with its last sample's time: an output data
/// rate with its anti-alias averaging, what a sensor hub delivers at a lower rate. Rotation
/// vectors and orientation angles keep the last sample of each block; every other sample as
/// recorded. A non-finite reading is left out of its block's average (a block of only such
/// readings is dropped); a bias / drift the recording does not state (NaN) stays NaN, the
/// reading averaged. A stream below the rate keeps every sample (one at the rate keeps
/// them too unless jitter puts two in one cell of the grid, which are then averaged). The
/// result is in time order (stable). rate_hz in (0, 1e9], else std::invalid_argument.
std::vector<Sample> at_sample_rate(const std::vector<Sample>& in, double rate_hz);

}  // namespace pdnav::phonesim
