// A real recording as the same walk taken faster (issue 27 "cadence up to 3.3 Hz": the shared
// runs are at 2.7 steps/s). No file I/O.
#pragma once
#include <vector>

#include "pdnav/geo/samples.h"

namespace pdnav::phonesim {

/// The walk k times faster along the same path, in the same attitudes: every time stamp t
/// becomes t0 + (t - t0) / k (t0 the earliest sample; utc_ms moves with it), so the cadence is
/// k times the recorded one and the step count unchanged. What the phone would read then: the
/// specific force's slow part (gravity and the attitude's slow changes, a zero-phase low-pass
/// at slow_hz of each accelerometer stream) as recorded and the rest (the gait) k^2 times
/// larger, as d^2x/dt^2 of a path taken k times faster; angular rates k times larger (the
/// uncalibrated gyroscope's stated drift unchanged); magnetometer, rotation vectors, pressure,
/// Truth positions unchanged; a Fix's speed k times larger; Meta TruthStepsFromNanos /
/// TruthStepsToNanos moved like the samples and TruthCadenceHz k times larger. GNSS
/// measurement rows (Raw, Nav, Status, AGC) cannot be taken faster and are dropped. A physical
/// model of a faster walker it is not: the steps keep their length (a real walker lengthens
/// them too) and the hand's and the body's motion all speed up alike. k in [0.25, 4] and
/// slow_hz > 0, else std::invalid_argument. The result is in the input's order.
std::vector<Sample> at_walk_speed(const std::vector<Sample>& in, double k, double slow_hz = 0.5);

}  // namespace pdnav::phonesim
