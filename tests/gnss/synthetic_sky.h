// Exact code observations of a synthetic sky (pdnav/gnss/solver_synthetic.h) with known answers,
// for the SPP tests (spp_synthetic, spp_robust, review_defects).
#pragma once
#include <map>
#include <vector>

#include "pdnav/gnss/measurements.h"
#include "pdnav/gnss/solver_synthetic.h"
#include "pdnav/gnss/spp.h"

namespace pdnav::test {

/// SPP without the ionosphere and troposphere models: the synthetic observations have neither.
inline gnss::SppOptions no_atmosphere() {
  gnss::SppOptions o;
  o.ionosphere = false;
  o.troposphere = false;
  return o;
}

/// Error-free pseudoranges seen from rx_ecef: Sagnac range + receiver clock (+ the system's
/// inter-system bias) - c (satellite clock - group delay); C/N0 40 dB-Hz, the system's default
/// carrier (B1I for BeiDou, so its TGD1 applies).
inline std::vector<gnss::SppObservation> observe(const std::vector<gnss::SyntheticSat>& sky, const geo::Ecef& rx_ecef,
                                                 double clock_m,
                                                 const std::map<gnss::Constellation, double>& isb_m = {}) {
  std::vector<gnss::SppObservation> obs;
  for (const auto& s : sky) {
    gnss::SppObservation o;
    o.sat = s.sat;
    o.cn0_dbhz = 40.0;
    o.carrier_hz = gnss::default_carrier_hz(s.sat.sys);
    o.state = s.state;
    const auto it = isb_m.find(s.sat.sys);
    o.pseudorange_m = gnss::sagnac_range_m(s.state.pos.p_m, rx_ecef.p_m) + clock_m +
                      (it == isb_m.end() ? 0.0 : it->second) -
                      kSpeedOfLight_mps * (s.state.clock_bias_s - s.state.group_delay_s);
    obs.push_back(o);
  }
  return obs;
}

}  // namespace pdnav::test
