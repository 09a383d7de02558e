// Compass-calibration waving ahead of a real recording (phonesim/handling.h).
#include "pdnav/phonesim/handling.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "pdnav/geo/units.h"

namespace pdnav::phonesim {

std::vector<Eigen::Vector3d> running_mean_residuals(const std::vector<Eigen::Vector3d>& samples, std::size_t count) {
  std::vector<Eigen::Vector3d> out;
  constexpr std::size_t kHalf = 5;
  for (std::size_t i = kHalf; i < kHalf + count && i + kHalf < samples.size(); ++i) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t k = i - kHalf; k < i + kHalf; ++k) mean += samples[k];
    out.push_back(samples[i] - mean / static_cast<double>(2 * kHalf));
  }
  return out;
}

namespace {

/// The wrist's rotation in the phone frame at phase ph (fade 0 = none).
Eigen::Quaterniond wrist(double ph, double fade) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(fade * 70 * kDegToRad * std::sin(ph), Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(fade * 55 * kDegToRad * std::sin(2 * ph + 0.6), Eigen::Vector3d::UnitX()) *
                            Eigen::AngleAxisd(fade * 35 * kDegToRad * std::sin(0.5 * ph + 1.1), Eigen::Vector3d::UnitY()));
}

/// Phone -> ENU attitude the waving ends in: the rotation vector, else gravity alone (yaw 0).
Eigen::Quaterniond end_attitude(const WavingEnd& end) {
  if (end.rotation_xyzw) return Eigen::Quaterniond(*end.rotation_xyzw).normalized();  // Eigen's coefficient order is x, y, z, w
  const Eigen::Vector3d up_phone = end.accel_phone_mps2.norm() > 0 ? end.accel_phone_mps2.normalized() : Eigen::Vector3d::UnitZ();
  return Eigen::Quaterniond::FromTwoVectors(up_phone, Eigen::Vector3d::UnitZ());
}

Eigen::Vector3d cycled(const std::vector<Eigen::Vector3d>& v, std::size_t i) {
  return v.empty() ? Eigen::Vector3d::Zero() : v[i % v.size()];
}

}  // namespace

WavingSamples synthesize_waving(const WavingEnd& end, const WavingOptions& options) {
  WavingSamples out;
  if (!(options.seconds > 0.0) || !(options.rate_hz > 0.0)) return out;
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double dt = 1.0 / options.rate_hz, g = end.accel_phone_mps2.norm() > 0 ? end.accel_phone_mps2.norm() : 9.81;
  const int n = static_cast<int>(options.seconds * options.rate_hz);
  const Eigen::Quaterniond q_end = end_attitude(end);
  const Eigen::Vector3d field_enu = end.field_phone_ut ? Eigen::Vector3d(q_end * *end.field_phone_ut) : Eigen::Vector3d::Zero();
  double phase = 0.0, f_hz = 0.9;
  Eigen::Quaterniond prev = q_end;
  for (int i = 0; i < n; ++i) {
    const double t = i * dt;
    f_hz = std::clamp(f_hz + 0.05 * n01(rng), 0.6, 1.2);
    phase += 2 * kPi * f_hz * dt;
    const double fade = std::max(0.0, options.amplitude * std::min({1.0, t / 1.0, (options.seconds - t) / 1.0}));
    const Eigen::Quaterniond q = q_end * wrist(phase, fade);  // phone -> ENU
    const Eigen::AngleAxisd rel(prev.conjugate() * q);      // body-frame increment
    prev = q;
    Eigen::Vector3d rate = i == 0 || rel.angle() < 1e-12 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(rel.axis() * rel.angle() / dt);
    // hand translation in ENU, 1.5-3 m/s^2
    const Eigen::Vector3d hand(2.5 * std::sin(phase + 0.3), 1.5 * std::sin(2 * phase), 3.0 * std::sin(phase * 1.5 + 2.0));
    const Eigen::Vector3d f = q.conjugate() * (Eigen::Vector3d(0, 0, g) + fade * hand) + cycled(end.accel_noise_mps2, i);
    rate += cycled(end.gyro_noise_radps, i);
    const TimeNs t_ns = end.t_end_ns - static_cast<TimeNs>(std::llround((n - 1 - i) * dt * 1e9));
    out.accel.push_back({t_ns, kMissingInt, f});
    out.gyro.push_back({t_ns, kMissingInt, rate});
    if (end.rotation_xyzw) out.rotation.push_back({t_ns, kMissingInt, q.coeffs(), kNaN});
    if (end.field_phone_ut) out.mag.push_back({t_ns, kMissingInt, q.conjugate() * field_enu});
  }
  return out;
}

}  // namespace pdnav::phonesim
