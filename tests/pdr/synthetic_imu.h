// Synthetic walking IMU streams with known answers (turns, steps, heading) for the pdr tests.
// A walker moves along a yaw profile psi(t) (counter-clockwise positive, psi = 0 = east); the
// phone sits at a fixed tilt in the body frame and sways with the gait. Gyro = true body rate
// + bias + white noise; accelerometer = specific force (gravity + vertical bounce) + noise.
#pragma once
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "pdnav/geo/samples.h"

namespace pdnav::test {

struct TurnSegment {
  double straight_before_s;  // straight walking before the turn
  double angle_deg;          // signed, positive = left (counter-clockwise)
};

struct WalkSpec {
  double rate_hz = 100.0;
  double cadence_hz = 1.8;          // steps per second
  double tilt_deg = 0.0;            // phone tilt from flat (screen up) about its x axis
  double mount_yaw_deg = 0.0;       // phone yaw relative to the walking direction
  double turn_rate_dps = 60.0;      // peak-ish turn speed (raised-cosine profile)
  double sway_yaw_deg = 3.0;        // gait sway amplitudes
  double sway_roll_deg = 4.0;
  double bounce_mps2 = 2.0;         // vertical acceleration amplitude at the step frequency
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d(0.006, -0.008, 0.007);  // ~0.35-0.45 deg/s
  double gyro_noise_radps = 0.003;  // per-sample 1-sigma
  double accel_noise_mps2 = 0.05;
  double initial_psi_deg = 90.0;    // start walking north
  double final_straight_s = 8.0;
  std::uint64_t seed = 1;
};

struct SyntheticWalk {
  std::vector<AccelSample> accel;
  std::vector<GyroSample> gyro;
  std::vector<RotationVectorSample> rotation;  // true phone->ENU quaternion
  std::vector<double> psi_rad;                 // walking yaw at each sample
  double duration_s = 0.0;
};

/// Yaw profile: straight segments and raised-cosine turns.
class YawProfile {
 public:
  YawProfile(const std::vector<TurnSegment>& segs, double psi0_rad, double turn_rate_dps) : psi0_(psi0_rad) {
    double t = 0.0;
    for (const auto& s : segs) {
      t += s.straight_before_s;
      const double dur = std::max(1.5, 2.0 * std::abs(s.angle_deg) / turn_rate_dps);
      turns_.push_back({t, dur, s.angle_deg * kDegToRad});
      t += dur;
    }
    end_ = t;
  }
  double operator()(double t) const {
    double psi = psi0_;
    for (const auto& tr : turns_) {
      if (t >= tr.start + tr.dur) {
        psi += tr.angle;
      } else if (t > tr.start) {
        const double u = (t - tr.start) / tr.dur;
        psi += tr.angle * 0.5 * (1.0 - std::cos(kPi * u));
      }
    }
    return psi;
  }
  double end_s() const { return end_; }

 private:
  struct Turn {
    double start, dur, angle;
  };
  double psi0_;
  std::vector<Turn> turns_;
  double end_ = 0.0;
};

inline SyntheticWalk make_walk(const WalkSpec& spec, const std::vector<TurnSegment>& segs) {
  const YawProfile yaw(segs, spec.initial_psi_deg * kDegToRad, spec.turn_rate_dps);
  const double duration = yaw.end_s() + spec.final_straight_s;
  std::mt19937_64 rng(spec.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double dt = 1.0 / spec.rate_hz;
  const double stride_hz = spec.cadence_hz / 2.0;
  // Phone orientation in the walker's body frame (x forward, y left, z up): flat screen-up,
  // yawed by mount_yaw, tilted about the phone's x axis.
  const Eigen::Matrix3d mount =
      (Eigen::AngleAxisd(spec.mount_yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(spec.tilt_deg * kDegToRad, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  auto orientation = [&](double t) -> Eigen::Matrix3d {
    const double sway_yaw = spec.sway_yaw_deg * kDegToRad * std::sin(2 * kPi * stride_hz * t);
    const double sway_roll = spec.sway_roll_deg * kDegToRad * std::sin(2 * kPi * stride_hz * t + 0.7);
    return (Eigen::AngleAxisd(yaw(t) + sway_yaw, Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(sway_roll, Eigen::Vector3d::UnitX()))
               .toRotationMatrix() *
           mount;
  };
  SyntheticWalk w;
  w.duration_s = duration;
  const std::int64_t n = static_cast<std::int64_t>(duration * spec.rate_hz);
  const TimeNs t0_ns = 1'000'000'000;
  for (std::int64_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt;
    const TimeNs t_ns = t0_ns + static_cast<TimeNs>(std::llround(t * 1e9));
    const Eigen::Matrix3d r = orientation(t);
    // body rate over [t - dt/2, t + dt/2] from the relative rotation
    const Eigen::Matrix3d ra = orientation(t - 0.5 * dt), rb = orientation(t + 0.5 * dt);
    const Eigen::AngleAxisd rel(ra.transpose() * rb);
    Eigen::Vector3d rate = rel.axis() * rel.angle() / dt;
    for (int k = 0; k < 3; ++k) rate[k] += spec.gyro_noise_radps * n01(rng);
    rate += spec.gyro_bias_radps;
    const double bounce = spec.bounce_mps2 * std::sin(2 * kPi * spec.cadence_hz * t);
    const Eigen::Vector3d f_world(0, 0, kStandardGravity_mps2 + bounce);
    Eigen::Vector3d f = r.transpose() * f_world;
    for (int k = 0; k < 3; ++k) f[k] += spec.accel_noise_mps2 * n01(rng);
    w.accel.push_back(AccelSample{t_ns, kMissingInt, f});
    w.gyro.push_back(GyroSample{t_ns, kMissingInt, rate});
    const Eigen::Quaterniond q(r);
    w.rotation.push_back(RotationVectorSample{t_ns, kMissingInt, Eigen::Vector4d(q.x(), q.y(), q.z(), q.w()), kNaN});
    w.psi_rad.push_back(yaw(t));
  }
  return w;
}

}  // namespace pdnav::test
