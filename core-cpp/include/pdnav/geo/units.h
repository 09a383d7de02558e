// Units, time and physical constants shared by every module.
#pragma once
#include <cstdint>

namespace pdnav {

/// Time is always int64 nanoseconds. Sensor time is Android's elapsedRealtimeNanos.
using TimeNs = std::int64_t;

inline constexpr TimeNs kNsPerS = 1'000'000'000;
inline constexpr TimeNs kNsPerMs = 1'000'000;
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;
inline constexpr double kSpeedOfLight_mps = 299'792'458.0;  // IS-GPS-200 20.3.4.3
inline constexpr double kStandardGravity_mps2 = 9.80665;

constexpr double deg_to_rad(double deg) { return deg * kDegToRad; }
constexpr double rad_to_deg(double rad) { return rad * kRadToDeg; }
constexpr double ns_to_s(TimeNs t_ns) { return static_cast<double>(t_ns) * 1e-9; }
constexpr TimeNs s_to_ns(double t_s) { return static_cast<TimeNs>(t_s * 1e9); }

/// Wrap an angle to (-pi, pi].
double wrap_pi(double angle_rad);
/// Wrap an angle to [0, 2 pi).
double wrap_two_pi(double angle_rad);

}  // namespace pdnav
