// SP3-c / SP3-d precise orbit reader (IGS SP3-c 2007, SP3-d 2016 format descriptions).
// Positions in km and clocks in microseconds in the file; stored in m and s. Times are
// converted to GPS time (GPS and GAL time systems as is, UTC with leap seconds; others
// rejected). Bad or missing positions (0.000000) and clocks (999999.999999) are dropped.
#pragma once
#include <istream>
#include <map>
#include <string>
#include <vector>

#include "pdnav/geo/frames.h"
#include "pdnav/geo/units.h"
#include "pdnav/gnss/types.h"

namespace pdnav::gnss {

struct Sp3Sample {
  geo::Ecef pos;              // centre of mass, ECEF (ITRF/IGS frame)
  double clock_s = 0.0;
  bool has_clock = false;
};

struct Sp3Epoch {
  TimeNs gps_ns = 0;
  std::map<SatId, Sp3Sample> sats;
};

struct Sp3File {
  char version = 'c';
  std::string time_system = "GPS";
  std::vector<Sp3Epoch> epochs;
  int skipped_lines = 0;      // malformed / bad-value satellite lines
};

/// Time systems of precise products (SP3, RINEX clock): GPS, GAL, QZS (steered to GPS time, taken
/// as GPS time), UTC (+ leap seconds), TAI (- 19 s), BDT (+ 14 s).
bool product_time_system_supported(const std::string& time_system);
/// Calendar seconds since the GPS epoch read in `time_system` -> GPS time, ns.
TimeNs product_time_to_gps_ns(double calendar_s, const std::string& time_system);

/// Throws std::runtime_error("name:line: reason") on a bad header or unsupported time system.
Sp3File read_sp3(std::istream& in, const std::string& name);
Sp3File read_sp3_file(const std::string& path);

}  // namespace pdnav::gnss
