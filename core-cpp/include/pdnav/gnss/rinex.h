// RINEX navigation file reader (RINEX 2.10/2.11 GPS and GLONASS, RINEX 3.0x mixed).
// Formats: IGS RINEX 2.11 (2012) Tables A3/A10, RINEX 3.04/3.05 Tables A6-A16.
// Records are grouped by their first line (system letter / PRN in the first columns) and
// the blank-prefixed continuation lines that follow, so short or missing lines, extra
// lines (3.05 GLONASS) and Fortran `D` exponents are all handled; blank fields read as 0.
#pragma once
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "pdnav/gnss/ephemeris.h"

namespace pdnav::gnss {

struct RinexNavData {
  double version = 0.0;
  char file_system = 'G';                 // 'G', 'R', 'M', ... from the header
  std::vector<KeplerEphemeris> kepler;    // GPS, QZSS, Galileo, BeiDou
  std::vector<GlonassEphemeris> glonass;
  std::optional<KlobucharParams> klobuchar;  // GPS (ION ALPHA/BETA or GPSA/GPSB)
  EphemerisLoadReport report;
};

/// Parse a navigation file from a stream; `name` is used in "name:line: reason" messages.
/// Throws std::runtime_error when the header is missing, not a navigation file, or of an
/// unsupported version. Bad records are skipped and counted in report.skipped_by_reason.
RinexNavData read_rinex_nav(std::istream& in, const std::string& name);
/// Same, from a file; throws std::runtime_error("path:0: cannot open") when unreadable.
RinexNavData read_rinex_nav_file(const std::string& path);

/// Columns [col, col + width) of a fixed-column RINEX / SP3 / clock line ("" past its end).
std::string rinex_field(const std::string& line, std::size_t col, std::size_t width);
/// `s` without leading and trailing blanks (space, tab, CR, LF).
std::string rinex_trim(const std::string& s);

/// Parse one RINEX floating field ("-0.123D-04", blanks -> 0). nullopt when not a finite number.
std::optional<double> parse_rinex_double(const std::string& field);

}  // namespace pdnav::gnss
