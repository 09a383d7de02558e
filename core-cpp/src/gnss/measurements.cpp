#include "pdnav/gnss/measurements.h"

#include <algorithm>
#include <cmath>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/spp.h"  // clock_group

namespace pdnav::gnss {
namespace {

constexpr std::int64_t kNs100Ms = 100 * kNsPerMs;
constexpr std::int64_t kNsPerHour = 3600 * kNsPerS;

/// a mod m in [0, m).
std::int64_t floor_mod(std::int64_t a, std::int64_t m) {
  const std::int64_t r = a % m;
  return r < 0 ? r + m : r;
}

/// d wrapped to (-period/2, period/2].
std::int64_t wrap_half(std::int64_t d, std::int64_t period) {
  d = floor_mod(d, period);
  return d > period / 2 ? d - period : d;
}

bool has(std::int64_t state, std::int64_t bit) { return (state & bit) != 0; }

bool finite_and_small(double v, double limit) { return std::isfinite(v) && std::fabs(v) < limit; }

double ns_to_m(std::int64_t d_ns, double frac_ns) {
  return (static_cast<double>(d_ns) + frac_ns) * 1e-9 * kSpeedOfLight_mps;
}

/// Week-based time of week (GPS, Galileo, QZSS, BeiDou after the BDT offset).
double week_based_pr_m(std::int64_t rx_ns, double frac_ns, std::int64_t sv_ns) {
  const std::int64_t tow_ns = floor_mod(rx_ns, geo::kNsPerWeek);
  return ns_to_m(wrap_half(tow_ns - sv_ns, geo::kNsPerWeek), frac_ns);
}

double gps_like_pr_m(const GnssRawSample& r, const GpsTime& rx, std::string& reason) {
  const bool tow = has(r.state, state_bit::kTowDecoded) || has(r.state, state_bit::kTowKnown);
  if (!tow || has(r.state, state_bit::kMsecAmbiguous)) {
    reason = "code: time of week not decoded";
    return kNaN;
  }
  return week_based_pr_m(rx.ns, rx.frac_ns, r.received_sv_time_nanos);
}

double galileo_pr_m(const GnssRawSample& r, const GpsTime& rx, std::string& reason) {
  if (has(r.state, state_bit::kTowDecoded) || has(r.state, state_bit::kTowKnown))
    return week_based_pr_m(rx.ns, rx.frac_ns, r.received_sv_time_nanos);
  if (!has(r.state, state_bit::kGalE1c2ndCodeLock)) {
    reason = "code: Galileo neither TOW nor E1C secondary code lock";
    return kNaN;
  }
  // E1C secondary code: ReceivedSvTime is known modulo 100 ms; Galileo ranges are 77-97 ms.
  std::int64_t d = floor_mod(floor_mod(rx.ns, kNs100Ms) - floor_mod(r.received_sv_time_nanos, kNs100Ms), kNs100Ms);
  if (d < kNs100Ms / 2) d += kNs100Ms;
  return ns_to_m(d, rx.frac_ns);
}

double beidou_pr_m(const GnssRawSample& r, const GpsTime& rx, std::string& reason) {
  if (!(has(r.state, state_bit::kTowDecoded) || has(r.state, state_bit::kTowKnown))) {
    reason = "code: time of week not decoded";
    return kNaN;
  }
  const std::int64_t rx_bdt_ns = rx.ns - 14 * kNsPerS;  // BDT = GPST - 14 s
  return week_based_pr_m(rx_bdt_ns, rx.frac_ns, r.received_sv_time_nanos);
}

double glonass_pr_m(const GnssRawSample& r, const GpsTime& rx, int leap_s, std::string& reason) {
  if (!(has(r.state, state_bit::kGloTodDecoded) || has(r.state, state_bit::kGloTodKnown))) {
    reason = "code: GLONASS time of day not decoded";
    return kNaN;
  }
  // GLONASS time = UTC(SU) + 3 h; time of day wraps at the GLONASS day boundary.
  const std::int64_t rx_glo_ns = rx.ns - std::int64_t{leap_s} * kNsPerS + 3 * kNsPerHour;
  const std::int64_t tod_ns = floor_mod(rx_glo_ns, geo::kNsPerDay);
  return ns_to_m(wrap_half(tod_ns - r.received_sv_time_nanos, geo::kNsPerDay), rx.frac_ns);
}

/// ADR fields of a row into the measurement; counted when unusable.
void fill_adr(const GnssRawSample& r, const MeasurementOptions& opt, Measurement& m, ExclusionCounts& ex) {
  const std::int64_t st = r.accumulated_delta_range_state;
  if (st == kMissingInt || !has(st, adr_bit::kValid)) {
    if (std::isfinite(r.accumulated_delta_range_m) && r.accumulated_delta_range_m != 0.0) ++ex["adr: state not valid"];
    return;
  }
  if (!finite_and_small(r.accumulated_delta_range_m, 1e12)) { ++ex["adr: non-finite value"]; return; }
  m.adr_reset = has(st, adr_bit::kReset);
  m.adr_cycle_slip = has(st, adr_bit::kCycleSlip);
  m.adr_m = r.accumulated_delta_range_m;
  m.adr_sigma_m = finite_and_small(r.accumulated_delta_range_uncertainty_m, opt.max_uncertainty)
                      ? r.accumulated_delta_range_uncertainty_m : kNaN;
  if (m.adr_reset) ++ex["adr: reset"];
  if (m.adr_cycle_slip) ++ex["adr: cycle slip"];
}

/// Pseudorange rate fields of a row.
void fill_rate(const GnssRawSample& r, const MeasurementOptions& opt, Measurement& m, ExclusionCounts& ex) {
  if (!finite_and_small(r.pseudorange_rate_mps, 1e5)) {
    ++ex["doppler: missing or non-finite"];
    return;
  }
  m.pr_rate_mps = r.pseudorange_rate_mps;
  m.pr_rate_sigma_mps = finite_and_small(r.pseudorange_rate_uncertainty_mps, opt.max_uncertainty)
                            ? r.pseudorange_rate_uncertainty_mps : kNaN;
}

/// Pseudorange fields of a row; NaN pseudorange (counted) when the code phase is unusable.
void fill_code(const GnssRawSample& r, const GpsTime& rx, int leap_s, const MeasurementOptions& opt,
               Measurement& m, ExclusionCounts& ex) {
  std::string reason;
  if (r.received_sv_time_nanos == kMissingInt || r.received_sv_time_nanos < 0) {
    ++ex["code: ReceivedSvTimeNanos missing"];
    return;
  }
  const double pr = pseudorange_m(r, rx, leap_s, reason);
  if (!std::isfinite(pr)) { ++ex[reason]; return; }
  if (pr < opt.min_pseudorange_m || pr > opt.max_pseudorange_m) { ++ex["code: pseudorange out of range"]; return; }
  double sigma = kNaN;
  if (r.received_sv_time_uncertainty_nanos != kMissingInt && r.received_sv_time_uncertainty_nanos >= 0)
    sigma = static_cast<double>(r.received_sv_time_uncertainty_nanos) * 1e-9 * kSpeedOfLight_mps;
  if (std::isfinite(sigma) && sigma > opt.max_pr_sigma_m) { ++ex["code: uncertainty too large"]; return; }
  m.pseudorange_m = pr;
  m.pseudorange_sigma_m = sigma;
  m.transmit_gps_ns = rx.ns - std::llround(pr / kSpeedOfLight_mps * 1e9);
}

/// True for the L1-band signal the solver uses (GPS/QZSS L1, Galileo E1, BeiDou B1I/B1C,
/// GLONASS L1OF); L5/E5a/B2a and other bands would need their own group delays.
bool l1_band(Constellation sys, double carrier_hz) {
  if (!std::isfinite(carrier_hz)) return true;  // old logs have no frequency column: L1
  if (sys == Constellation::kGlonass) return carrier_hz > 1590e6 && carrier_hz < 1610e6;
  if (sys == Constellation::kBeidou) return carrier_hz > 1555e6 && carrier_hz < 1580e6;
  return std::fabs(carrier_hz - 1575.42e6) < 10e6;
}

/// Preference among two signals of one satellite in the same band: usable code first, then
/// usable carrier, then a fixed order of tracking codes (pilot/data-pilot before data: C, X, I, Q,
/// P, B ...; the same choice every epoch, so smoothing and TDCP stay on one signal), C/N0 last.
bool better_signal(const Measurement& a, const Measurement& b) {
  if (a.code_ok() != b.code_ok()) return a.code_ok();
  if (a.adr_ok() != b.adr_ok()) return a.adr_ok();
  static const std::string kOrder = "CXIQPBDLSZAMNW";
  auto rank = [](const std::string& c) {
    const auto p = c.empty() ? std::string::npos : kOrder.find(c[0]);
    return p == std::string::npos ? kOrder.size() : p;
  };
  if (rank(a.code_type) != rank(b.code_type)) return rank(a.code_type) < rank(b.code_type);
  return a.cn0_dbhz > b.cn0_dbhz;
}

/// Keeps one signal per satellite (better_signal), counting the others.
void drop_duplicates(std::vector<Measurement>& meas, ExclusionCounts& excluded) {
  std::vector<Measurement> out;
  for (const Measurement& m : meas) {
    auto it = std::find_if(out.begin(), out.end(), [&](const Measurement& o) { return o.sat == m.sat; });
    if (it == out.end()) { out.push_back(m); continue; }
    ++excluded["signal: duplicate satellite in epoch"];
    if (better_signal(m, *it)) *it = m;
  }
  meas.swap(out);
}

bool supported(Constellation c) {
  return c == Constellation::kGps || c == Constellation::kGlonass || c == Constellation::kGalileo ||
         c == Constellation::kBeidou || c == Constellation::kQzss;
}


/// FrequencyMode::kBest: in a clock group with at least `min_sats` usable L5/E5a/B2a codes,
/// every such satellite is measured on that band (code, Doppler, carrier); the others keep L1.
/// A group with fewer L5 codes stays on L1: its L5 clock (the receiver's L1-L5 bias, one more
/// unknown) would be fixed by too few satellites.
void use_best_band(std::vector<Measurement>& meas, std::vector<Measurement>& l5, int min_sats,
                   ExclusionCounts& excluded) {
  drop_duplicates(l5, excluded);
  std::map<Constellation, int> per_group;
  for (const Measurement& s5 : l5) ++per_group[clock_group(s5.sat.sys)];
  for (const Measurement& s5 : l5) {
    if (per_group[clock_group(s5.sat.sys)] < min_sats) {
      ++excluded["best: too few L5/E5a codes in the clock group (L1 kept)"];
      continue;
    }
    auto it = std::find_if(meas.begin(), meas.end(), [&](const Measurement& o) { return o.sat == s5.sat; });
    if (it == meas.end()) {
      meas.push_back(s5);
      ++excluded["best: L5/E5a signal without L1 (used)"];
    } else {
      *it = s5;
      ++excluded["best: L5/E5a signal used instead of L1"];
    }
  }
}

double median_of(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(v.begin(), mid));
}

}  // namespace

const char* frequency_mode_name(FrequencyMode m) {
  switch (m) {
    case FrequencyMode::kDual: return "dual";
    case FrequencyMode::kL5: return "l5";
    case FrequencyMode::kBest: return "best";
    default: return "single";
  }
}

bool l5_band(Constellation sys, double carrier_hz) {
  if (!std::isfinite(carrier_hz)) return false;
  if (sys != Constellation::kGps && sys != Constellation::kQzss && sys != Constellation::kGalileo &&
      sys != Constellation::kBeidou)
    return false;
  return std::fabs(carrier_hz - 1176.45e6) < 1e6;
}

void combine_dual_frequency(std::vector<Measurement>& meas, const MeasurementOptions& opt, ExclusionCounts& excluded) {
  std::map<Constellation, std::vector<std::size_t>> code_sats, dual_sats;
  for (std::size_t i = 0; i < meas.size(); ++i) {
    const Measurement& m = meas[i];
    if (!m.code_ok()) continue;
    const Constellation g = clock_group(m.sat.sys);
    code_sats[g].push_back(i);
    if (std::isfinite(m.pseudorange_l5_m) && std::isfinite(m.cn0_l5_dbhz)) dual_sats[g].push_back(i);
  }
  for (const auto& [g, all] : code_sats) {
    const auto it = dual_sats.find(g);
    const std::size_t n_dual = it == dual_sats.end() ? 0 : it->second.size();
    if (n_dual == 0) continue;
    if (static_cast<int>(n_dual) < std::max(2, opt.dual_min_sats) ||
        static_cast<double>(n_dual) < opt.dual_min_fraction * static_cast<double>(all.size())) {
      excluded["dual: too few dual-frequency satellites in the clock group (single frequency)"] +=
          static_cast<std::int64_t>(n_dual);
      continue;
    }
    std::vector<double> d;
    for (std::size_t i : it->second) d.push_back(meas[i].pseudorange_m - meas[i].pseudorange_l5_m);
    const double med = median_of(d);
    std::vector<bool> combined(meas.size(), false);
    for (std::size_t k = 0; k < it->second.size(); ++k) {
      Measurement& m = meas[it->second[k]];
      const double dev = d[k] - med;
      if (!(std::fabs(dev) <= opt.dual_max_deviation_m)) {
        ++excluded["dual: L1-L5 difference far from the group median (code dropped)"];
        m.pseudorange_m = kNaN;
        continue;
      }
      m.pseudorange_l1_m = m.pseudorange_m;
      m.pseudorange_m += kIfBeta * dev;
      m.iono_free = true;
      combined[it->second[k]] = true;
      ++excluded["dual: ionosphere-free code used"];
    }
    for (std::size_t i : all) {
      if (combined[i] || !meas[i].code_ok()) continue;
      if (opt.dual_keep_single) { ++excluded["dual: L1-only satellite kept in an IF group"]; continue; }
      ++excluded["dual: L1-only satellite of an IF group (code not used)"];
      meas[i].pseudorange_m = kNaN;
    }
  }
}

double default_carrier_hz(Constellation sys, int glonass_channel) {
  switch (sys) {
    case Constellation::kGps: case Constellation::kQzss: case Constellation::kGalileo:
    case Constellation::kSbas: return 1575.42e6;
    case Constellation::kBeidou: return 1561.098e6;
    case Constellation::kGlonass: return 1602.0e6 + glonass_channel * 0.5625e6;
    case Constellation::kIrnss: return 1176.45e6;
    default: return kNaN;
  }
}

bool receive_gps_time(const GnssRawSample& r, GpsTime& out) {
  if (r.time_nanos == kMissingInt || r.full_bias_nanos == kMissingInt) return false;
  const double offset = (std::isfinite(r.time_offset_nanos) ? r.time_offset_nanos : 0.0) -
                        (std::isfinite(r.bias_nanos) ? r.bias_nanos : 0.0);
  if (std::fabs(offset) > 1e9) return false;
  const double whole = std::floor(offset);
  // Overflow-checked: arbitrary (fuzzed or corrupt) clock fields must not wrap.
  std::int64_t ns = 0;
  if (__builtin_sub_overflow(r.time_nanos, r.full_bias_nanos, &ns) ||
      __builtin_add_overflow(ns, static_cast<std::int64_t>(whole), &ns))
    return false;
  out.ns = ns;
  out.frac_ns = offset - whole;
  return out.ns > 0;
}

double pseudorange_m(const GnssRawSample& r, const GpsTime& rx, int leap_seconds, std::string& reason) {
  if (!has(r.state, state_bit::kCodeLock)) { reason = "code: no code lock"; return kNaN; }
  const SatId sat = SatId::from_android(r.constellation_type, r.svid);
  switch (sat.sys) {
    case Constellation::kGps: case Constellation::kQzss: return gps_like_pr_m(r, rx, reason);
    case Constellation::kGalileo: return galileo_pr_m(r, rx, reason);
    case Constellation::kBeidou: return beidou_pr_m(r, rx, reason);
    case Constellation::kGlonass: return glonass_pr_m(r, rx, leap_seconds, reason);
    default: reason = "unsupported constellation"; return kNaN;
  }
}

bool build_epoch(const std::vector<GnssRawSample>& rows, const MeasurementOptions& opt,
                 MeasurementEpoch& out, ExclusionCounts& excluded) {
  out = MeasurementEpoch{};
  if (rows.empty()) return false;
  const GnssRawSample& c = rows.front();
  out.t_ns = c.t_ns;
  out.time_nanos = c.time_nanos;
  out.hw_discontinuity = c.hardware_clock_discontinuity_count;
  if (!receive_gps_time(c, out.rx)) {
    excluded["epoch: no GPS time (FullBiasNanos missing)"] += static_cast<std::int64_t>(rows.size());
    return false;
  }
  out.full_bias_nanos = c.full_bias_nanos;
  out.bias_nanos = std::isfinite(c.bias_nanos) ? c.bias_nanos : 0.0;
  if (finite_and_small(c.drift_nanos_per_second, 1e9))
    out.clock_drift_mps = c.drift_nanos_per_second * 1e-9 * kSpeedOfLight_mps;
  out.leap_seconds = (c.leap_second != kMissingInt && c.leap_second >= 0 && c.leap_second < 100)
                         ? static_cast<int>(c.leap_second) : geo::leap_seconds_at_gps_ns(out.rx.ns);
  const bool dual = opt.frequency == FrequencyMode::kDual;
  const bool l5_only = opt.frequency == FrequencyMode::kL5;
  const bool best = opt.frequency == FrequencyMode::kBest;
  std::vector<Measurement> l5;  // second-band codes (dual mode) or measurements (best mode)
  for (const GnssRawSample& r : rows) {
    Measurement m;
    m.sat = SatId::from_android(r.constellation_type, r.svid);
    if (!supported(m.sat.sys)) { ++excluded["unsupported constellation"]; continue; }
    if (!std::isfinite(r.cn0_dbhz)) { ++excluded["cn0: missing"]; continue; }
    if (r.cn0_dbhz < opt.min_cn0_dbhz) { ++excluded["cn0 < 15 dB-Hz"]; continue; }
    m.cn0_dbhz = r.cn0_dbhz;
    if (m.sat.sys == Constellation::kGlonass && r.svid >= 93 && r.svid <= 106) m.glonass_channel = r.svid - 100;
    if (finite_and_small(r.carrier_frequency_hz, 1e10) && r.carrier_frequency_hz > 1e8) m.carrier_hz = r.carrier_frequency_hz;
    if (r.code_type.size() <= 4) m.code_type = r.code_type;
    const bool second = (dual || best) && l5_band(m.sat.sys, m.carrier_hz);
    if (l5_only && !l5_band(m.sat.sys, m.carrier_hz)) { ++excluded["signal: not L5/E5a/B2a (--freq l5)"]; continue; }
    if (!l5_only && !second && !l1_band(m.sat.sys, m.carrier_hz)) {
      ++excluded[dual ? "signal: neither L1/E1/B1 nor L5/E5a" : "signal: not L1/E1/B1 (one band used)"];
      continue;
    }
    // TimeOffsetNanos is per measurement, so each row has its own receive time
    GpsTime rx;
    if (!receive_gps_time(r, rx)) { ++excluded["epoch: no GPS time (FullBiasNanos missing)"]; continue; }
    fill_code(r, rx, out.leap_seconds, opt, m, excluded);
    if (second && dual) {  // only the code of the second band is used (ADR/Doppler stay L1)
      if (m.code_ok()) l5.push_back(m);
      continue;
    }
    fill_rate(r, opt, m, excluded);
    fill_adr(r, opt, m, excluded);
    if (second) {  // best: the whole L5 measurement replaces L1 below when its code is usable
      if (m.code_ok()) l5.push_back(m);
      continue;
    }
    if (!m.code_ok() && !std::isfinite(m.pr_rate_mps) && !std::isfinite(m.adr_m)) continue;
    out.meas.push_back(m);
  }
  drop_duplicates(out.meas, excluded);
  if (best) use_best_band(out.meas, l5, opt.dual_min_sats, excluded);
  if (dual) {
    drop_duplicates(l5, excluded);
    for (const Measurement& s5 : l5) {
      auto it = std::find_if(out.meas.begin(), out.meas.end(), [&](const Measurement& o) { return o.sat == s5.sat; });
      if (it == out.meas.end() || !it->code_ok()) { ++excluded["dual: L5/E5a code without L1 code (not used)"]; continue; }
      it->pseudorange_l5_m = s5.pseudorange_m;
      it->cn0_l5_dbhz = s5.cn0_dbhz;
    }
    combine_dual_frequency(out.meas, opt, excluded);
  }
  return !out.meas.empty();
}

}  // namespace pdnav::gnss
