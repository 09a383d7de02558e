// Broadcast-vs-precise orbit comparison: the truth check of the ephemeris code.
#pragma once
#include <string>
#include <vector>

#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/sp3.h"

namespace pdnav::gnss {

struct OrbitComparisonRow {
  SatId sat;
  int epochs = 0;              // SP3 epochs where both broadcast and SP3 exist
  int missing = 0;             // SP3 epochs where the broadcast state was refused
  std::string last_reason;     // why (when missing > 0)
  double max_3d_m = 0.0;
  double rms_3d_m = 0.0;
  double max_radial_m = 0.0;   // |radial| component of the difference
  /// |c (dt_brdc - dt_sp3)| with the periodic relativistic term removed from the broadcast
  /// clock (SP3 convention); includes the per-system clock datum offset; 0 without SP3 clock.
  double max_clock_m = 0.0;
};

/// For every satellite present in both, broadcast state vs SP3 at each SP3 epoch
/// (difference = broadcast - SP3; the broadcast GPS/GAL/BDS orbit refers to the antenna
/// phase centre, SP3 to the centre of mass: expect 1-2 m of that alone).
std::vector<OrbitComparisonRow> compare_broadcast_to_sp3(const EphemerisStore& store, const Sp3File& sp3);

}  // namespace pdnav::gnss
