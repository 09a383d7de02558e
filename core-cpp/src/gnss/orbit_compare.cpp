#include "pdnav/gnss/orbit_compare.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace pdnav::gnss {
namespace {
/// SP3 clocks exclude the periodic relativistic term; remove it from the broadcast clock
/// (-2 r.v / c^2, IS-GPS-200 20.3.3.3.3.1 equivalent form). GLONASS clocks never include it.
double clock_without_relativity_s(const SatId& sat, const SatState& st) {
  if (sat.sys == Constellation::kGlonass) return st.clock_bias_s;
  return st.clock_bias_s + 2.0 * st.pos.p_m.dot(st.vel_mps) / (kSpeedOfLight_mps * kSpeedOfLight_mps);
}
}  // namespace

std::vector<OrbitComparisonRow> compare_broadcast_to_sp3(const EphemerisStore& store, const Sp3File& sp3) {
  const std::vector<SatId> have = store.satellites();
  std::map<SatId, OrbitComparisonRow> rows;
  std::map<SatId, double> sum_sq;
  for (const Sp3Epoch& ep : sp3.epochs) {
    for (const auto& [sat, truth] : ep.sats) {
      if (!std::binary_search(have.begin(), have.end(), sat)) continue;
      OrbitComparisonRow& row = rows[sat];
      row.sat = sat;
      std::string why;
      const auto st = store.state(sat, ep.gps_ns, &why);
      if (!st) {
        ++row.missing;
        row.last_reason = why;
        continue;
      }
      const Eigen::Vector3d d = st->pos.p_m - truth.pos.p_m;
      const double d3 = d.norm();
      const double radial = std::abs(d.dot(truth.pos.p_m.normalized()));
      ++row.epochs;
      row.max_3d_m = std::max(row.max_3d_m, d3);
      row.max_radial_m = std::max(row.max_radial_m, radial);
      sum_sq[sat] += d3 * d3;
      if (truth.has_clock)
        row.max_clock_m = std::max(row.max_clock_m, std::abs(clock_without_relativity_s(sat, *st) - truth.clock_s) *
                                                        kSpeedOfLight_mps);
    }
  }
  std::vector<OrbitComparisonRow> out;
  for (auto& [sat, row] : rows) {
    if (row.epochs > 0) row.rms_3d_m = std::sqrt(sum_sq[sat] / row.epochs);
    out.push_back(row);
  }
  return out;
}

}  // namespace pdnav::gnss
