#include "pdnav/gnss/glonass.h"

#include <algorithm>
#include <cmath>

#include "pdnav/gnss/ephemeris.h"

namespace pdnav::gnss {

GlonassOrbitState glonass_derivative(const GlonassOrbitState& s, const Eigen::Vector3d& luni_solar_mps2) {
  using C = GlonassConstants;
  const Eigen::Vector3d& r = s.pos_m;
  const Eigen::Vector3d& v = s.vel_mps;
  const double r2 = r.squaredNorm();
  const double rn = std::sqrt(r2);
  const double mu_r3 = C::gm_m3ps2 / (r2 * rn);
  const double j2_term = 1.5 * C::j2 * C::gm_m3ps2 * C::ae_m * C::ae_m / (r2 * r2 * rn);
  const double z2_r2 = r.z() * r.z() / r2;
  const double w2 = C::omega_radps * C::omega_radps;
  GlonassOrbitState d;
  d.pos_m = v;
  d.vel_mps.x() = -mu_r3 * r.x() - j2_term * r.x() * (1.0 - 5.0 * z2_r2) + w2 * r.x() +
                  2.0 * C::omega_radps * v.y() + luni_solar_mps2.x();
  d.vel_mps.y() = -mu_r3 * r.y() - j2_term * r.y() * (1.0 - 5.0 * z2_r2) + w2 * r.y() -
                  2.0 * C::omega_radps * v.x() + luni_solar_mps2.y();
  d.vel_mps.z() = -mu_r3 * r.z() - j2_term * r.z() * (3.0 - 5.0 * z2_r2) + luni_solar_mps2.z();
  return d;
}

namespace {
GlonassOrbitState axpy(const GlonassOrbitState& s, double h, const GlonassOrbitState& d) {
  return {s.pos_m + h * d.pos_m, s.vel_mps + h * d.vel_mps};
}

GlonassOrbitState rk4_step(const GlonassOrbitState& s, const Eigen::Vector3d& acc, double h) {
  const GlonassOrbitState k1 = glonass_derivative(s, acc);
  const GlonassOrbitState k2 = glonass_derivative(axpy(s, h / 2, k1), acc);
  const GlonassOrbitState k3 = glonass_derivative(axpy(s, h / 2, k2), acc);
  const GlonassOrbitState k4 = glonass_derivative(axpy(s, h, k3), acc);
  GlonassOrbitState out;
  out.pos_m = s.pos_m + h / 6.0 * (k1.pos_m + 2.0 * k2.pos_m + 2.0 * k3.pos_m + k4.pos_m);
  out.vel_mps = s.vel_mps + h / 6.0 * (k1.vel_mps + 2.0 * k2.vel_mps + 2.0 * k3.vel_mps + k4.vel_mps);
  return out;
}
}  // namespace

GlonassOrbitState glonass_propagate(const GlonassOrbitState& s0, const Eigen::Vector3d& luni_solar_mps2,
                                    double dt_s, double max_step_s) {
  const double step = std::max(std::abs(max_step_s), 1e-3);
  const int n = std::max(1, static_cast<int>(std::ceil(std::abs(dt_s) / step)));
  const double h = dt_s / n;
  GlonassOrbitState s = s0;
  for (int i = 0; i < n; ++i) s = rk4_step(s, luni_solar_mps2, h);
  return s;
}

SatState glonass_state(const GlonassEphemeris& eph, TimeNs gps_ns) {
  const double dt = ns_to_s(gps_ns - eph.tb_gps_ns);
  const GlonassOrbitState s = glonass_propagate({eph.pos_m, eph.vel_mps}, eph.acc_mps2, dt);
  SatState out;
  out.pos = geo::Ecef(s.pos_m);
  out.vel_mps = s.vel_mps;
  // GLONASS ICD 3.3.3: t_sys = t_sv + tau_n - gamma_n (t_sv - tb); RINEX stores -tau_n.
  out.clock_bias_s = eph.minus_tau_n_s + eph.gamma_n * dt;
  out.clock_drift_sps = eph.gamma_n;
  out.group_delay_s = 0.0;
  out.glonass_channel = eph.channel;
  out.healthy = eph.health == 0;
  out.toe_gps_ns = eph.tb_gps_ns;
  out.iode = static_cast<int>((eph.tb_gps_ns / kNsPerS) % 86400 / 900);
  return out;
}

}  // namespace pdnav::gnss
