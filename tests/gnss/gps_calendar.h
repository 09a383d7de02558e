// GPS time of a calendar instant, for the RINEX / SP3 / clock tests whose files give epochs as
// GPS calendar dates.
#pragma once
#include <cmath>

#include "pdnav/geo/time.h"

namespace pdnav::test {

/// A GPS-time calendar date and time as ns since the GPS epoch (rounded to the ns).
inline TimeNs gps_calendar_ns(int year, int month, int day, int hour, int minute, double second) {
  return static_cast<TimeNs>(std::llround(geo::calendar_to_epoch_seconds(year, month, day, hour, minute, second) * 1e9));
}

}  // namespace pdnav::test
