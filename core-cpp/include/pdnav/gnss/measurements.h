// Android raw GNSS measurements -> pseudorange, pseudorange rate, accumulated delta range.
// Measurement model of Google's white paper "Using GNSS Raw Measurements on Android Devices"
// (GSA 2017, Sec. 2.4-2.5) and the android.location.GnssMeasurement state-bit definitions.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "pdnav/geo/samples.h"
#include "pdnav/gnss/types.h"

namespace pdnav::gnss {

/// android.location.GnssMeasurement STATE_* bits.
namespace state_bit {
inline constexpr std::int64_t kCodeLock = 1;
inline constexpr std::int64_t kBitSync = 2;
inline constexpr std::int64_t kSubframeSync = 4;
inline constexpr std::int64_t kTowDecoded = 8;
inline constexpr std::int64_t kMsecAmbiguous = 16;
inline constexpr std::int64_t kSymbolSync = 32;
inline constexpr std::int64_t kGloStringSync = 64;
inline constexpr std::int64_t kGloTodDecoded = 128;
inline constexpr std::int64_t kBdsD2BitSync = 256;
inline constexpr std::int64_t kBdsD2SubframeSync = 512;
inline constexpr std::int64_t kGalE1bcCodeLock = 1024;
inline constexpr std::int64_t kGalE1c2ndCodeLock = 2048;
inline constexpr std::int64_t kGalE1bPageSync = 4096;
inline constexpr std::int64_t kSbasSync = 8192;
inline constexpr std::int64_t kTowKnown = 16384;
inline constexpr std::int64_t kGloTodKnown = 32768;
}  // namespace state_bit

/// android.location.GnssMeasurement ADR_STATE_* bits.
namespace adr_bit {
inline constexpr std::int64_t kValid = 1;
inline constexpr std::int64_t kReset = 2;
inline constexpr std::int64_t kCycleSlip = 4;
}  // namespace adr_bit

/// Default carrier frequency of a constellation's civil L1/E1/B1 signal (ICDs); GLONASS
/// needs the FDMA channel k: 1602 MHz + k * 0.5625 MHz (GLONASS ICD 3.3.1.4).
double default_carrier_hz(Constellation sys, int glonass_channel = 0);

/// Receiver time in GPS time scale, split so that no precision is lost: ns + fraction.
struct GpsTime {
  std::int64_t ns = 0;     // integer ns since the GPS epoch
  double frac_ns = 0.0;    // in [0, 1)
  double seconds() const { return static_cast<double>(ns) * 1e-9 + frac_ns * 1e-9; }
};

/// One satellite's measurement in an epoch, after the validity checks.
struct Measurement {
  SatId sat;
  double pseudorange_m = kNaN;          // NaN when the code phase is not usable
  double pseudorange_sigma_m = kNaN;    // from ReceivedSvTimeUncertaintyNanos
  std::int64_t transmit_gps_ns = 0;     // receive time - pseudorange / c, GPS time scale
  double pr_rate_mps = kNaN;            // PseudorangeRateMetersPerSecond (Doppler * -lambda)
  double pr_rate_sigma_mps = kNaN;
  double adr_m = kNaN;                  // AccumulatedDeltaRangeMeters, NaN when not valid
  double adr_sigma_m = kNaN;
  bool adr_reset = false;               // ADR_STATE_RESET
  bool adr_cycle_slip = false;          // ADR_STATE_CYCLE_SLIP
  double cn0_dbhz = kNaN;
  double carrier_hz = kNaN;             // CarrierFrequencyHz, or NaN (use default_carrier_hz)
  std::string code_type;                // GnssMeasurement CodeType ("C", "Q", "X", ...), "" unknown
  int glonass_channel = 99;             // FDMA channel from an Android svid 93..106, 99 = unknown
  bool code_ok() const { return pseudorange_m == pseudorange_m; }
  bool adr_ok() const { return adr_m == adr_m && !adr_reset && !adr_cycle_slip; }
};

/// All measurements of one receiver epoch (one TimeNanos).
struct MeasurementEpoch {
  TimeNs t_ns = 0;                      // elapsedRealtimeNanos of the epoch
  std::int64_t time_nanos = 0;          // GnssClock.TimeNanos (receiver hardware clock)
  GpsTime rx;                           // receive time in GPS time
  std::int64_t hw_discontinuity = kMissingInt;
  double clock_drift_mps = kNaN;        // DriftNanosPerSecond * c * 1e-9
  std::int64_t full_bias_nanos = 0;     // FullBiasNanos and BiasNanos: hardware clock -> GPS time
  double bias_nanos = 0.0;
  int leap_seconds = 0;                 // GPS - UTC used for GLONASS
  std::vector<Measurement> meas;
};

struct MeasurementOptions {
  double min_cn0_dbhz = 15.0;            // issue 7 / Walker 2019 Sec. 2.2: reject C/N0 < 15 dB-Hz
  double max_uncertainty = 1e6;         // uncertainties above this (e.g. 3.4e38 "unknown") reject the field
  double max_pr_sigma_m = 150.0;        // ReceivedSvTimeUncertainty * c above this: code unusable
  double min_pseudorange_m = 1.0e7;     // below 10 000 km the code phase is wrong (ambiguity)
  double max_pseudorange_m = 1.0e8;     // above 100 000 km likewise
};

/// Reasons are counted in a map "reason" -> count (stable strings, documented in docs/gnss.md).
using ExclusionCounts = std::map<std::string, std::int64_t>;

/// Converts the Raw rows of one epoch (same TimeNanos) into measurements. Rows that cannot be
/// used at all are dropped; fields that cannot be used (code phase, ADR) become NaN; every
/// dropped row or field increments `excluded[reason]`. Never throws on bad values; returns
/// false (epoch unusable, counted) when the clock fields are missing or invalid.
bool build_epoch(const std::vector<GnssRawSample>& rows, const MeasurementOptions& opt,
                 MeasurementEpoch& out, ExclusionCounts& excluded);

/// Receive time in GPS time: TimeNanos + TimeOffsetNanos - (FullBiasNanos + BiasNanos).
/// false when FullBiasNanos is missing (the receiver has no GPS time yet).
bool receive_gps_time(const GnssRawSample& r, GpsTime& out);

/// Pseudorange (m) from the receive time and ReceivedSvTimeNanos of one row, resolving the
/// week (GPS, Galileo, QZSS, BeiDou), day (GLONASS) or 100 ms (Galileo E1C) ambiguity.
/// NaN with `reason` set when the tracking state does not make the code phase valid.
double pseudorange_m(const GnssRawSample& r, const GpsTime& rx, int leap_seconds, std::string& reason);

}  // namespace pdnav::gnss
