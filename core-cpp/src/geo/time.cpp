#include "pdnav/geo/time.h"

#include <cmath>

namespace pdnav::geo {
namespace {
// Unix ms at which GPS-UTC became the paired value (IERS Bulletin C).
struct Leap { std::int64_t unix_ms; int gps_minus_utc_s; };
constexpr Leap kLeaps[] = {
    {362793600000, 1},   {394329600000, 2},   {425865600000, 3},   {489024000000, 4},
    {567993600000, 5},   {631152000000, 6},   {662688000000, 7},   {709948800000, 8},
    {741484800000, 9},   {773020800000, 10},  {820454400000, 11},  {867715200000, 12},
    {915148800000, 13},  {1136073600000, 14}, {1230768000000, 15}, {1341100800000, 16},
    {1435708800000, 17}, {1483228800000, 18},
};
}  // namespace

int leap_seconds_at_unix_ms(std::int64_t unix_ms) {
  int n = 0;
  for (const Leap& l : kLeaps)
    if (unix_ms >= l.unix_ms) n = l.gps_minus_utc_s;
  return n;
}

int leap_seconds_at_gps_ns(TimeNs gps_ns) {
  // GPS instant of each leap = unix_ms of the leap + leap count after it.
  int n = 0;
  for (const Leap& l : kLeaps) {
    const TimeNs leap_gps_ns = (l.unix_ms - kGpsEpochUnixMs) * kNsPerMs + TimeNs{l.gps_minus_utc_s} * kNsPerS;
    if (gps_ns >= leap_gps_ns) n = l.gps_minus_utc_s;
  }
  return n;
}

std::int64_t gps_ns_to_unix_ms(TimeNs gps_ns) {
  const int leap = leap_seconds_at_gps_ns(gps_ns);
  // floor division so negative remainders do not round toward zero
  TimeNs ms = gps_ns / kNsPerMs;
  if (gps_ns % kNsPerMs < 0) --ms;
  return ms + kGpsEpochUnixMs - std::int64_t{leap} * 1000;
}

TimeNs unix_ms_to_gps_ns(std::int64_t unix_ms) {
  const int leap = leap_seconds_at_unix_ms(unix_ms);
  return (unix_ms - kGpsEpochUnixMs + std::int64_t{leap} * 1000) * kNsPerMs;
}

GpsWeekTow gps_ns_to_week_tow(TimeNs gps_ns) {
  TimeNs week = gps_ns / kNsPerWeek;
  TimeNs rem = gps_ns % kNsPerWeek;
  if (rem < 0) { rem += kNsPerWeek; --week; }
  return GpsWeekTow{static_cast<int>(week), static_cast<double>(rem) * 1e-9};
}

TimeNs week_tow_to_gps_ns(int week, double tow_s) {
  return TimeNs{week} * kNsPerWeek + static_cast<TimeNs>(std::llround(tow_s * 1e9));
}

int resolve_week_rollover(int week_mod_1024, int reference_full_week) {
  int w = week_mod_1024 % 1024;
  int best = w;
  while (best + 1024 <= reference_full_week + 512) best += 1024;
  return best;
}

double calendar_to_epoch_seconds(int year, int month, int day, int hour, int minute, double second) {
  // days from civil (H. Hinnant's algorithm), relative to 1980-01-06
  const int y = month <= 2 ? year - 1 : year;
  const int era = (y >= 0 ? y : y - 399) / 400;
  const int yoe = y - era * 400;
  const int mp = (month + 9) % 12;
  const int doy = (153 * mp + 2) / 5 + day - 1;
  const int doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  const long days_since_unix = static_cast<long>(era) * 146097 + doe - 719468;
  const long days_since_gps = days_since_unix - 3657;  // 1980-01-06 is Unix day 3657
  return static_cast<double>(days_since_gps) * 86400.0 + hour * 3600.0 + minute * 60.0 + second;
}

double wrap_week_s(double dt_s) {
  constexpr double half = 302400.0;
  if (dt_s > half) return dt_s - 2 * half;
  if (dt_s < -half) return dt_s + 2 * half;
  return dt_s;
}

}  // namespace pdnav::geo
