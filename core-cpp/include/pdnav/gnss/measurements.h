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
  // Dual frequency (MeasurementOptions::frequency = kDual): when the satellite's clock group
  // uses the ionosphere-free combination this epoch, pseudorange_m is the L1/L5 (E1/E5a)
  // ionosphere-free code referenced to the L1 receiver clock (see combine_dual_frequency);
  // ADR, Doppler, C/N0, carrier_hz and code_type stay those of the L1 signal.
  bool iono_free = false;
  double pseudorange_l1_m = kNaN;       // the L1 code before the combination (NaN when not combined)
  double pseudorange_l5_m = kNaN;       // the L5/E5a code of the same satellite, NaN when not tracked
  double cn0_l5_dbhz = kNaN;
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

/// Which bands the code solution uses.
///   kSingle: L1/E1/B1 only, Klobuchar for the ionosphere; L5/E5a rows counted and dropped.
///   kDual:   per clock group (GPS+QZSS, Galileo, ...) and epoch, the L1/L5 ionosphere-free
///            code when enough of the group's satellites track both bands (otherwise the whole
///            group stays single frequency + Klobuchar: see combine_dual_frequency).
/// kSingle: L1/E1/B1 code, Klobuchar; kDual: L1/L5 ionosphere-free per clock group; kL5: the
/// L5/E5a/B2a signal alone (code, Doppler, carrier), Klobuchar scaled to its frequency (noise-
/// model learning of the second band); kBest: per satellite the L5/E5a/B2a signal where its
/// code is usable, else L1 (one receiver clock per constellation and band in the SPP).
enum class FrequencyMode { kSingle, kDual, kL5, kBest };
/// "single", "dual", "l5", "best".
const char* frequency_mode_name(FrequencyMode m);

struct MeasurementOptions {
  FrequencyMode frequency = FrequencyMode::kSingle;  // default chosen by measurement (docs/gnss.md)
  // Dual frequency: a clock group is combined when at least dual_min_sats of its code
  // satellites, and at least dual_min_fraction of them, track L5/E5a. The receiver's L1-L5
  // bias (2.35 km GPS / 1.91 km Galileo on the GSDC Pixel 5) differs per group; mixing IF and
  // L1 codes in one clock group would need its own bias unknown, so the group is all-or-none.
  int dual_min_sats = 4;  // also kBest: fewest L5 codes for a clock group to move to L5
  double dual_min_fraction = 0.75;
  /// Satellites of a combined group whose L1-L5 difference is this far from the group median
  /// are dropped (an L5 multipath/tracking error): 20 m = 25 m of L1 ionosphere difference.
  double dual_max_deviation_m = 20.0;
  /// Keep the L1 code of a combined group's L1-only satellites (mixes IF and L1 in one clock
  /// group: the few-metre mean-ionosphere mismatch is not modelled). Default false: dropped.
  bool dual_keep_single = false;
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

/// True for an L5-band signal usable as the second frequency (GPS/QZSS L5, Galileo E5a,
/// BeiDou B2a: 1176.45 MHz).
bool l5_band(Constellation sys, double carrier_hz);

/// Ionosphere-free combination coefficients for L1 (f1) and L5 (f5):
///   IF = alpha P1 - beta P5, alpha = f1^2/(f1^2-f5^2) = 2.2606, beta = f5^2/(f1^2-f5^2) = 1.2606
/// (Misra & Enge 2011 Sec. 5.3.2). The code noise is amplified by sqrt(alpha^2 + beta^2) = 2.59
/// for equal noise on both bands.
inline constexpr double kIfAlpha = 1575.42e6 * 1575.42e6 / (1575.42e6 * 1575.42e6 - 1176.45e6 * 1176.45e6);
inline constexpr double kIfBeta = kIfAlpha - 1.0;

/// Dual-frequency step of build_epoch (public for the tests). `meas` are the L1 measurements
/// with pseudorange_l5_m / cn0_l5_dbhz filled where the satellite tracks L5/E5a. Per clock group
/// (QZSS with GPS): when the group qualifies (dual_min_sats, dual_min_fraction), every
/// dual satellite's code becomes
///   P_IF = P1 + beta (d - median_group(d)),  d = P1 - P5,
/// i.e. the IF code minus beta x the epoch's median L1-L5 difference. The median carries the
/// receiver L1-L5 bias (and the satellites' mean group delay), so P_IF stays on the L1 receiver
/// clock up to the group's median ionosphere (absorbed by the group's clock/ISB like the bias),
/// and the satellite's own ionosphere and TGD/BGD are removed (variance: noise_model.h iono_free_variance_m2).
/// L1-only satellites of a combined group lose their code (counted) unless dual_keep_single.
void combine_dual_frequency(std::vector<Measurement>& meas, const MeasurementOptions& opt, ExclusionCounts& excluded);

/// Receive time in GPS time: TimeNanos + TimeOffsetNanos - (FullBiasNanos + BiasNanos).
/// false when FullBiasNanos is missing (the receiver has no GPS time yet).
bool receive_gps_time(const GnssRawSample& r, GpsTime& out);

/// Pseudorange (m) from the receive time and ReceivedSvTimeNanos of one row, resolving the
/// week (GPS, Galileo, QZSS, BeiDou), day (GLONASS) or 100 ms (Galileo E1C) ambiguity.
/// NaN with `reason` set when the tracking state does not make the code phase valid.
double pseudorange_m(const GnssRawSample& r, const GpsTime& rx, int leap_seconds, std::string& reason);

}  // namespace pdnav::gnss
