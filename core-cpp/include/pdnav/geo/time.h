// GNSS time scales. GPS time (GPST) counts SI seconds from 1980-01-06 00:00:00 UTC with no
// leap seconds; UTC = GPST - leap seconds (18 s since 2017-01-01, IERS Bulletin C).
// Galileo System Time is aligned to GPST; BeiDou Time = GPST - 14 s (BDS-SIS-ICD-B1I 5.1.2);
// GLONASS time = UTC(SU) + 3 h (GLONASS ICD 3.3.3).
#pragma once
#include <cstdint>

#include "pdnav/geo/units.h"

namespace pdnav::geo {

inline constexpr std::int64_t kSecondsPerWeek = 604800;
inline constexpr std::int64_t kSecondsPerDay = 86400;
inline constexpr TimeNs kNsPerWeek = kSecondsPerWeek * kNsPerS;
inline constexpr TimeNs kNsPerDay = kSecondsPerDay * kNsPerS;
/// Unix time (ms) of the GPS epoch 1980-01-06T00:00:00Z.
inline constexpr std::int64_t kGpsEpochUnixMs = 315964800000;
/// BeiDou Time epoch (2006-01-01) minus GPS epoch, in GPS seconds: 1356 weeks + 14 s.
inline constexpr std::int64_t kBdsEpochMinusGpsEpochS = 1356 * kSecondsPerWeek + 14;

/// GPS-UTC leap seconds in force at a UTC instant (Unix ms); table from IERS Bulletin C
/// (1980-2017; no leap second has been announced since). Before 1980-01-06 returns 0.
int leap_seconds_at_unix_ms(std::int64_t unix_ms);
/// Same, for an instant given in GPS time (ns since the GPS epoch).
int leap_seconds_at_gps_ns(TimeNs gps_ns);

/// GPS time (ns since GPS epoch) <-> Unix time (ms, UTC).
std::int64_t gps_ns_to_unix_ms(TimeNs gps_ns);
TimeNs unix_ms_to_gps_ns(std::int64_t unix_ms);

struct GpsWeekTow {
  int week = 0;         // full week number (no 1024 rollover)
  double tow_s = 0.0;   // seconds of week
};
GpsWeekTow gps_ns_to_week_tow(TimeNs gps_ns);
TimeNs week_tow_to_gps_ns(int week, double tow_s);

/// Resolve a 10-bit (mod 1024) GPS week against a reference full week (closest match).
int resolve_week_rollover(int week_mod_1024, int reference_full_week);

/// Civil date-time (UTC or a time scale's own calendar) to seconds since the GPS epoch
/// *in that calendar*, ignoring leap seconds; used by the RINEX readers.
double calendar_to_epoch_seconds(int year, int month, int day, int hour, int minute, double second);

/// Time difference t - t_ref wrapped to (-half_week, half_week]; IS-GPS-200 20.3.3.3.3.1.
double wrap_week_s(double dt_s);

}  // namespace pdnav::geo
