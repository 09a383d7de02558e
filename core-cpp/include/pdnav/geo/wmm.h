// World Magnetic Model (WMM): the main geomagnetic field from Gauss coefficients, following
// "The US/UK World Magnetic Model for 2025-2030: Technical Report" (NOAA NCEI / BGS), Sec. 1.2:
// eq. (9) time-dependent coefficients, eq. (10)-(11) spherical-harmonic field in geocentric
// spherical coordinates, eq. (17) rotation to geodetic, eq. (19) D, I, H, F.
// WMM2025 (public domain, NOAA/BGS) is embedded; other .COF files load from a path.
#pragma once
#include <cstdint>
#include <istream>
#include <string>
#include <vector>

#include "pdnav/geo/frames.h"
#include "pdnav/geo/units.h"

namespace pdnav::geo {

/// One line of a .COF file: degree n, order m, g/h in nT and their secular variation in nT/yr.
struct WmmCoefficient {
  int n = 0;
  int m = 0;
  double g_nt = 0.0;
  double h_nt = 0.0;
  double g_dot_ntpyr = 0.0;
  double h_dot_ntpyr = 0.0;
};

/// A spherical-harmonic main-field model (epoch + coefficients up to degree n_max).
struct WmmModel {
  double epoch_year = 0.0;     // e.g. 2025.0
  std::string name;            // e.g. "WMM-2025"
  std::string release_date;    // as written in the .COF header
  int n_max = 0;
  std::vector<WmmCoefficient> coefficients;

  /// The embedded WMM2025 (valid 2025.0-2030.0).
  static const WmmModel& wmm2025();
  /// Parses a .COF stream (header line, "n m g h gdot hdot" lines, "9999..." terminator).
  /// Throws std::runtime_error("name:line: reason") on malformed input.
  static WmmModel parse_cof(std::istream& in, const std::string& name);
  /// Loads a .COF file from disk; throws std::runtime_error("path:line: reason").
  static WmmModel load_cof(const std::string& path);
};

/// Field at a point, geodetic north/east/down components (nT) and the derived angles.
struct MagneticField {
  double x_nt = 0.0;  // north
  double y_nt = 0.0;  // east
  double z_nt = 0.0;  // down
  double h_nt = 0.0;  // horizontal intensity
  double f_nt = 0.0;  // total intensity
  double declination_rad = 0.0;  // D, east of true north positive
  double inclination_rad = 0.0;  // I, down positive
};

/// Evaluates the model at a geodetic position (height above the WGS84 ellipsoid) and a
/// decimal year (e.g. 2027.5). Latitudes are clamped 1e-9 rad away from the poles, where D is
/// undefined.
MagneticField wmm_field(const WmmModel& model, const Geodetic& where, double decimal_year);

/// Decimal year of a UTC instant (Unix ms): year + elapsed fraction of that calendar year.
double decimal_year_from_unix_ms(std::int64_t unix_ms);

/// Magnetic declination (rad, east positive) from the embedded WMM2025 at a UTC instant.
/// Add it to a magnetic heading to get a true heading. The date is clamped to the model's
/// validity, 2025.0-2030.0 (extrapolating the secular variation for decades is meaningless);
/// a missing time (kMissingInt) uses 2025.0.
double magnetic_declination_rad(const Geodetic& where, std::int64_t unix_ms);

}  // namespace pdnav::geo
