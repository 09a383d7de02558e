// Skip reason categories shared by the readers: keys of ReadStats::skipped_by_reason (listed
// by `pdnav inspect`), spelled once so a reason reads the same in every format.
#pragma once

namespace pdnav::io::detail {

inline constexpr const char* kNonNumeric = "non-numeric value";
inline constexpr const char* kOutOfRange = "value out of range";
inline constexpr const char* kInvalidTime = "invalid time";
inline constexpr const char* kBackwards = "time went backwards";
inline constexpr const char* kWrongFieldCount = "wrong field count";
inline constexpr const char* kTorn = "torn last line";
inline constexpr const char* kTooLong = "line too long";

}  // namespace pdnav::io::detail
