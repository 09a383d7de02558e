// The sample streams of the SIGKILL recording test, shared by the writer child
// (record_child.cpp) and the checking test (recording_test.cpp). Every stream has a fixed
// period; sample k of a stream is due at t0 + k * period and its values are a pure function
// of (stream, k), so the reader side can check each line it gets back exactly, and that the
// lines of each stream form a gap-free prefix 0..n-1.
#pragma once
#include <cstdint>
#include <string>

#include "pdnav/geo/samples.h"

namespace pdnav::reliability {

enum class Stream { kAccel, kGyro, kMag, kPressure, kRotationVector, kGnssRaw, kFix };
inline constexpr int kStreamCount = 7;
inline constexpr int kRawPerEpoch = 8;  // satellites per 1 Hz GNSS epoch (one Raw line each)

/// Period of a stream in ns: realistic phone rates (accel/gyro 200 Hz, mag and rotation
/// vector 50 Hz, baro 25 Hz, GNSS 1 Hz epochs of kRawPerEpoch satellites, fix 1 Hz).
inline TimeNs stream_period_ns(Stream s) {
  switch (s) {
    case Stream::kAccel:
    case Stream::kGyro: return 5'000'000;
    case Stream::kMag:
    case Stream::kRotationVector: return 20'000'000;
    case Stream::kPressure: return 40'000'000;
    case Stream::kGnssRaw:
    case Stream::kFix: return 1'000'000'000;
  }
  return 1'000'000'000;
}

inline const char* stream_name(Stream s) {
  static const char* const kNames[] = {"Accel", "Gyro", "Mag", "Pressure", "RotationVector", "Raw", "Fix"};
  return kNames[static_cast<int>(s)];
}

/// A value with few decimals (exact in any sane text form) that changes with k.
inline double wave(std::int64_t k, int salt, double base, double span) {
  return base + span * static_cast<double>((k * 37 + salt * 11) % 1000) / 1000.0;
}

/// Sample k of stream s (for GNSS, the Raw line `sat` of epoch k) with its time t_ns.
inline Sample stream_sample(Stream s, std::int64_t k, TimeNs t_ns, int sat = 0) {
  switch (s) {
    case Stream::kAccel: {
      AccelSample a;
      a.t_ns = t_ns;
      a.acc_mps2 = {wave(k, 1, -1.0, 2.0), wave(k, 2, 8.5, 2.5), wave(k, 3, -1.0, 2.0)};
      return a;
    }
    case Stream::kGyro: {
      GyroSample g;
      g.t_ns = t_ns;
      g.rate_radps = {wave(k, 4, -0.5, 1.0), wave(k, 5, -0.5, 1.0), wave(k, 6, -0.5, 1.0)};
      return g;
    }
    case Stream::kMag: {
      MagSample m;
      m.t_ns = t_ns;
      m.field_ut = {wave(k, 7, -20.0, 40.0), wave(k, 8, 10.0, 20.0), wave(k, 9, -45.0, 10.0)};
      return m;
    }
    case Stream::kPressure: {
      PressureSample p;
      p.t_ns = t_ns;
      p.pressure_pa = wave(k, 10, 95000.0, 100.0);
      return p;
    }
    case Stream::kRotationVector: {
      RotationVectorSample r;
      r.t_ns = t_ns;
      r.quat_xyzw = Eigen::Vector4d(0.5, 0.5, 0.5, 0.5);
      r.heading_accuracy_rad = wave(k, 11, 0.1, 0.4);
      return r;
    }
    case Stream::kGnssRaw: {
      GnssRawSample g;
      g.t_ns = t_ns;
      g.time_nanos = t_ns;
      g.full_bias_nanos = -1'400'000'000'000'000'000 + k;
      g.bias_nanos = 0.25;
      g.svid = 2 + sat * 3;
      g.constellation_type = 1;
      g.state = 16431;
      g.received_sv_time_nanos = 300'000'000'000 + k * 1'000'000'000 + sat;
      g.received_sv_time_uncertainty_nanos = 12;
      g.cn0_dbhz = wave(k, 12 + sat, 20.0, 25.0);
      g.pseudorange_rate_mps = wave(k, 20 + sat, -500.0, 1000.0);
      g.carrier_frequency_hz = 1575420030.0;
      return g;
    }
    case Stream::kFix: {
      FixSample f;
      f.t_ns = t_ns;
      f.provider = "GPS";
      f.lat_deg = wave(k, 30, 42.5, 0.01);
      f.lon_deg = wave(k, 31, 1.5, 0.01);
      f.alt_m = wave(k, 32, 1000.0, 50.0);
      f.accuracy_m = wave(k, 33, 3.0, 10.0);
      return f;
    }
  }
  return AccelSample{};
}

}  // namespace pdnav::reliability
