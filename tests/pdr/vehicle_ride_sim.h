// A passenger riding a road vehicle with a hand-held phone, simulated from vehicle physics (not
// from the motion classifier's features): the road is a random profile with the ISO 8608
// displacement PSD Gd(n) = Gd(n0) (n / n0)^-2, n0 = 0.1 cycle/m (class B geometric mean
// 64e-6 m^3, class C 256e-6 m^3), plus a speed hump (75 mm x 3.7 m) and transverse joints;
// two quarter-car models (front and rear axle, the rear one seeing the road a wheelbase later;
// sprung 400 kg, unsprung 40 kg, suspension 20 kN/m and 1.5 kNs/m: body mode 1.1 Hz at damping
// ratio 0.27, tyre 200 kN/m: wheel hop ~12 Hz, the textbook passenger-car values of Gillespie,
// "Fundamentals of Vehicle Dynamics", ch. 5) integrated at 1 kHz; the seat is a 4 Hz, 0.3-damped
// cushion (the seat resonance reported for car and bus seats, Griffin, "Handbook of Human
// Vibration"); engine vibration at the 4-cylinder firing frequency (2 x rpm / 60); a speed
// profile of stops, jerk-limited accelerations of 0.9-1.5 m/s^2 and decelerations of 1.2-2 m/s^2
// (city bus and car service values), cruise at 8-14 m/s, and turns of 30-90 deg whose lateral
// acceleration is v x yaw rate. The phone is held in front (pitch 35 deg) at a seeded yaw to the
// vehicle; the hand wanders by a few degrees at 0.1-0.6 Hz and trembles (9-11 Hz, 0.02 m/s^2).
// Specific force f = R^T (a + g e_up) and the body rate are sampled at 50 Hz with +-1 ms jitter,
// white noise and per-axis biases.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "real_walk.h"

namespace pdnav::test {

struct RideSpec {
  double duration_s = 120.0;
  double rate_hz = 50.0;
  double road_gd_m3 = 64e-6;   // ISO 8608 class B (good urban road); 256e-6 = class C
  double wheelbase_m = 2.7;
  double hump_at_m = 250.0;    // distance of the speed hump (negative: none)
  std::uint64_t seed = 1;
};

struct RideStats {
  double seat_vertical_rms_mps2 = 0.0;  // while moving
  double max_speed_mps = 0.0;
  double max_yaw_rate_radps = 0.0;
};

/// The ride ends at t_end_ns (so a recording can follow it).
inline RealWalk make_ride(const RideSpec& spec, TimeNs t_end_ns, RideStats* stats = nullptr) {
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> n01(0.0, 1.0);
  constexpr double kG = 9.80665, kTwoPi = 2.0 * 3.14159265358979323846, kDeg = 3.14159265358979323846 / 180.0;
  // road: sum of cosines over 0.011-2.83 cycle/m (ISO 8608 band), log-spaced
  const int kWaves = 240;
  std::vector<double> wn(kWaves), wa(kWaves), wph(kWaves);
  const double n_lo = 0.011, n_hi = 2.83;
  for (int i = 0; i < kWaves; ++i) {
    const double n = n_lo * std::pow(n_hi / n_lo, (i + 0.5) / kWaves);
    const double dn = n * std::log(n_hi / n_lo) / kWaves;
    wn[i] = n;
    wa[i] = std::sqrt(2.0 * spec.road_gd_m3 * std::pow(n / 0.1, -2.0) * dn);
    wph[i] = kTwoPi * u01(rng);
  }
  std::vector<double> joints;  // transverse joints / patches: 12 mm dips over 0.4 m
  for (double x = 40.0; x < 3000.0; x += 50.0 + 100.0 * u01(rng)) joints.push_back(x);
  auto road = [&](double x) {
    double z = 0.0;
    for (int i = 0; i < kWaves; ++i) z += wa[i] * std::cos(kTwoPi * wn[i] * x + wph[i]);
    if (spec.hump_at_m >= 0 && x > spec.hump_at_m && x < spec.hump_at_m + 3.7)
      z += 0.075 * std::sin(kTwoPi * 0.5 * (x - spec.hump_at_m) / 3.7);
    for (double j : joints)
      if (x > j && x < j + 0.4) z -= 0.012 * 0.5 * (1.0 - std::cos(kTwoPi * (x - j) / 0.4));
    return z;
  };
  // quarter cars (front, rear): states sprung z, v; unsprung z, v
  const double ms = 400, mu = 40, ks = 20000, cs = 1500, kt = 200000;
  double zs[2] = {0, 0}, vs[2] = {0, 0}, zu[2] = {0, 0}, vu[2] = {0, 0};
  const double wp = kTwoPi * 4.0, zp_damp = 0.3;
  double zp = 0, vp = 0;
  // speed plan: stop, accelerate, cruise (maybe a turn), brake; repeated
  enum Phase { kStop, kAccel, kCruise, kBrake } phase = kStop;
  double phase_left_s = 3.0 + 4.0 * u01(rng), a_cmd = 0, a_act = 0, v = 0, v_target = 0, x = 0, yaw = 0;
  double turn_left_s = 0, turn_len_s = 0, turn_angle = 0;
  const double yaw_rel = kTwoPi * u01(rng);
  double wander_f[3][3], wander_a[3][3], wander_p[3][3];
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      wander_f[k][j] = 0.1 + 0.5 * u01(rng), wander_a[k][j] = (0.7 + 0.6 * u01(rng)) * kDeg, wander_p[k][j] = kTwoPi * u01(rng);
  const double tremor_f = 9.0 + 2.0 * u01(rng);
  const Eigen::Vector3d acc_bias(0.05 * n01(rng), 0.05 * n01(rng), 0.05 * n01(rng));
  const Eigen::Vector3d gyro_bias(0.003 * n01(rng), 0.003 * n01(rng), 0.003 * n01(rng));

  const double dt = 1e-3;
  const int n_steps = static_cast<int>(spec.duration_s / dt);
  const double sample_dt = 1.0 / spec.rate_hz;
  double next_sample = 0.0;
  auto attitude = [&](double t, double yaw_vehicle) {
    double w[3];
    for (int k = 0; k < 3; ++k) {
      w[k] = 0;
      for (int j = 0; j < 3; ++j) w[k] += wander_a[k][j] * std::sin(kTwoPi * wander_f[k][j] * t + wander_p[k][j]);
    }
    // yaw is clockwise from north in navigation; here a right-handed rotation about up (ENU)
    return Eigen::Quaterniond(Eigen::AngleAxisd(yaw_vehicle + yaw_rel + w[0], Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(35.0 * kDeg + w[1], Eigen::Vector3d::UnitX()) *
                              Eigen::AngleAxisd(w[2], Eigen::Vector3d::UnitY()));
  };
  RealWalk out;
  double sum_sq = 0;
  long moving_n = 0;
  RideStats st;
  Eigen::Quaterniond q_prev = attitude(0.0, 0.0);
  double t_prev_sample = -1;
  for (int i = 0; i < n_steps; ++i) {
    const double t = i * dt;
    // --- speed plan
    phase_left_s -= dt;
    switch (phase) {
      case kStop:
        a_cmd = 0;
        if (phase_left_s <= 0) phase = kAccel, v_target = 8.0 + 6.0 * u01(rng), a_cmd = 0.9 + 0.6 * u01(rng);
        break;
      case kAccel:
        if (v >= v_target) phase = kCruise, a_cmd = 0, phase_left_s = 10.0 + 15.0 * u01(rng),
                                turn_left_s = u01(rng) < 0.7 ? 2.0 + 3.0 * u01(rng) : -1;
        break;
      case kCruise:
        if (turn_left_s > 0 && (turn_left_s -= dt) <= 0) {
          turn_len_s = 6.0 + 4.0 * u01(rng);
          turn_angle = (u01(rng) < 0.5 ? -1 : 1) * (30.0 + 60.0 * u01(rng)) * kDeg;
          turn_left_s = -turn_len_s;  // negative: turning, counts up to 0
        } else if (turn_left_s < 0 && turn_len_s > 0) {
          turn_left_s += dt;
          if (turn_left_s >= 0) turn_len_s = 0, turn_left_s = -1;
        }
        if (phase_left_s <= 0) phase = kBrake, a_cmd = -(1.2 + 0.8 * u01(rng));
        break;
      case kBrake:
        if (v <= 0.3) phase = kStop, a_cmd = 0, phase_left_s = 4.0 + 6.0 * u01(rng);
        break;
    }
    a_act += (a_cmd - a_act) * dt / 0.7;  // jerk-limited (first-order, 0.7 s)
    if (phase == kStop) v = std::max(0.0, v - 2.0 * dt), a_act = v > 0 ? a_act : 0.0;
    v = std::max(0.0, v + a_act * dt);
    const double a_long = v > 0 ? a_act : 0.0;
    double yaw_rate = 0;
    if (turn_len_s > 0 && turn_left_s < 0) {
      const double s = (turn_left_s + turn_len_s) / turn_len_s;  // 0..1
      yaw_rate = turn_angle / turn_len_s * (1.0 - std::cos(kTwoPi * s));  // raised cosine, integral = angle
    }
    yaw += yaw_rate * dt;
    x += v * dt;
    // --- suspension and seat
    double acc_body = 0;
    for (int k = 0; k < 2; ++k) {
      const double zr = v > 0 || x > 0 ? road(x - k * spec.wheelbase_m) : 0.0;
      const double fs = -ks * (zs[k] - zu[k]) - cs * (vs[k] - vu[k]);
      const double as = fs / ms, au = (-fs - kt * (zu[k] - zr)) / mu;
      vs[k] += as * dt, vu[k] += au * dt;
      zs[k] += vs[k] * dt, zu[k] += vu[k] * dt;
      acc_body += 0.5 * as;
    }
    const double zb = 0.5 * (zs[0] + zs[1]), vb = 0.5 * (vs[0] + vs[1]);
    const double ap = -wp * wp * (zp - zb) - 2 * zp_damp * wp * (vp - vb);
    vp += ap * dt, zp += vp * dt;
    (void)acc_body;
    const double rpm = 800.0 + 1700.0 * std::min(1.0, v / 14.0) + 600.0 * std::max(0.0, a_long);
    const double f_fire = 2.0 * rpm / 60.0;
    const double engine_v = 0.04 * std::sin(kTwoPi * f_fire * t), engine_l = 0.03 * std::sin(kTwoPi * f_fire * t + 1.0);
    if (v > 1.0) sum_sq += ap * ap, ++moving_n;
    st.max_speed_mps = std::max(st.max_speed_mps, v);
    st.max_yaw_rate_radps = std::max(st.max_yaw_rate_radps, std::abs(yaw_rate));
    if (t + 1e-12 < next_sample) continue;
    next_sample += sample_dt;
    // --- phone
    const Eigen::Vector3d fwd(std::cos(yaw + 1.5707963267948966), std::sin(yaw + 1.5707963267948966), 0);  // vehicle +Y at yaw 0
    const Eigen::Vector3d left(-fwd.y(), fwd.x(), 0);
    const Eigen::Vector3d a_world = a_long * fwd + v * yaw_rate * left + engine_l * left +
                                    Eigen::Vector3d(0, 0, ap + engine_v);
    const Eigen::Quaterniond q = attitude(t, yaw);
    Eigen::Vector3d f = q.conjugate() * (a_world + Eigen::Vector3d(0, 0, kG));
    for (int k = 0; k < 3; ++k) f[k] += 0.02 * std::sin(kTwoPi * tremor_f * t + k) + 0.03 * n01(rng);
    f += acc_bias;
    Eigen::Vector3d rate = Eigen::Vector3d::Zero();
    if (t_prev_sample >= 0) {
      const Eigen::AngleAxisd rel(q_prev.conjugate() * q);
      rate = rel.axis() * rel.angle() / (t - t_prev_sample);
    }
    q_prev = q;
    t_prev_sample = t;
    rate += gyro_bias + Eigen::Vector3d(0.004 * n01(rng), 0.004 * n01(rng), 0.004 * n01(rng));
    const double jitter_s = 0.001 * (2.0 * u01(rng) - 1.0);
    const TimeNs t_ns = t_end_ns - static_cast<TimeNs>(std::llround((spec.duration_s - t - jitter_s) * 1e9));
    out.accel.push_back({t_ns, kMissingInt, f});
    out.gyro.push_back({t_ns, kMissingInt, rate});
  }
  st.seat_vertical_rms_mps2 = moving_n > 0 ? std::sqrt(sum_sq / moving_n) : 0.0;
  if (stats) *stats = st;
  return out;
}

}  // namespace pdnav::test
