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

std::optional<SatState> EphemerisStore::state(const SatId& sat, TimeNs t, std::string* why_not) const {
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
  return {s.begin(), s.end()};
}

std::size_t EphemerisStore::size() const {
  std::size_t n = 0;
  for (const auto& kv : kepler_) n += kv.second.size();
  for (const auto& kv : glonass_) n += kv.second.size();
  return n;
}

}  // namespace pdnav::gnss
