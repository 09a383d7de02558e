// A phone carried in a swinging hand, simulated from the physics (not from the step detector's
// model): the arm is a damped physical pendulum hanging from the shoulder, driven by a shoulder
// torque at the STRIDE frequency and shaken by the shoulder's own motion (the body's vertical
// bounce and fore-aft surge at the STEP frequency, lateral sway at the stride frequency, and a
// heel-strike transient at every foot contact). The phone rigidly held in the hand rotates with
// the arm, so gravity turns in the phone frame; the hand's acceleration carries the tangential
// (r theta'') and centripetal (r theta'^2) terms. Specific force f = R^T (a_hand + g e_up) is
// sampled at ~100 Hz with timing jitter, white noise, a per-axis bias and 16-bit quantisation.
//
// Numbers (docs/pdr.md, "Swinging hand"): pendulum length 0.35 m to the arm's centre of
// percussion (natural period ~1.2 s, close to the stride period, which is why arms swing),
// hand 0.65 m from the shoulder, swing +-20-35 deg with a forward offset, COM bounce
// 2-3 cm (about +-3 m/s^2 at 1.8 Hz), heel strikes 2-4 m/s^2 at the shoulder decaying in ~25 ms
// at ~14 Hz, left/right asymmetry 15 %. The right arm is fully forward at the left heel strike.
#pragma once
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "pdnav/geo/samples.h"

namespace pdnav::test {

struct SwingSpec {
  double rate_hz = 100.0;
  double cadence_hz = 1.8;          // steps per second (stride = cadence / 2)
  double swing_amplitude_deg = 28.0;  // arm swing amplitude about the offset
  double swing_offset_deg = 6.0;    // forward bias of the swing
  double pendulum_length_m = 0.35;  // equivalent simple-pendulum length of the arm (dynamics)
  double upper_arm_m = 0.30;        // shoulder -> elbow (kinematics)
  double forearm_m = 0.36;          // elbow -> phone in the hand
  double elbow_flexion_deg = 25.0;  // mean elbow flexion while walking
  double elbow_swing_deg = 15.0;    // extra flexion on the forward swing (in phase with theta)
  double damping_ratio = 0.35;      // arm damping (muscle + joint), fraction of critical
  double bounce_m = 0.025;          // COM vertical oscillation amplitude (step frequency)
  double surge_m = 0.008;           // fore-aft oscillation amplitude (step frequency)
  double sway_m = 0.02;             // lateral oscillation amplitude (stride frequency)
  double heel_strike_mps2 = 3.0;    // shoulder vertical transient at each foot contact
  double wrist_roll_deg = 10.0;     // forearm pronation/supination with the swing
  double grip_tilt_deg = 20.0;      // phone long axis vs the arm
  double cadence_jitter = 0.03;     // random-walk spread of the cadence (fraction)
  double amplitude_jitter = 0.10;   // stride-to-stride spread of the swing drive (fraction)
  double accel_noise_mps2 = 0.04;
  double gyro_noise_radps = 0.005;
  double accel_bias_mps2 = 0.08;
  double still_before_s = 3.0;      // standing (arm at rest) before and after the walk
  double still_after_s = 3.0;
  int steps = 120;                  // true steps (heel strikes) in the walk
  std::uint64_t seed = 7;
};

struct SwingWalk {
  std::vector<AccelSample> accel;
  std::vector<GyroSample> gyro;  // the phone's angular rate, phone axes, at the accelerometer's times
  std::vector<TimeNs> heel_strikes_ns;  // truth
};

inline SwingWalk make_swinging_walk(const SwingSpec& spec) {
  std::mt19937_64 rng(spec.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double g = kStandardGravity_mps2;
  constexpr double kSimDt = 0.0005;  // integration step (2 kHz)
  // Heel-strike times: cadence as a bounded random walk, a ramp-up of 2 steps.
  std::vector<double> strikes;
  double t = spec.still_before_s, cadence = spec.cadence_hz;
  for (int k = 0; k < spec.steps; ++k) {
    strikes.push_back(t);
    cadence = spec.cadence_hz * (1.0 + std::clamp(std::log(cadence / spec.cadence_hz) + 0.3 * spec.cadence_jitter * n01(rng),
                                                 -2.0 * spec.cadence_jitter, 2.0 * spec.cadence_jitter));
    const double ramp = k == 0 ? 1.35 : k == 1 ? 1.15 : 1.0;  // first steps are slower
    t += ramp / cadence;
  }
  const double walk_end = strikes.back() + 1.0 / spec.cadence_hz;
  const double duration = walk_end + spec.still_after_s;
  // Gait phase phi(t) in steps (integer at each heel strike); walking intensity 0..1.
  auto step_phase = [&](double tt, double* intensity) {
    if (tt < strikes.front()) {
      *intensity = std::max(0.0, 1.0 - (strikes.front() - tt) * spec.cadence_hz);  // ramp-in over one step
      return (tt - strikes.front()) * spec.cadence_hz;
    }
    if (tt >= strikes.back()) {
      const double p = static_cast<double>(strikes.size() - 1) + (tt - strikes.back()) * spec.cadence_hz;
      *intensity = std::max(0.0, 1.0 - (tt - strikes.back()) * spec.cadence_hz);  // comes to rest in a step
      return p;
    }
    const auto it = std::upper_bound(strikes.begin(), strikes.end(), tt);
    const std::size_t k = static_cast<std::size_t>(it - strikes.begin()) - 1;
    *intensity = 1.0;
    return static_cast<double>(k) + (tt - strikes[k]) / (strikes[k + 1] - strikes[k]);
  };
  // Shoulder acceleration in the world (x forward, y left, z up) from the gait phase.
  std::vector<double> drive_scale;
  for (std::size_t k = 0; k <= strikes.size() / 2 + 1; ++k) {
    drive_scale.push_back(1.0 + spec.amplitude_jitter * std::clamp(n01(rng), -2.0, 2.0));
  }
  auto shoulder_acc = [&](double tt, double* phase_out, double* intensity_out) {
    double inten = 0.0;
    const double phi = step_phase(tt, &inten);
    const double w_step = 2.0 * kPi * spec.cadence_hz;
    const double ps = 2.0 * kPi * phi;  // step-phase angle
    Eigen::Vector3d a;
    // COM lowest just after heel strike (double support), highest at mid-stance.
    a.z() = inten * spec.bounce_m * w_step * w_step * std::cos(ps - 0.6);
    a.x() = inten * spec.surge_m * w_step * w_step * std::sin(ps + 0.4);
    a.y() = inten * spec.sway_m * (0.25 * w_step * w_step) * std::sin(0.5 * ps);
    // Heel-strike transient (alternate feet 15 % different), decaying damped oscillation.
    if (tt >= strikes.front() - 1e-9) {
      const auto it = std::upper_bound(strikes.begin(), strikes.end(), tt);
      const std::size_t k = static_cast<std::size_t>(it - strikes.begin()) - 1;
      const double dt_hs = tt - strikes[k];
      const double amp = spec.heel_strike_mps2 * ((k % 2 == 0) ? 1.0 : 0.85);
      const double env = std::exp(-dt_hs / 0.025);
      a.z() += amp * env * std::sin(2.0 * kPi * 14.0 * dt_hs + 0.3);
      a.x() -= 0.4 * amp * env * std::sin(2.0 * kPi * 14.0 * dt_hs);
    }
    *phase_out = phi;
    *intensity_out = inten;
    return a;
  };
  // Pendulum: theta'' = -(g + a_z)/L sin(theta) - a_x/L cos(theta) - 2 zeta w0 theta' + tau(t).
  // The drive tau is at the stride frequency, its amplitude from the linear response so the
  // swing reaches the target; the right arm is fully forward at the left (odd) heel strike.
  const double L = spec.pendulum_length_m;
  const double w0 = std::sqrt(g / L);
  const double w_stride = kPi * spec.cadence_hz;
  const double gain = 1.0 / std::hypot(w0 * w0 - w_stride * w_stride, 2.0 * spec.damping_ratio * w0 * w_stride);
  const double phase_lag = std::atan2(2.0 * spec.damping_ratio * w0 * w_stride, w0 * w0 - w_stride * w_stride);
  const double drive_amp = spec.swing_amplitude_deg * kDegToRad / gain;
  const double drive_offset = spec.swing_offset_deg * kDegToRad * w0 * w0;
  double theta = 0.0, omega = 0.0;
  auto theta_dd = [&](double tt, double th, double om, Eigen::Vector3d* a_sh) {
    double phi = 0.0, inten = 0.0;
    const Eigen::Vector3d a = shoulder_acc(tt, &phi, &inten);
    if (a_sh) *a_sh = a;
    const std::size_t stride = static_cast<std::size_t>(std::max(0.0, std::floor(phi / 2.0)));
    const double scale = drive_scale[std::min(stride, drive_scale.size() - 1)];
    // Arm forward (theta max) at odd strikes: stride phase pi*phi - pi/2 at phi = 1 -> peak.
    const double tau = inten * (drive_offset + scale * drive_amp * std::sin(kPi * phi - kPi / 2.0 + phase_lag));
    return -(g + a.z()) / L * std::sin(th) - a.x() / L * std::cos(th) - 2.0 * spec.damping_ratio * w0 * om + tau;
  };
  const double l1 = spec.upper_arm_m, l2 = spec.forearm_m;
  const Eigen::Matrix3d grip = (Eigen::AngleAxisd(spec.grip_tilt_deg * kDegToRad, Eigen::Vector3d::UnitZ())).toRotationMatrix();
  // Phone axes in the arm frame (arm along -z when theta = 0): phone +Y down the arm, +Z (screen)
  // toward the body (+y world for a right hand), +X = Y x Z forward.
  Eigen::Matrix3d phone_in_arm;
  phone_in_arm.col(0) = Eigen::Vector3d::UnitX();
  phone_in_arm.col(1) = -Eigen::Vector3d::UnitZ();
  phone_in_arm.col(2) = Eigen::Vector3d::UnitY();
  std::uniform_real_distribution<double> jitter(-0.001, 0.001);
  const Eigen::Vector3d bias(spec.accel_bias_mps2 * n01(rng), spec.accel_bias_mps2 * n01(rng), spec.accel_bias_mps2 * n01(rng));
  SwingWalk out;
  for (double s : strikes) out.heel_strikes_ns.push_back(1'000'000'000 + static_cast<TimeNs>(std::llround(s * 1e9)));
  double next_sample = 0.0;
  const double sample_dt = 1.0 / spec.rate_hz;
  Eigen::Matrix3d prev_rot = Eigen::Matrix3d::Identity();
  double prev_rot_t = 0.0;
  bool have_prev_rot = false;
  std::mt19937_64 gyro_rng(spec.seed ^ 0x9E3779B97F4A7C15ULL);  // its own stream: the accelerometer's noise is as before
  constexpr double kQuantum = 19.6133 * 2.0 / 65536.0;  // +-2 g in 16 bits
  for (double tt = 0.0; tt < duration; tt += kSimDt) {
    // RK4 on (theta, omega)
    const double k1t = omega, k1o = theta_dd(tt, theta, omega, nullptr);
    const double k2t = omega + 0.5 * kSimDt * k1o, k2o = theta_dd(tt + 0.5 * kSimDt, theta + 0.5 * kSimDt * k1t, k2t, nullptr);
    const double k3t = omega + 0.5 * kSimDt * k2o, k3o = theta_dd(tt + 0.5 * kSimDt, theta + 0.5 * kSimDt * k2t, k3t, nullptr);
    const double k4t = omega + kSimDt * k3o, k4o = theta_dd(tt + kSimDt, theta + kSimDt * k3t, k4t, nullptr);
    if (tt + kSimDt > next_sample) {
      // Hand acceleration: shoulder + upper arm (angle theta) + forearm (angle theta + elbow),
      // each segment l (alpha'' e_t + alpha'^2 e_r). The elbow flexes more on the forward
      // swing: elbow = flex0 + flex1 * (theta - offset) / amplitude, differentiated exactly.
      Eigen::Vector3d a_sh;
      const double thdd = theta_dd(tt, theta, omega, &a_sh);
      double phi = 0.0, inten = 0.0;
      (void)shoulder_acc(tt, &phi, &inten);
      const double k_el = inten * spec.elbow_swing_deg / std::max(1.0, spec.swing_amplitude_deg);
      const double elbow = inten * spec.elbow_flexion_deg * kDegToRad + k_el * (theta - spec.swing_offset_deg * kDegToRad);
      auto seg = [](double l, double a, double ad, double add) {
        const Eigen::Vector3d e_radial(-std::sin(a), 0.0, std::cos(a));  // toward the joint
        const Eigen::Vector3d e_tangent(std::cos(a), 0.0, std::sin(a));
        return Eigen::Vector3d(l * add * e_tangent + l * ad * ad * e_radial);
      };
      const double fore = theta + elbow, fore_d = omega * (1.0 + k_el), fore_dd = thdd * (1.0 + k_el);
      const Eigen::Vector3d a_hand = a_sh + seg(l1, theta, omega, thdd) + seg(l2, fore, fore_d, fore_dd);
      const double roll = inten * spec.wrist_roll_deg * kDegToRad * std::sin(kPi * phi);
      const Eigen::Matrix3d arm = Eigen::AngleAxisd(-fore, Eigen::Vector3d::UnitY()).toRotationMatrix();
      const Eigen::Matrix3d rot = arm * phone_in_arm * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitY()) * grip;
      Eigen::Vector3d f = rot.transpose() * (a_hand + Eigen::Vector3d(0.0, 0.0, g));
      for (int k = 0; k < 3; ++k) {
        f[k] += bias[k] + spec.accel_noise_mps2 * n01(rng);
        f[k] = kQuantum * std::round(f[k] / kQuantum);
      }
      const TimeNs t_ns = 1'000'000'000 + static_cast<TimeNs>(std::llround((tt + jitter(rng)) * 1e9));
      // Angular rate in phone axes from the attitude change since the last sample.
      Eigen::Vector3d w = Eigen::Vector3d::Zero();
      if (have_prev_rot) {
        const Eigen::AngleAxisd d(prev_rot.transpose() * rot);
        w = d.axis() * d.angle() / (tt - prev_rot_t);
      }
      for (int k = 0; k < 3; ++k) w[k] += spec.gyro_noise_radps * n01(gyro_rng);
      prev_rot = rot;
      prev_rot_t = tt;
      have_prev_rot = true;
      if (out.accel.empty() || t_ns > out.accel.back().t_ns) {
        out.accel.push_back(AccelSample{t_ns, kMissingInt, f});
        out.gyro.push_back(GyroSample{t_ns, kMissingInt, w});
      }
      next_sample += sample_dt;
    }
    theta += kSimDt / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t);
    omega += kSimDt / 6.0 * (k1o + 2.0 * k2o + 2.0 * k3o + k4o);
  }
  return out;
}

}  // namespace pdnav::test
