// The time-ordered sample stream: everything a phone records, as plain structs.
// One struct per log line type (docs/log-format.md). Every sample carries t_ns, Android's
// elapsedRealtimeNanos (the common timeline); utc_ms is the wall clock where the line has it.
// Missing numeric fields are NaN (doubles) or kMissingInt (integers).
#pragma once
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/units.h"

namespace pdnav {

inline constexpr std::int64_t kMissingInt = std::numeric_limits<std::int64_t>::min();
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Calibrated accelerometer (Android TYPE_ACCELEROMETER), phone axes, includes gravity.
struct AccelSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; Eigen::Vector3d acc_mps2 = Eigen::Vector3d::Zero(); };
/// Calibrated gyroscope, phone axes.
struct GyroSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; Eigen::Vector3d rate_radps = Eigen::Vector3d::Zero(); };
/// Calibrated magnetometer, phone axes.
struct MagSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; Eigen::Vector3d field_ut = Eigen::Vector3d::Zero(); };
/// Uncalibrated accelerometer with the estimated bias.
struct UncalAccelSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; Eigen::Vector3d acc_mps2 = Eigen::Vector3d::Zero(); Eigen::Vector3d bias_mps2 = Eigen::Vector3d::Zero(); };
/// Uncalibrated gyroscope with the estimated drift.
struct UncalGyroSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; Eigen::Vector3d rate_radps = Eigen::Vector3d::Zero(); Eigen::Vector3d drift_radps = Eigen::Vector3d::Zero(); };
/// Uncalibrated magnetometer with the estimated hard-iron bias.
struct UncalMagSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; Eigen::Vector3d field_ut = Eigen::Vector3d::Zero(); Eigen::Vector3d bias_ut = Eigen::Vector3d::Zero(); };
/// GnssLogger OrientationDeg line (Android orientation angles, degrees).
struct OrientationSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; double yaw_deg = kNaN; double roll_deg = kNaN; double pitch_deg = kNaN; };
/// Barometer (TYPE_PRESSURE). Android reports hPa; stored here in Pa.
struct PressureSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; double pressure_pa = kNaN; };
/// Rotation vector (TYPE_ROTATION_VECTOR): unit quaternion phone->ENU (x,y,z,w) and the
/// estimated heading accuracy (NaN when the sensor does not report it).
struct RotationVectorSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; Eigen::Vector4d quat_xyzw = Eigen::Vector4d(0, 0, 0, 1); double heading_accuracy_rad = kNaN; };
/// Android step-detector event (TYPE_STEP_DETECTOR): one step at t_ns.
struct StepDetectorSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; };
/// Android step-counter (TYPE_STEP_COUNTER): cumulative steps since boot.
struct StepCounterSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; std::int64_t count = 0; };

/// One GnssMeasurement with its GnssClock (GnssLogger `Raw` line). Names follow Android.
struct GnssRawSample {
  TimeNs t_ns = 0;  // elapsedRealtimeNanos of the measurement epoch (see docs/log-format.md)
  std::int64_t utc_ms = kMissingInt;
  // GnssClock
  std::int64_t time_nanos = kMissingInt;
  std::int64_t leap_second = kMissingInt;
  double time_uncertainty_nanos = kNaN;
  std::int64_t full_bias_nanos = kMissingInt;
  double bias_nanos = kNaN;
  double bias_uncertainty_nanos = kNaN;
  double drift_nanos_per_second = kNaN;
  double drift_uncertainty_nanos_per_second = kNaN;
  std::int64_t hardware_clock_discontinuity_count = kMissingInt;
  // GnssMeasurement
  int svid = 0;
  double time_offset_nanos = kNaN;
  std::int64_t state = 0;
  std::int64_t received_sv_time_nanos = kMissingInt;
  std::int64_t received_sv_time_uncertainty_nanos = kMissingInt;
  double cn0_dbhz = kNaN;
  double pseudorange_rate_mps = kNaN;
  double pseudorange_rate_uncertainty_mps = kNaN;
  std::int64_t accumulated_delta_range_state = 0;
  double accumulated_delta_range_m = kNaN;
  double accumulated_delta_range_uncertainty_m = kNaN;
  double carrier_frequency_hz = kNaN;
  std::int64_t carrier_cycles = kMissingInt;
  double carrier_phase = kNaN;
  double carrier_phase_uncertainty = kNaN;
  int multipath_indicator = 0;
  double snr_db = kNaN;
  int constellation_type = 0;  // android.location.GnssStatus.CONSTELLATION_*
  double agc_db = kNaN;
  double baseband_cn0_dbhz = kNaN;
  double full_inter_signal_bias_nanos = kNaN;
  double full_inter_signal_bias_uncertainty_nanos = kNaN;
  double satellite_inter_signal_bias_nanos = kNaN;
  double satellite_inter_signal_bias_uncertainty_nanos = kNaN;
  std::string code_type;
  std::int64_t chipset_elapsed_realtime_nanos = kMissingInt;
};

/// A position fix (GnssLogger `Fix`): the phone's own GNSS/FLP/NLP location.
struct FixSample {
  TimeNs t_ns = 0;
  std::int64_t utc_ms = kMissingInt;  // UnixTimeMillis of the fix
  std::string provider;               // "GPS", "FLP", "NLP", ...
  double lat_deg = kNaN, lon_deg = kNaN, alt_m = kNaN;
  double speed_mps = kNaN, accuracy_m = kNaN, bearing_deg = kNaN;
  double speed_accuracy_mps = kNaN, bearing_accuracy_deg = kNaN, vertical_accuracy_m = kNaN;
  /// Android's accuracy is the radius of 68 % confidence: for a circular Gaussian that radius is
  /// 1.51 per-axis sigmas (sqrt(-2 ln 0.32)), so sigma = accuracy_m / kAccuracyRadiusPerSigma.
  static constexpr double kAccuracyRadiusPerSigma = 1.51;
};

/// GnssNavigationMessage (GnssLogger `Nav`): raw navigation data bits of one satellite.
struct NavMessageSample {
  TimeNs t_ns = 0;
  int svid = 0;
  int type = 0;
  int status = 0;
  int message_id = 0;
  int sub_message_id = 0;
  std::vector<std::uint8_t> data;
};

/// GnssStatus (GnssLogger `Status`), one satellite signal.
struct GnssStatusSample {
  TimeNs t_ns = 0;
  std::int64_t utc_ms = kMissingInt;
  int signal_count = 0, signal_index = 0, constellation_type = 0, svid = 0;
  double carrier_frequency_hz = kNaN, cn0_dbhz = kNaN, azimuth_deg = kNaN, elevation_deg = kNaN;
  bool used_in_fix = false, has_almanac = false, has_ephemeris = false;
  double baseband_cn0_dbhz = kNaN;
};

/// Automatic gain control (GnssLogger `Agc`).
struct AgcSample {
  TimeNs t_ns = 0;
  std::int64_t utc_ms = kMissingInt;
  std::int64_t time_nanos = kMissingInt;
  double agc_db = kNaN, carrier_frequency_hz = kNaN;
  int constellation_type = 0;
};

/// Ground-truth position (simulator, survey, or a reference receiver).
struct TruthSample {
  TimeNs t_ns = 0;
  double lat_deg = kNaN, lon_deg = kNaN, h_m = kNaN;
  double heading_deg = kNaN;  // NaN when unknown
};

/// Session metadata, one key/value per line (format version, device, user height,
/// declared start position and its uncertainty, DEM/graph identities). Keys: docs/log-format.md.
struct MetaSample {
  TimeNs t_ns = 0;
  std::string key;
  std::string value;
};

/// Game rotation vector (TYPE_GAME_ROTATION_VECTOR): unit quaternion phone->a world frame
/// whose Z is up but whose yaw is arbitrary (gyro + accelerometer, no magnetometer), x,y,z,w.
struct GameRotationVectorSample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; Eigen::Vector4d quat_xyzw = Eigen::Vector4d(0, 0, 0, 1); };

/// A sensor's accuracy change (SensorEventListener.onAccuracyChanged): Android sensor type
/// (Sensor.TYPE_*, e.g. 2 magnetic field) and SensorManager.SENSOR_STATUS_* (-1 no contact,
/// 0 unreliable, 1 low, 2 medium, 3 high). t_ns is the elapsed time of the callback.
struct SensorAccuracySample { TimeNs t_ns = 0; std::int64_t utc_ms = kMissingInt; int sensor_type = 0; int accuracy = 0; };

// New line types are appended: the variant index is the JNI batch kind (core-cpp/jni).
using Sample = std::variant<AccelSample, GyroSample, MagSample, UncalAccelSample, UncalGyroSample,
                            UncalMagSample, OrientationSample, PressureSample, RotationVectorSample,
                            StepDetectorSample, StepCounterSample, GnssRawSample, FixSample,
                            NavMessageSample, GnssStatusSample, AgcSample, TruthSample, MetaSample,
                            GameRotationVectorSample, SensorAccuracySample>;

/// Timestamp of any sample.
inline TimeNs sample_time_ns(const Sample& s) {
  return std::visit([](const auto& x) { return x.t_ns; }, s);
}

/// Whether sample type T carries a wall-clock time (utc_ms): the sensor and GNSS lines, not
/// Truth, Meta or Nav.
template <typename T, typename = void>
struct has_utc : std::false_type {};
template <typename T>
struct has_utc<T, std::void_t<decltype(std::declval<T>().utc_ms)>> : std::true_type {};

}  // namespace pdnav
