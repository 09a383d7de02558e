#include "pdnav/gnss/types.h"

#include <cstdio>

namespace pdnav::gnss {

char rinex_letter(Constellation c) {
  switch (c) {
    case Constellation::kGps: return 'G';
    case Constellation::kGlonass: return 'R';
    case Constellation::kGalileo: return 'E';
    case Constellation::kBeidou: return 'C';
    case Constellation::kQzss: return 'J';
    case Constellation::kIrnss: return 'I';
    case Constellation::kSbas: return 'S';
    default: return '?';
  }
}

Constellation constellation_from_rinex_letter(char c) {
  switch (c) {
    case 'G': case ' ': return Constellation::kGps;
    case 'R': return Constellation::kGlonass;
    case 'E': return Constellation::kGalileo;
    case 'C': return Constellation::kBeidou;
    case 'J': return Constellation::kQzss;
    case 'I': return Constellation::kIrnss;
    case 'S': return Constellation::kSbas;
    default: return Constellation::kUnknown;
  }
}

const char* to_string(Constellation c) {
  switch (c) {
    case Constellation::kGps: return "GPS";
    case Constellation::kGlonass: return "GLONASS";
    case Constellation::kGalileo: return "Galileo";
    case Constellation::kBeidou: return "BeiDou";
    case Constellation::kQzss: return "QZSS";
    case Constellation::kIrnss: return "IRNSS";
    case Constellation::kSbas: return "SBAS";
    default: return "unknown";
  }
}

SatId SatId::from_android(int constellation_type, int svid) {
  SatId s;
  s.sys = (constellation_type >= 0 && constellation_type <= 7) ? static_cast<Constellation>(constellation_type)
                                                               : Constellation::kUnknown;
  s.prn = svid;
  if (s.sys == Constellation::kQzss && svid >= 193) s.prn = svid - 192;  // J01 = svid 193
  if (s.sys == Constellation::kSbas && svid >= 120) s.prn = svid - 100;  // S20 = PRN 120
  return s;
}

std::string SatId::to_string() const {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%c%02d", rinex_letter(sys), prn);
  return buf;
}

}  // namespace pdnav::gnss
