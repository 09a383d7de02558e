// The column schema of every line type, written once and used by both the reader and the
// writer: visit_fields(sample, v) calls the visitor for each column in writer order.
// Visitor interface (all names are the canonical column names of docs/log-format.md):
//   v.elapsed(name, TimeNs&)   the elapsedRealtimeNanos column (t_ns)
//   v.i64(name, int64&)  v.i32(name, int&)  v.f64(name, double&)  v.hpa(name, double& pa)
//   v.flag(name, bool&)  v.text(name, std::string&)  v.bytes(name, std::vector<uint8_t>&)
#pragma once
#include <cstddef>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "pdnav/geo/samples.h"

namespace pdnav::io::detail {

/// Which clock a line's UTC column comes from (docs/log-format.md, "Time").
enum class UtcKind {
  kNone,  // no UTC column
  kWall,  // System.currentTimeMillis() of the logging phone (sensor, Status lines)
  kGnss,  // UTC derived from GNSS time (Raw, Fix, Agc)
};

template <class S> struct LineTraits;
#define PDNAV_LINE(Type, Name, Utc, LearnsWall)                 \
  template <> struct LineTraits<Type> {                         \
    static constexpr std::string_view name = Name;              \
    static constexpr UtcKind utc = UtcKind::Utc;                \
    static constexpr bool learns_wall_offset = LearnsWall;      \
  };
PDNAV_LINE(AccelSample, "Accel", kWall, true)
PDNAV_LINE(GyroSample, "Gyro", kWall, true)
PDNAV_LINE(MagSample, "Mag", kWall, true)
PDNAV_LINE(UncalAccelSample, "UncalAccel", kWall, true)
PDNAV_LINE(UncalGyroSample, "UncalGyro", kWall, true)
PDNAV_LINE(UncalMagSample, "UncalMag", kWall, true)
PDNAV_LINE(OrientationSample, "OrientationDeg", kWall, true)
PDNAV_LINE(PressureSample, "Pressure", kWall, true)
PDNAV_LINE(RotationVectorSample, "RotationVector", kWall, true)
PDNAV_LINE(StepDetectorSample, "StepDetector", kWall, true)
PDNAV_LINE(StepCounterSample, "StepCounter", kWall, true)
PDNAV_LINE(GnssRawSample, "Raw", kGnss, false)
PDNAV_LINE(FixSample, "Fix", kGnss, false)
PDNAV_LINE(NavMessageSample, "Nav", kNone, false)
PDNAV_LINE(GnssStatusSample, "Status", kWall, false)
PDNAV_LINE(AgcSample, "Agc", kGnss, false)
PDNAV_LINE(TruthSample, "Truth", kNone, false)
PDNAV_LINE(MetaSample, "Meta", kNone, false)
PDNAV_LINE(GameRotationVectorSample, "GameRotationVector", kWall, true)
PDNAV_LINE(SensorAccuracySample, "SensorAccuracy", kWall, false)
#undef PDNAV_LINE

inline constexpr std::size_t kNumLineTypes = std::variant_size_v<Sample>;

template <class V> void sensor_time(std::int64_t& utc_ms, TimeNs& t_ns, V& v) {
  v.i64("utcTimeMillis", utc_ms);
  v.elapsed("elapsedRealtimeNanos", t_ns);
}

template <class V> void visit_fields(AccelSample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.f64("AccelXMps2", s.acc_mps2[0]); v.f64("AccelYMps2", s.acc_mps2[1]); v.f64("AccelZMps2", s.acc_mps2[2]);
}
template <class V> void visit_fields(GyroSample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.f64("GyroXRadPerSec", s.rate_radps[0]); v.f64("GyroYRadPerSec", s.rate_radps[1]); v.f64("GyroZRadPerSec", s.rate_radps[2]);
}
template <class V> void visit_fields(MagSample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.f64("MagXMicroT", s.field_ut[0]); v.f64("MagYMicroT", s.field_ut[1]); v.f64("MagZMicroT", s.field_ut[2]);
}
template <class V> void visit_fields(UncalAccelSample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.f64("UncalAccelXMps2", s.acc_mps2[0]); v.f64("UncalAccelYMps2", s.acc_mps2[1]); v.f64("UncalAccelZMps2", s.acc_mps2[2]);
  v.f64("BiasXMps2", s.bias_mps2[0]); v.f64("BiasYMps2", s.bias_mps2[1]); v.f64("BiasZMps2", s.bias_mps2[2]);
}
template <class V> void visit_fields(UncalGyroSample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.f64("UncalGyroXRadPerSec", s.rate_radps[0]); v.f64("UncalGyroYRadPerSec", s.rate_radps[1]); v.f64("UncalGyroZRadPerSec", s.rate_radps[2]);
  v.f64("DriftXRadPerSec", s.drift_radps[0]); v.f64("DriftYRadPerSec", s.drift_radps[1]); v.f64("DriftZRadPerSec", s.drift_radps[2]);
}
template <class V> void visit_fields(UncalMagSample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.f64("UncalMagXMicroT", s.field_ut[0]); v.f64("UncalMagYMicroT", s.field_ut[1]); v.f64("UncalMagZMicroT", s.field_ut[2]);
  v.f64("BiasXMicroT", s.bias_ut[0]); v.f64("BiasYMicroT", s.bias_ut[1]); v.f64("BiasZMicroT", s.bias_ut[2]);
}
template <class V> void visit_fields(OrientationSample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.f64("yawDeg", s.yaw_deg); v.f64("rollDeg", s.roll_deg); v.f64("pitchDeg", s.pitch_deg);
}
template <class V> void visit_fields(PressureSample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.hpa("PressureHpa", s.pressure_pa);
}
template <class V> void visit_fields(RotationVectorSample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.f64("QuatX", s.quat_xyzw[0]); v.f64("QuatY", s.quat_xyzw[1]); v.f64("QuatZ", s.quat_xyzw[2]); v.f64("QuatW", s.quat_xyzw[3]);
  v.f64("HeadingAccuracyRad", s.heading_accuracy_rad);
}
template <class V> void visit_fields(StepDetectorSample& s, V& v) { sensor_time(s.utc_ms, s.t_ns, v); }
template <class V> void visit_fields(StepCounterSample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.i64("Count", s.count);
}

template <class V> void visit_fields(GnssRawSample& s, V& v) {
  v.i64("utcTimeMillis", s.utc_ms);
  v.i64("TimeNanos", s.time_nanos);
  v.i64("LeapSecond", s.leap_second);
  v.f64("TimeUncertaintyNanos", s.time_uncertainty_nanos);
  v.i64("FullBiasNanos", s.full_bias_nanos);
  v.f64("BiasNanos", s.bias_nanos);
  v.f64("BiasUncertaintyNanos", s.bias_uncertainty_nanos);
  v.f64("DriftNanosPerSecond", s.drift_nanos_per_second);
  v.f64("DriftUncertaintyNanosPerSecond", s.drift_uncertainty_nanos_per_second);
  v.i64("HardwareClockDiscontinuityCount", s.hardware_clock_discontinuity_count);
  v.i32("Svid", s.svid);
  v.f64("TimeOffsetNanos", s.time_offset_nanos);
  v.i64("State", s.state);
  v.i64("ReceivedSvTimeNanos", s.received_sv_time_nanos);
  v.i64("ReceivedSvTimeUncertaintyNanos", s.received_sv_time_uncertainty_nanos);
  v.f64("Cn0DbHz", s.cn0_dbhz);
  v.f64("PseudorangeRateMetersPerSecond", s.pseudorange_rate_mps);
  v.f64("PseudorangeRateUncertaintyMetersPerSecond", s.pseudorange_rate_uncertainty_mps);
  v.i64("AccumulatedDeltaRangeState", s.accumulated_delta_range_state);
  v.f64("AccumulatedDeltaRangeMeters", s.accumulated_delta_range_m);
  v.f64("AccumulatedDeltaRangeUncertaintyMeters", s.accumulated_delta_range_uncertainty_m);
  v.f64("CarrierFrequencyHz", s.carrier_frequency_hz);
  v.i64("CarrierCycles", s.carrier_cycles);
  v.f64("CarrierPhase", s.carrier_phase);
  v.f64("CarrierPhaseUncertainty", s.carrier_phase_uncertainty);
  v.i32("MultipathIndicator", s.multipath_indicator);
  v.f64("SnrInDb", s.snr_db);
  v.i32("ConstellationType", s.constellation_type);
  v.f64("AgcDb", s.agc_db);
  v.f64("BasebandCn0DbHz", s.baseband_cn0_dbhz);
  v.f64("FullInterSignalBiasNanos", s.full_inter_signal_bias_nanos);
  v.f64("FullInterSignalBiasUncertaintyNanos", s.full_inter_signal_bias_uncertainty_nanos);
  v.f64("SatelliteInterSignalBiasNanos", s.satellite_inter_signal_bias_nanos);
  v.f64("SatelliteInterSignalBiasUncertaintyNanos", s.satellite_inter_signal_bias_uncertainty_nanos);
  v.text("CodeType", s.code_type);
  v.i64("ChipsetElapsedRealtimeNanos", s.chipset_elapsed_realtime_nanos);
  v.elapsed("elapsedRealtimeNanos", s.t_ns);  // pdnav addition (superset)
}

template <class V> void visit_fields(FixSample& s, V& v) {
  v.text("Provider", s.provider);
  v.f64("LatitudeDegrees", s.lat_deg);
  v.f64("LongitudeDegrees", s.lon_deg);
  v.f64("AltitudeMeters", s.alt_m);
  v.f64("SpeedMps", s.speed_mps);
  v.f64("AccuracyMeters", s.accuracy_m);
  v.f64("BearingDegrees", s.bearing_deg);
  v.i64("UnixTimeMillis", s.utc_ms);
  v.f64("SpeedAccuracyMps", s.speed_accuracy_mps);
  v.f64("BearingAccuracyDegrees", s.bearing_accuracy_deg);
  v.elapsed("elapsedRealtimeNanos", s.t_ns);
  v.f64("VerticalAccuracyMeters", s.vertical_accuracy_m);
}

template <class V> void visit_fields(NavMessageSample& s, V& v) {
  v.i32("Svid", s.svid);
  v.i32("Type", s.type);
  v.i32("Status", s.status);
  v.i32("MessageId", s.message_id);
  v.i32("Sub-messageId", s.sub_message_id);
  v.elapsed("elapsedRealtimeNanos", s.t_ns);  // pdnav addition; GnssLogger's Nav has no time
  v.bytes("Data(Bytes)", s.data);             // one signed byte per field, to the end of the line
}

template <class V> void visit_fields(GnssStatusSample& s, V& v) {
  v.i64("UnixTimeMillis", s.utc_ms);
  v.i32("SignalCount", s.signal_count);
  v.i32("SignalIndex", s.signal_index);
  v.i32("ConstellationType", s.constellation_type);
  v.i32("Svid", s.svid);
  v.f64("CarrierFrequencyHz", s.carrier_frequency_hz);
  v.f64("Cn0DbHz", s.cn0_dbhz);
  v.f64("AzimuthDegrees", s.azimuth_deg);
  v.f64("ElevationDegrees", s.elevation_deg);
  v.flag("UsedInFix", s.used_in_fix);
  v.flag("HasAlmanacData", s.has_almanac);
  v.flag("HasEphemerisData", s.has_ephemeris);
  v.f64("BasebandCn0DbHz", s.baseband_cn0_dbhz);
  v.elapsed("elapsedRealtimeNanos", s.t_ns);  // pdnav addition
}

template <class V> void visit_fields(AgcSample& s, V& v) {
  v.i64("utcTimeMillis", s.utc_ms);
  v.i64("TimeNanos", s.time_nanos);
  v.f64("AgcDb", s.agc_db);
  v.f64("CarrierFrequencyHz", s.carrier_frequency_hz);
  v.i32("ConstellationType", s.constellation_type);
  v.elapsed("elapsedRealtimeNanos", s.t_ns);  // pdnav addition
}

template <class V> void visit_fields(TruthSample& s, V& v) {
  v.elapsed("elapsedRealtimeNanos", s.t_ns);
  v.f64("LatitudeDegrees", s.lat_deg);
  v.f64("LongitudeDegrees", s.lon_deg);
  v.f64("HeightMeters", s.h_m);
  v.f64("HeadingDegrees", s.heading_deg);
}

template <class V> void visit_fields(MetaSample& s, V& v) {
  v.elapsed("elapsedRealtimeNanos", s.t_ns);
  v.text("Key", s.key);
  v.text("Value", s.value);
}

template <class V> void visit_fields(GameRotationVectorSample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.f64("QuatX", s.quat_xyzw[0]); v.f64("QuatY", s.quat_xyzw[1]); v.f64("QuatZ", s.quat_xyzw[2]); v.f64("QuatW", s.quat_xyzw[3]);
}

template <class V> void visit_fields(SensorAccuracySample& s, V& v) {
  sensor_time(s.utc_ms, s.t_ns, v);
  v.i32("SensorType", s.sensor_type);
  v.i32("Accuracy", s.accuracy);
}

/// Collects the canonical column names of a line type, in schema order.
struct NameCollector {
  std::vector<std::string> names;
  template <class T> void add(std::string_view n, T&) { names.emplace_back(n); }
  void elapsed(std::string_view n, TimeNs& x) { add(n, x); }
  void i64(std::string_view n, std::int64_t& x) { add(n, x); }
  void i32(std::string_view n, int& x) { add(n, x); }
  void f64(std::string_view n, double& x) { add(n, x); }
  void hpa(std::string_view n, double& x) { add(n, x); }
  void flag(std::string_view n, bool& x) { add(n, x); }
  void text(std::string_view n, std::string& x) { add(n, x); }
  void bytes(std::string_view n, std::vector<std::uint8_t>& x) { add(n, x); }
};

}  // namespace pdnav::io::detail
