// Atmospheric delays and look angles for single-frequency positioning.
#pragma once
#include <array>

#include "pdnav/geo/frames.h"

namespace pdnav::gnss {

/// Broadcast Klobuchar coefficients (alpha in s, s/semicircle..., beta in s, s/semicircle...).
struct KlobucharParams {
  std::array<double, 4> alpha{};
  std::array<double, 4> beta{};
};

/// Klobuchar ionospheric delay on GPS L1 [s] (IS-GPS-200 20.3.3.5.2.5, Figure 20-4).
/// `gps_tow_s` is GPS time of week [s] of the reception; az/el of the satellite seen from rx.
/// For another carrier f scale by (f_L1 / f)^2 (e.g. GLONASS, BeiDou B1I).
double klobuchar_delay_s(const KlobucharParams& p, const geo::Geodetic& rx, double az_rad,
                         double el_rad, double gps_tow_s);

/// The broadcast model's geometry of a satellite at elevation el (IS-GPS-200 20.3.3.5.2.5):
/// the Earth-centred angle from the receiver to the ionospheric pierce point, psi = 0.0137 /
/// (E + 0.11) - 0.022 semicircles, and the obliquity factor F = 1 + 16 (0.53 - E)^3 (E =
/// elevation in semicircles, clamped at 0).
struct PiercePoint {
  double earth_angle_sc = 0.0;
  double obliquity = 1.0;
};
PiercePoint klobuchar_pierce_point(double el_rad);

/// Saastamoinen zenith delays with the standard atmosphere at the receiver height
/// (Saastamoinen 1972; P = 1013.25 (1 - 2.2557e-5 h)^5.2568 hPa, T = 15 - 6.5e-3 h deg C).
struct TroposphereZenith {
  double hydrostatic_m = 0.0;
  double wet_m = 0.0;
};
TroposphereZenith saastamoinen_zenith(const geo::Geodetic& rx, double rel_humidity = 0.7);

/// Tropospheric mapping function of RTCA DO-229 A.4.2.4 (Black & Eisner 1984):
/// m(E) = 1.001 / sqrt(0.002001 + sin^2 E), valid down to ~2 deg (clamped below 0 deg).
double troposphere_mapping(double el_rad);

/// Slant tropospheric delay [m] = (zhd + zwd) * m(el). Heights outside -500..11000 m are
/// clamped to that range for the standard atmosphere.
double saastamoinen_delay_m(const geo::Geodetic& rx, double el_rad, double rel_humidity = 0.7);

/// Azimuth (from north, clockwise, [0, 2pi)) and elevation of `sat` seen from `rx`.
struct AzEl {
  double az_rad = 0.0;
  double el_rad = 0.0;
};
AzEl azimuth_elevation(const geo::Ecef& rx, const geo::Ecef& sat);

}  // namespace pdnav::gnss
