// The batch layout shared by the JNI bridge and the Kotlin SampleBatch class
// (app/src/main/kotlin/org/pdnav/app/nav/SampleBatch.kt): every sample is one row of
// fixed-width primitive arrays, so a whole batch crosses JNI in a handful of array copies.
//   kind     int32   pdnav::Sample variant index (0 Accel ... 17 Meta, 18 GameRotationVector, 19 SensorAccuracy)
//   t_ns     int64   elapsedRealtimeNanos
//   ints     int64 x kInts      integer fields (utc_ms first where the type has it)
//   doubles  float64 x kDoubles  real fields (core units: m/s^2, rad/s, uT, Pa, deg, m)
//   strings  String x kStrings   text fields (GNSS code type, fix provider, meta key/value)
//   bytes    int8 x kBytes       navigation-message data (length in ints[5])
// The field order of every kind is listed in docs/android.md; Kotlin checks kLayoutVersion
// and the widths at load time so the two sides cannot drift apart silently.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

#include "pdnav/geo/samples.h"

namespace pdnav::jni {

inline constexpr int kLayoutVersion = 1;
inline constexpr std::size_t kInts = 16;
inline constexpr std::size_t kDoubles = 24;
inline constexpr std::size_t kStrings = 2;
inline constexpr std::size_t kBytes = 64;
inline constexpr int kKinds = static_cast<int>(std::variant_size_v<Sample>);

/// Read-only view of n rows (arrays already copied out of the JVM).
struct BatchView {
  std::size_t n = 0;
  const std::int32_t* kinds = nullptr;
  const std::int64_t* t_ns = nullptr;
  const std::int64_t* ints = nullptr;       // n * kInts
  const double* doubles = nullptr;          // n * kDoubles
  const std::string* strings = nullptr;     // n * kStrings
  const std::int8_t* bytes = nullptr;       // n * kBytes
};

/// Writable rows for the reverse direction (log reader -> Kotlin).
struct BatchOut {
  std::size_t capacity = 0;
  std::int32_t* kinds = nullptr;
  std::int64_t* t_ns = nullptr;
  std::int64_t* ints = nullptr;
  double* doubles = nullptr;
  std::string* strings = nullptr;
  std::int8_t* bytes = nullptr;
};

/// Row i as a Sample. Throws std::invalid_argument (row index and reason) for an unknown
/// kind or an out-of-range field (e.g. a navigation message longer than kBytes).
Sample decode_row(const BatchView& b, std::size_t i);

/// Writes s into row i (all other fields of the row are cleared first). Throws
/// std::invalid_argument when a field cannot be represented (nav data longer than kBytes).
void encode_row(const Sample& s, BatchOut& b, std::size_t i);

}  // namespace pdnav::jni
