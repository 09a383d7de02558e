#include "pdnav/gnss/solver_synthetic.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "pdnav/gnss/spp.h"

namespace pdnav::gnss {

std::vector<SyntheticSat> synthetic_sky(const geo::Ecef& rx, int n, std::uint64_t seed,
                                        const std::vector<Constellation>& systems) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.1, 0.1);
  const geo::Geodetic g = geo::to_geodetic(rx);
  const Eigen::Matrix3d enu_to_ecef = geo::ecef_to_enu_rotation(g).transpose();
  constexpr double kOrbitRadiusM = 26'560'000.0, kSpeedMps = 3870.0;
  std::vector<SyntheticSat> sky;
  for (int i = 0; i < n; ++i) {
    const double az = std::fmod(i * 2.39996323 + jitter(rng), 2.0 * kPi);
    const double el = deg_to_rad(15.0 + 70.0 * (0.5 + 0.5 * std::sin(1.7 * i + jitter(rng))));
    const Eigen::Vector3d los_enu(std::cos(el) * std::sin(az), std::cos(el) * std::cos(az), std::sin(el));
    const Eigen::Vector3d u = enu_to_ecef * los_enu;
    // range r along u such that |rx + r u| = orbit radius
    const double b = rx.p_m.dot(u), c = rx.p_m.squaredNorm() - kOrbitRadiusM * kOrbitRadiusM;
    const double r = -b + std::sqrt(b * b - c);
    SyntheticSat s;
    s.sat = SatId{systems[static_cast<std::size_t>(i) % systems.size()], i + 1};
    s.state.pos = geo::Ecef(rx.p_m + r * u);
    const Eigen::Vector3d radial = s.state.pos.p_m.normalized();
    Eigen::Vector3d along = radial.cross(Eigen::Vector3d::UnitZ());
    if (along.norm() < 1e-6) along = Eigen::Vector3d::UnitX();
    s.state.vel_mps = along.normalized() * kSpeedMps * (i % 2 == 0 ? 1.0 : -1.0);
    s.state.clock_bias_s = 1e-5 * jitter(rng);
    s.state.clock_drift_sps = 1e-11 * jitter(rng);
    s.state.group_delay_s = 5e-9 * jitter(rng);
    sky.push_back(s);
  }
  return sky;
}

std::vector<SyntheticSat> propagate_sky(const std::vector<SyntheticSat>& sky, double dt_s) {
  std::vector<SyntheticSat> out = sky;
  for (auto& s : out) {
    s.state.pos.p_m += s.state.vel_mps * dt_s;
    s.state.clock_bias_s += s.state.clock_drift_sps * dt_s;
  }
  return out;
}

double sagnac_range_m(const Eigen::Vector3d& sat, const Eigen::Vector3d& rx) {
  double range = (sat - rx).norm();
  for (int k = 0; k < 4; ++k) range = (rotate_for_travel_time(sat, range / kSpeedOfLight_mps) - rx).norm();
  return range;
}

double range_rate_mps(const SatState& st, const Eigen::Vector3d& rx, const Eigen::Vector3d& rx_vel) {
  const double travel_s = sagnac_range_m(st.pos.p_m, rx) / kSpeedOfLight_mps;
  const Eigen::Vector3d sat = rotate_for_travel_time(st.pos.p_m, travel_s);
  const Eigen::Vector3d vel = rotate_for_travel_time(st.vel_mps, travel_s);
  return (vel - rx_vel).dot((sat - rx).normalized());
}

}  // namespace pdnav::gnss
