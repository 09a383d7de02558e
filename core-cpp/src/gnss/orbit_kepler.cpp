// Keplerian broadcast orbit and clock: IS-GPS-200 20.3.3.4.3 (Table 20-IV) and
// 20.3.3.3.3.1 (clock, relativistic term); Galileo OS SIS ICD 5.1.1 / 5.1.4; BeiDou
// BDS-SIS-ICD-B1I 5.2.4.12 (GEO satellites: extra rotation by -5 deg about X, then by
// Omega_e * tk about Z).
#include <cmath>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/ephemeris.h"

namespace pdnav::gnss {
namespace {

struct SystemConstants {
  double gm_m3ps2;
  double omega_e_radps;
};

SystemConstants constants_for(Constellation sys) {
  switch (sys) {
    case Constellation::kGalileo: return {3.986004418e14, 7.2921151467e-5};  // OS SIS ICD 5.1.1
    case Constellation::kBeidou: return {3.986004418e14, 7.2921150e-5};      // BDS ICD 5.2.4.11
    default: return {3.986005e14, 7.2921151467e-5};                          // IS-GPS-200 (GPS, QZSS)
  }
}

/// Seconds of week of the ephemeris reference time in the satellite's own system time.
double toe_seconds_of_week(const KeplerEphemeris& eph) {
  TimeNs t = eph.toe_gps_ns;
  if (eph.sat.sys == Constellation::kBeidou) t -= 14 * kNsPerS;  // BDT = GPST - 14 s
  return geo::gps_ns_to_week_tow(t).tow_s;
}

struct OrbitPoint {
  Eigen::Vector3d pos_m;
  double ecc_anomaly_rad;
};

OrbitPoint kepler_position(const KeplerEphemeris& eph, double tk_s) {
  const SystemConstants k = constants_for(eph.sat.sys);
  const double a = eph.sqrt_a_sqrtm * eph.sqrt_a_sqrtm;
  const double n = std::sqrt(k.gm_m3ps2 / (a * a * a)) + eph.delta_n_radps;
  const double mk = eph.m0_rad + n * tk_s;
  double ek = mk;
  for (int i = 0; i < 30; ++i) {  // Newton on Kepler's equation M = E - e sin E
    const double d = (ek - eph.e * std::sin(ek) - mk) / (1.0 - eph.e * std::cos(ek));
    ek -= d;
    if (std::abs(d) < 1e-14) break;
  }
  const double vk = std::atan2(std::sqrt(1.0 - eph.e * eph.e) * std::sin(ek), std::cos(ek) - eph.e);
  const double phik = vk + eph.omega_rad;
  const double s2 = std::sin(2.0 * phik), c2 = std::cos(2.0 * phik);
  const double uk = phik + eph.cus_rad * s2 + eph.cuc_rad * c2;
  const double rk = a * (1.0 - eph.e * std::cos(ek)) + eph.crs_m * s2 + eph.crc_m * c2;
  const double ik = eph.i0_rad + eph.idot_radps * tk_s + eph.cis_rad * s2 + eph.cic_rad * c2;
  const double xp = rk * std::cos(uk), yp = rk * std::sin(uk);
  const double toe_sow = toe_seconds_of_week(eph);
  const double ci = std::cos(ik), si = std::sin(ik);
  if (eph.bds_geo) {
    // BDS GEO: position in the user-defined inertial-like frame, then R_Z(we tk) R_X(-5 deg).
    const double om = eph.omega0_rad + eph.omega_dot_radps * tk_s - k.omega_e_radps * toe_sow;
    const double co = std::cos(om), so = std::sin(om);
    const Eigen::Vector3d g(xp * co - yp * ci * so, xp * so + yp * ci * co, yp * si);
    const double phi = -5.0 * kDegToRad, cp = std::cos(phi), sp = std::sin(phi);
    const Eigen::Vector3d rx(g.x(), cp * g.y() + sp * g.z(), -sp * g.y() + cp * g.z());
    const double z = k.omega_e_radps * tk_s, cz = std::cos(z), sz = std::sin(z);
    return {Eigen::Vector3d(cz * rx.x() + sz * rx.y(), -sz * rx.x() + cz * rx.y(), rx.z()), ek};
  }
  const double om = eph.omega0_rad + (eph.omega_dot_radps - k.omega_e_radps) * tk_s - k.omega_e_radps * toe_sow;
  const double co = std::cos(om), so = std::sin(om);
  return {Eigen::Vector3d(xp * co - yp * ci * so, xp * so + yp * ci * co, yp * si), ek};
}

/// Clock offset incl. relativistic term F e sqrt(A) sin(E) (IS-GPS-200 20.3.3.3.3.1).
double clock_offset_s(const KeplerEphemeris& eph, double t_minus_toc_s, double ecc_anomaly_rad) {
  const SystemConstants k = constants_for(eph.sat.sys);
  const double f = -2.0 * std::sqrt(k.gm_m3ps2) / (kSpeedOfLight_mps * kSpeedOfLight_mps);
  const double dt = t_minus_toc_s;
  return eph.af0_s + eph.af1_sps * dt + eph.af2_sps2 * dt * dt +
         f * eph.e * eph.sqrt_a_sqrtm * std::sin(ecc_anomaly_rad);
}

}  // namespace

SatState kepler_state(const KeplerEphemeris& eph, TimeNs gps_ns) {
  const double tk = ns_to_s(gps_ns - eph.toe_gps_ns);
  const double tc = ns_to_s(gps_ns - eph.toc_gps_ns);
  constexpr double h = 0.5;  // central-difference half step [s] for velocity and drift
  const OrbitPoint p0 = kepler_position(eph, tk);
  const OrbitPoint pm = kepler_position(eph, tk - h);
  const OrbitPoint pp = kepler_position(eph, tk + h);
  SatState s;
  s.pos = geo::Ecef(p0.pos_m);
  s.vel_mps = (pp.pos_m - pm.pos_m) / (2.0 * h);
  s.clock_bias_s = clock_offset_s(eph, tc, p0.ecc_anomaly_rad);
  s.clock_drift_sps = (clock_offset_s(eph, tc + h, pp.ecc_anomaly_rad) -
                       clock_offset_s(eph, tc - h, pm.ecc_anomaly_rad)) / (2.0 * h);
  s.group_delay_s = eph.group_delay_s;
  s.healthy = eph.health == 0.0;
  s.toe_gps_ns = eph.toe_gps_ns;
  s.iode = eph.iode;
  return s;
}

}  // namespace pdnav::gnss
