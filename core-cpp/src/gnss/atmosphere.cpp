#include "pdnav/gnss/atmosphere.h"

#include <algorithm>
#include <cmath>

#include "pdnav/geo/units.h"

namespace pdnav::gnss {
namespace {
constexpr double kGpsPi = 3.1415926535898;  // IS-GPS-200 20.3.3.5.2.5 uses semicircles

double polynomial(const std::array<double, 4>& c, double x) {
  return c[0] + x * (c[1] + x * (c[2] + x * c[3]));
}
}  // namespace

PiercePoint klobuchar_pierce_point(double el_rad) {
  const double el_sc = std::max(el_rad, 0.0) / kGpsPi;  // semicircles
  return PiercePoint{0.0137 / (el_sc + 0.11) - 0.022, 1.0 + 16.0 * std::pow(0.53 - el_sc, 3)};
}

double klobuchar_delay_s(const KlobucharParams& p, const geo::Geodetic& rx, double az_rad, double el_rad,
                         double gps_tow_s) {
  const PiercePoint ipp = klobuchar_pierce_point(el_rad);
  const double psi = ipp.earth_angle_sc;
  double phi_i = rx.lat_rad / kGpsPi + psi * std::cos(az_rad);
  phi_i = std::clamp(phi_i, -0.416, 0.416);
  const double lambda_i = rx.lon_rad / kGpsPi + psi * std::sin(az_rad) / std::cos(phi_i * kGpsPi);
  const double phi_m = phi_i + 0.064 * std::cos((lambda_i - 1.617) * kGpsPi);
  double t = 4.32e4 * lambda_i + gps_tow_s;
  t = std::fmod(t, 86400.0);
  if (t < 0) t += 86400.0;
  const double f = ipp.obliquity;
  const double amp = std::max(polynomial(p.alpha, phi_m), 0.0);
  const double per = std::max(polynomial(p.beta, phi_m), 72000.0);
  const double x = 2.0 * kGpsPi * (t - 50400.0) / per;
  if (std::abs(x) >= 1.57) return f * 5e-9;
  const double x2 = x * x;
  return f * (5e-9 + amp * (1.0 - x2 / 2.0 + x2 * x2 / 24.0));
}

TroposphereZenith saastamoinen_zenith(const geo::Geodetic& rx, double rel_humidity) {
  const double h_m = std::clamp(rx.h_m, -500.0, 11000.0);
  // Standard atmosphere (e.g. Berg 1948 as used with Saastamoinen; RTCA DO-229 style).
  const double p_hpa = 1013.25 * std::pow(1.0 - 2.2557e-5 * h_m, 5.2568);
  const double t_k = 15.0 - 6.5e-3 * h_m + 273.15;
  const double rh = std::clamp(rel_humidity, 0.0, 1.0);
  // Water vapour partial pressure [hPa] (Magnus-type formula used with Saastamoinen).
  const double e_hpa = 6.108 * rh * std::exp((17.15 * t_k - 4684.0) / (t_k - 38.45));
  TroposphereZenith z;
  // Saastamoinen (1972) hydrostatic delay, Davis et al. (1985) form, IERS Conventions 2010 eq. 9.11.
  z.hydrostatic_m = 0.0022768 * p_hpa / (1.0 - 0.00266 * std::cos(2.0 * rx.lat_rad) - 0.28e-6 * h_m);
  // Saastamoinen (1972) wet delay.
  z.wet_m = 0.002277 * (1255.0 / t_k + 0.05) * e_hpa;
  return z;
}

double troposphere_mapping(double el_rad) {
  const double s = std::sin(std::max(el_rad, 0.0));
  return 1.001 / std::sqrt(0.002001 + s * s);
}

double saastamoinen_delay_m(const geo::Geodetic& rx, double el_rad, double rel_humidity) {
  const TroposphereZenith z = saastamoinen_zenith(rx, rel_humidity);
  return (z.hydrostatic_m + z.wet_m) * troposphere_mapping(el_rad);
}

AzEl azimuth_elevation(const geo::Ecef& rx, const geo::Ecef& sat) {
  const geo::Geodetic g = geo::to_geodetic(rx);
  const Eigen::Vector3d enu = geo::ecef_to_enu_rotation(g) * (sat.p_m - rx.p_m);
  AzEl out;
  const double horiz = std::hypot(enu.x(), enu.y());
  out.el_rad = std::atan2(enu.z(), horiz);
  out.az_rad = horiz > 0.0 ? wrap_two_pi(std::atan2(enu.x(), enu.y())) : 0.0;
  return out;
}

}  // namespace pdnav::gnss
