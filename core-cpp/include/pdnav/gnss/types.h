// GNSS identifiers shared by the measurement, ephemeris and solver code.
#pragma once
#include <string>

namespace pdnav::gnss {

/// Android's android.location.GnssStatus.CONSTELLATION_* numbering.
enum class Constellation : int {
  kUnknown = 0, kGps = 1, kSbas = 2, kGlonass = 3, kQzss = 4, kBeidou = 5, kGalileo = 6, kIrnss = 7
};

/// RINEX system letter (G R E C J I S) of a constellation, '?' when none.
char rinex_letter(Constellation c);
Constellation constellation_from_rinex_letter(char c);
const char* to_string(Constellation c);

/// A satellite: constellation + the number RINEX uses (GPS/GAL/BDS PRN, GLONASS slot,
/// QZSS PRN-192 as in "J01", SBAS PRN-100). Android svids map to it with from_android().
struct SatId {
  Constellation sys = Constellation::kUnknown;
  int prn = 0;
  static SatId from_android(int constellation_type, int svid);
  std::string to_string() const;  // "G05", "R12", "E11", "C19", "J01"
  bool operator==(const SatId& o) const { return sys == o.sys && prn == o.prn; }
  bool operator<(const SatId& o) const { return sys != o.sys ? sys < o.sys : prn < o.prn; }
};

}  // namespace pdnav::gnss
