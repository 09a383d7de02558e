// GLONASS broadcast orbit propagation (GLONASS ICD edition 5.1, 2008, A.3.1.2): the PZ-90
// state at tb is integrated with 4th-order Runge-Kutta in the rotating Earth-fixed frame
// with the central term, J2 (C20), centrifugal and Coriolis terms and the broadcast
// luni-solar acceleration (held constant over the interval).
#pragma once
#include <Eigen/Core>

namespace pdnav::gnss {

struct GlonassConstants {
  static constexpr double gm_m3ps2 = 398600.4418e9;  // PZ-90 geocentric gravitational constant
  static constexpr double ae_m = 6378136.0;          // PZ-90 semi-major axis
  static constexpr double j2 = 1082.62575e-6;        // second zonal harmonic (-C20)
  static constexpr double omega_radps = 7.292115e-5; // Earth rotation rate
};

struct GlonassOrbitState {
  Eigen::Vector3d pos_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d vel_mps = Eigen::Vector3d::Zero();
};

/// Time derivative (velocity, acceleration) of the state (ICD A.3.1.2 equations).
GlonassOrbitState glonass_derivative(const GlonassOrbitState& s, const Eigen::Vector3d& luni_solar_mps2);

/// Integrate the state by dt_s (either sign) with RK4 steps no longer than max_step_s.
GlonassOrbitState glonass_propagate(const GlonassOrbitState& s0, const Eigen::Vector3d& luni_solar_mps2,
                                    double dt_s, double max_step_s = 60.0);

}  // namespace pdnav::gnss
