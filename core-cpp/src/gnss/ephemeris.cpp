#include "pdnav/gnss/ephemeris.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "pdnav/gnss/rinex.h"

namespace pdnav::gnss {
namespace {

bool is_galileo_inav(const KeplerEphemeris& k) { return (k.data_source & 0x205) != 0 || k.data_source == 0; }

bool same_record(const KeplerEphemeris& a, const KeplerEphemeris& b) {
  return a.toe_gps_ns == b.toe_gps_ns && a.toc_gps_ns == b.toc_gps_ns && a.iode == b.iode &&
         is_galileo_inav(a) == is_galileo_inav(b);
}

bool finite_state(const SatState& s) {
  return s.pos.p_m.allFinite() && s.vel_mps.allFinite() && std::isfinite(s.clock_bias_s) &&
         std::isfinite(s.clock_drift_sps) && std::isfinite(s.group_delay_s);
}

double abs_age_s(TimeNs t, TimeNs ref) { return std::abs(ns_to_s(t - ref)); }

/// Nearest-in-time record among those accepted by `keep`; nullptr when none.
template <typename Eph, typename RefTime, typename Keep>
const Eph* nearest(const std::vector<Eph>& list, TimeNs t, RefTime ref, Keep keep) {
  const Eph* best = nullptr;
  double best_age = std::numeric_limits<double>::infinity();
  for (const Eph& e : list) {
    if (!keep(e)) continue;
    const double age = abs_age_s(t, ref(e));
    if (age < best_age) { best_age = age; best = &e; }
  }
  return best;
}

std::optional<SatState> refuse(std::string* why_not, const char* reason) {
  if (why_not) *why_not = reason;
  return std::nullopt;
}

}  // namespace

int EphemerisLoadReport::records_total() const {
  int n = 0;
  for (const auto& kv : records_by_system) n += kv.second;
  return n;
}

int EphemerisLoadReport::skipped_total() const {
  int n = 0;
  for (const auto& kv : skipped_by_reason) n += kv.second;
  return n;
}

EphemerisStore::EphemerisStore(EphemerisStoreOptions options) : options_(options) {}

EphemerisLoadReport EphemerisStore::load_rinex_nav(const std::string& path) {
  RinexNavData d = read_rinex_nav_file(path);
  for (const auto& k : d.kepler) add(k);
  for (const auto& g : d.glonass) add(g);
  if (d.klobuchar) klobuchar_ = d.klobuchar;
  return d.report;
}

EphemerisLoadReport EphemerisStore::load_rinex_nav(std::istream& in, const std::string& name) {
  RinexNavData d = read_rinex_nav(in, name);
  for (const auto& k : d.kepler) add(k);
  for (const auto& g : d.glonass) add(g);
  if (d.klobuchar) klobuchar_ = d.klobuchar;
  return d.report;
}

void EphemerisStore::add(const KeplerEphemeris& eph) {
  auto& list = kepler_[eph.sat];
  for (const auto& e : list)
    if (same_record(e, eph)) return;
  list.push_back(eph);
}

void EphemerisStore::add(const GlonassEphemeris& eph) {
  auto& list = glonass_[eph.sat];
  for (const auto& e : list)
    if (e.tb_gps_ns == eph.tb_gps_ns) return;
  list.push_back(eph);
}

int EphemerisStore::add_precise(const Sp3File& sp3) {
  std::map<SatId, PreciseTrack> tracks;
  for (const Sp3Epoch& e : sp3.epochs) {
    for (const auto& [sat, smp] : e.sats) {
      if (!smp.pos.p_m.allFinite()) continue;
      PreciseTrack& tr = tracks[sat];
      if (!tr.t.empty() && e.gps_ns <= tr.t.back()) continue;  // out of order / repeated epoch
      tr.t.push_back(e.gps_ns);
      tr.pos_m.push_back(smp.pos.p_m);
      tr.clock_s.push_back(smp.has_clock && std::isfinite(smp.clock_s) ? smp.clock_s
                                                                         : std::numeric_limits<double>::quiet_NaN());
    }
  }
  int n = 0;
  for (auto& [sat, tr] : tracks) {
    if (static_cast<int>(tr.t.size()) < std::max(2, options_.precise_points)) continue;
    precise_[sat] = std::move(tr);
    ++n;
  }
  return n;
}

int EphemerisStore::add_precise_clocks(const ClockFile& clk) {
  int n = 0;
  for (const auto& [sat, v] : clk.sats) {
    if (v.empty()) continue;
    precise_clock_[sat] = v;
    ++n;
  }
  return n;
}

std::optional<SatState> EphemerisStore::precise_state(const SatId& sat, TimeNs t, std::string* why_not) const {
  const auto it = precise_.find(sat);
  if (it == precise_.end()) return refuse(why_not, "no precise orbit");
  const PreciseTrack& tr = it->second;
  const int n = static_cast<int>(tr.t.size());
  const int m = std::min(std::max(2, options_.precise_points), n);
  if (t < tr.t.front() || t > tr.t.back()) return refuse(why_not, "outside the precise orbit span");
  const auto hi = std::upper_bound(tr.t.begin(), tr.t.end(), t);
  int k = static_cast<int>(hi - tr.t.begin());  // tr.t[k-1] <= t < tr.t[k]
  k = std::clamp(k, 1, n - 1);
  // a gap (missing epochs) inside the stencil would make the polynomial meaningless
  int first = std::clamp(k - m / 2, 0, n - m);
  const double span_s = ns_to_s(tr.t[static_cast<std::size_t>(first + m - 1)] - tr.t[static_cast<std::size_t>(first)]);
  const double step_s = ns_to_s(tr.t[static_cast<std::size_t>(k)] - tr.t[static_cast<std::size_t>(k - 1)]);
  if (!(step_s > 0) || span_s > 1.5 * step_s * (m - 1)) return refuse(why_not, "gap in the precise orbit");
  // Lagrange interpolation of the position at t and t +- 0.5 s (velocity by central difference)
  auto interp = [&](double dt_s) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    const double x = ns_to_s(t - tr.t[static_cast<std::size_t>(first)]) + dt_s;
    for (int i = 0; i < m; ++i) {
      const double xi = ns_to_s(tr.t[static_cast<std::size_t>(first + i)] - tr.t[static_cast<std::size_t>(first)]);
      double w = 1.0;
      for (int j = 0; j < m; ++j) {
        if (j == i) continue;
        const double xj = ns_to_s(tr.t[static_cast<std::size_t>(first + j)] - tr.t[static_cast<std::size_t>(first)]);
        w *= (x - xj) / (xi - xj);
      }
      p += w * tr.pos_m[static_cast<std::size_t>(first + i)];
    }
    return p;
  };
  SatState s;
  s.pos = geo::Ecef(interp(0.0));
  s.vel_mps = interp(0.5) - interp(-0.5);
  double clock_s = 0.0;
  if (const auto ck = precise_clock_.find(sat); ck != precise_clock_.end()) {  // RINEX clock file
    std::string why;
    if (!interpolate_clock(ck->second, t, options_.precise_clock, clock_s, s.clock_drift_sps, &why))
      return refuse(why_not, why.c_str());
  } else {
    const double c0 = tr.clock_s[static_cast<std::size_t>(k - 1)], c1 = tr.clock_s[static_cast<std::size_t>(k)];
    if (!std::isfinite(c0) || !std::isfinite(c1)) return refuse(why_not, "no precise clock");
    const double f = ns_to_s(t - tr.t[static_cast<std::size_t>(k - 1)]) / step_s;
    s.clock_drift_sps = (c1 - c0) / step_s;
    clock_s = c0 + f * (c1 - c0);
  }
  s.clock_bias_s = clock_s - 2.0 * s.pos.p_m.dot(s.vel_mps) / (kSpeedOfLight_mps * kSpeedOfLight_mps);
  s.toe_gps_ns = tr.t[static_cast<std::size_t>(k - 1)];
  s.iode = -1;  // precise
  std::string ignore;
  if (const auto b = broadcast_state(sat, t, &ignore)) {
    s.group_delay_s = b->group_delay_s;
    s.glonass_channel = b->glonass_channel;
    s.healthy = b->healthy;
  }
  if (!finite_state(s)) return refuse(why_not, "numerical failure");
  return s;
}

std::optional<SatState> EphemerisStore::state(const SatId& sat, TimeNs t, std::string* why_not) const {
  if (options_.prefer_precise && !precise_.empty()) {
    std::string why;
    auto p = precise_state(sat, t, &why);
    if (p) {
      if (!p->healthy && !options_.accept_unhealthy) return refuse(why_not, "unhealthy");
      if (why_not) why_not->clear();
      return p;
    }
  }
  return broadcast_state(sat, t, why_not);
}

std::optional<SatState> EphemerisStore::broadcast_state(const SatId& sat, TimeNs t, std::string* why_not) const {
  double max_age = 0.0;
  switch (sat.sys) {
    case Constellation::kGps: max_age = options_.gps_max_age_s; break;
    case Constellation::kGalileo: max_age = options_.galileo_max_age_s; break;
    case Constellation::kBeidou: max_age = options_.beidou_max_age_s; break;
    case Constellation::kQzss: max_age = options_.qzss_max_age_s; break;
    case Constellation::kGlonass: max_age = options_.glonass_max_age_s; break;
    default: return refuse(why_not, "unsupported constellation");
  }
  SatState s;
  if (sat.sys == Constellation::kGlonass) {
    const auto it = glonass_.find(sat);
    if (it == glonass_.end() || it->second.empty()) return refuse(why_not, "no ephemeris");
    const auto* g = nearest(it->second, t, [](const GlonassEphemeris& e) { return e.tb_gps_ns; },
                            [](const GlonassEphemeris&) { return true; });
    if (abs_age_s(t, g->tb_gps_ns) > max_age) return refuse(why_not, "stale ephemeris");
    s = glonass_state(*g, t);
  } else {
    const auto it = kepler_.find(sat);
    if (it == kepler_.end() || it->second.empty()) return refuse(why_not, "no ephemeris");
    const auto toe = [](const KeplerEphemeris& e) { return e.toe_gps_ns; };
    const KeplerEphemeris* k = nullptr;
    if (sat.sys == Constellation::kGalileo) {  // E1 users: I/NAV first (OS SIS ICD 5.1.9.2)
      k = nearest(it->second, t, toe, [](const KeplerEphemeris& e) { return is_galileo_inav(e); });
      if (k && abs_age_s(t, k->toe_gps_ns) > max_age) k = nullptr;
    }
    if (!k) k = nearest(it->second, t, toe, [](const KeplerEphemeris&) { return true; });
    if (abs_age_s(t, k->toe_gps_ns) > max_age) return refuse(why_not, "stale ephemeris");
    s = kepler_state(*k, t);
  }
  if (!s.healthy && !options_.accept_unhealthy) return refuse(why_not, "unhealthy");
  if (!finite_state(s)) return refuse(why_not, "numerical failure");
  if (why_not) why_not->clear();
  return s;
}

const KlobucharParams* EphemerisStore::klobuchar() const { return klobuchar_ ? &*klobuchar_ : nullptr; }

std::optional<int> EphemerisStore::glonass_channel(int slot) const {
  const auto it = glonass_.find(SatId{Constellation::kGlonass, slot});
  if (it == glonass_.end() || it->second.empty()) return std::nullopt;
  return it->second.back().channel;
}

std::vector<SatId> EphemerisStore::satellites() const {
  std::set<SatId> s;
  for (const auto& kv : kepler_)
    if (!kv.second.empty()) s.insert(kv.first);
  for (const auto& kv : glonass_)
    if (!kv.second.empty()) s.insert(kv.first);
  for (const auto& kv : precise_) s.insert(kv.first);
  return {s.begin(), s.end()};
}

std::size_t EphemerisStore::size() const {
  std::size_t n = 0;
  for (const auto& kv : kepler_) n += kv.second.size();
  for (const auto& kv : glonass_) n += kv.second.size();
  return n;
}

}  // namespace pdnav::gnss
