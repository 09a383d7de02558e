// World Magnetic Model (WMM): the main geomagnetic field from Gauss coefficients, following
// "The US/UK World Magnetic Model for 2025-2030: Technical Report" (NOAA NCEI / BGS), Sec. 1.2:
// eq. (9) time-dependent coefficients, eq. (10)-(11) spherical-harmonic field in geocentric
// spherical coordinates, eq. (17) rotation to geodetic, eq. (19) D, I, H, F.
// WMM2015 (version 2), WMM2020 and WMM2025 (public domain, NOAA NCEI / BGS) are embedded and
// picked by the date (issue 19.2); other .COF files load from a path.
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
  /// The embedded WMM2020 (valid 2020.0-2025.0).
  static const WmmModel& wmm2020();
  /// The embedded WMM2015 version 2 (valid 2015.0-2020.0; NOAA's 2018 out-of-cycle release
  /// that replaced the original WMM2015 for that whole span).
  static const WmmModel& wmm2015();
  /// Every embedded model, oldest first. Each is valid for kWmmValidityYears from its epoch.
  static std::vector<const WmmModel*> embedded();
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

inline constexpr double kWmmValidityYears = 5.0;  // each WMM release covers 5 years

/// A declination with the model that gave it.
struct Declination {
  double declination_rad = 0.0;  // D, east of true north positive
  double decimal_year = 0.0;     // the date it was evaluated at
  std::string model;             // e.g. "WMM-2020"
  bool extrapolated = false;     // the date lies outside every embedded model's span
  std::string warning;           // set when extrapolated (or the time is missing), for summaries
};

/// Declination at a UTC instant from the embedded model whose span holds the date (WMM2015
/// for 2015-2020, WMM2020 for 2020-2025, WMM2025 for 2025-2030). Outside every span the
/// nearest model's secular variation is extrapolated and `warning` says so; a missing time
/// (kMissingInt) uses WMM2025 at its epoch, with a warning.
Declination declination_at(const Geodetic& where, std::int64_t unix_ms);

/// declination_at(where, unix_ms).declination_rad. Add it to a magnetic heading to get a true
/// heading.
double magnetic_declination_rad(const Geodetic& where, std::int64_t unix_ms);

}  // namespace pdnav::geo
