// Phone handling synthesised ahead of a real recording (issue 16): the compass-calibration
// "figure eight" that starts many field sessions. Figure-eight wrist rotations (two axes at a
// 1:2 frequency ratio, a third slower one) at 0.6-1.2 Hz with a seeded drifting rate, 35-70 deg
// (times `amplitude`), hand translation of 1.5-3 m/s^2 (times `amplitude`), faded in and out over
// 1 s, ending in the recording's first attitude. Accelerometer, gyroscope, rotation vector and
// magnetometer are consistent with that attitude: specific force R^T (g up + a_hand), the body
// rate of R, R itself (phone -> ENU, as Android's rotation vector), R^T B with the recording's own
// field. The sensor noise is the recording's: residuals of its first samples about a running mean,
// cycled. Nothing here is the motion classifier's model (docs/pdr.md "Motion classifier").
// Seeded, reproducible, no file I/O.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pdnav/geo/samples.h"

namespace pdnav::phonesim {

struct WavingOptions {
  double seconds = 30.0;   // the "half minute of compass-calibration waving"
  double amplitude = 1.0;  // scales rotation and translation (0.5: gentle waving)
  double rate_hz = 50.0;   // the ILC walks' sensor rate
  std::uint64_t seed = 1;
};

/// The recording the waving precedes: its first readings fix the attitude and field the waving
/// ends in; its noise residuals are added to the synthesised samples.
struct WavingEnd {
  TimeNs t_end_ns = 0;                                // time of the last waving sample
  Eigen::Vector3d accel_phone_mps2 = Eigen::Vector3d(0, 0, 9.81);  // first accelerometer reading
  std::optional<Eigen::Vector4d> rotation_xyzw;       // first rotation vector, phone -> ENU (else yaw 0)
  std::optional<Eigen::Vector3d> field_phone_ut;      // first magnetometer reading (else no Mag)
  std::vector<Eigen::Vector3d> accel_noise_mps2;      // cycled; empty = no noise
  std::vector<Eigen::Vector3d> gyro_noise_radps;
};

struct WavingSamples {
  std::vector<AccelSample> accel;
  std::vector<GyroSample> gyro;
  std::vector<RotationVectorSample> rotation;  // only with WavingEnd::rotation_xyzw
  std::vector<MagSample> mag;                  // only with WavingEnd::field_phone_ut
};

/// Residuals of the first `count` samples about their +-5-sample running mean: a recording's own
/// sensor noise (and tremor) with its gait removed.
std::vector<Eigen::Vector3d> running_mean_residuals(const std::vector<Eigen::Vector3d>& samples,
                                                    std::size_t count = 100);

/// options.seconds of waving at options.rate_hz, the last sample at end.t_end_ns.
WavingSamples synthesize_waving(const WavingEnd& end, const WavingOptions& options);

}  // namespace pdnav::phonesim
