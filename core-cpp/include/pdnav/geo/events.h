// What passes between engines: small plain structs, no engine implementation behind them.
#pragma once
#include "pdnav/geo/units.h"

namespace pdnav {

/// One detected step with its length and heading (PDR output; terrain/route input).
struct PdrStep {
  TimeNs t_ns = 0;
  double length_m = 0.0;
  double heading_rad = 0.0;        // true-north heading, clockwise from north, in [0, 2pi)
  double heading_sigma_rad = 0.0;  // 1-sigma of heading_rad, NaN/0 when unknown
  double length_sigma_m = 0.0;
};

/// A turn found by the gyro re-orientation (APT Sec. V-B): signed angle about the vertical,
/// positive = left (counter-clockwise seen from above).
struct PdrTurn {
  TimeNs t_ns = 0;        // time the turn completed
  TimeNs start_ns = 0;    // time it began
  double angle_rad = 0.0;
};

/// An absolute position fix used by the route engine and fusion (e.g. a GNSS fix).
struct PositionFix {
  TimeNs t_ns = 0;
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double h_m = 0.0;
  double horizontal_sigma_m = 0.0;  // 1-sigma radius (Android "accuracy" is 68 %)
};

}  // namespace pdnav
