// RINEX clock 3.0x reader (IGS "RINEX Extensions to Handle Clock Information", Ray & Gurtner,
// versions 3.00-3.04): the "AS" (analysis, satellite) records of a precise clock product, e.g.
// CODE's 30 s or 5 min multi-GNSS clocks. Receiver/station records (AR, CR, DR, MS) are
// counted and skipped. Records are parsed by whitespace-separated fields, which reads both the
// 3.00-3.02 layout (4-character clock name) and the 3.04 layout (9-character name).
//
// Conventions (docs/gnss-orbits.md): the clock is the satellite clock offset in seconds as in
// SP3, i.e. without the periodic relativistic term (EphemerisStore adds -2 r.v / c^2) and
// referred to the ionosphere-free combination of the analysis (GPS: L1/L2 P(Y)).
#pragma once
#include <cstdint>
#include <istream>
#include <map>
#include <string>
#include <vector>

#include "pdnav/geo/units.h"
#include "pdnav/gnss/types.h"

namespace pdnav::gnss {

struct ClockSample {
  TimeNs gps_ns = 0;
  double clock_s = 0.0;
  double sigma_s = -1.0;  // second data value when given, else -1
};

struct ClockFile {
  double version = 0.0;
  std::string time_system = "GPS";                 // TIME SYSTEM ID (GPS when absent, per the format)
  std::map<SatId, std::vector<ClockSample>> sats;  // AS records, sorted by time, duplicates dropped
  std::int64_t records = 0;                        // AS records stored
  std::map<std::string, std::int64_t> skipped;     // reason -> count (other record types, bad lines)
  std::int64_t skipped_total() const;
};

/// Throws std::runtime_error("name:line: reason") on a file that is not RINEX clock 3.0x
/// (missing or wrong RINEX VERSION / TYPE, no END OF HEADER, unsupported TIME SYSTEM ID).
/// Malformed data records are counted skips (`skipped`, with the reason).
ClockFile read_rinex_clock(std::istream& in, const std::string& name);
ClockFile read_rinex_clock_file(const std::string& path);

struct ClockInterpolationOptions {
  /// Largest interval between the two samples bracketing t. Products come at 30 s or 5 min;
  /// linear interpolation over 5 min costs ~1-3 cm for GPS Rb clocks (IGS clock products),
  /// a missing 5-min sample (10 min) is refused: 330 s = 5 min + 10 %.
  double max_interval_s = 330.0;
};

/// Linear interpolation of a satellite's clock (s) and its rate (s/s) at GPS time t.
/// false with a reason ("no precise clock", "outside the clock file span", "gap in the
/// precise clock") when t is not bracketed by samples at most max_interval_s apart.
bool interpolate_clock(const std::vector<ClockSample>& samples, TimeNs t, const ClockInterpolationOptions& opt,
                       double& clock_s, double& rate_sps, std::string* why_not = nullptr);

}  // namespace pdnav::gnss
