// Two cascaded first-order low-pass sections (internal to pdr/): the step detector's |a| and
// tilt, and the placement's field direction.
#pragma once
#include <cmath>

#include "pdnav/geo/units.h"

namespace pdnav::pdr::detail {

/// Gain of a first-order section with cut-off `cutoff_hz` over a sample step of dt_s, exact for an
/// input held over the step (1 - exp(-dt / tau)): the cut-off does not move with the sampling rate.
inline double lowpass_gain(double dt_s, double cutoff_hz) { return 1.0 - std::exp(-2.0 * kPi * cutoff_hz * dt_s); }

/// One sample through two cascaded sections of gain `gain` (state y1, y2); returns the output y2.
template <typename T>
const T& lowpass2(T& y1, T& y2, const T& x, double gain) {
  y1 += gain * (x - y1);
  y2 += gain * (y1 - y2);
  return y2;
}

}  // namespace pdnav::pdr::detail
