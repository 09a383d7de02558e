#include "pdnav/gnss/rinex_obs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/measurements.h"
#include "pdnav/gnss/rinex.h"

namespace pdnav::gnss {
namespace {

constexpr std::int64_t kNsPerHour = 3600 * kNsPerS;
const char* const kAndroidClockComment = "pdnav: Android clock bias in the epoch clock offset";

std::string label(const std::string& l) { return rinex_trim(rinex_field(l, 60, 20)); }

bool parse_int(const std::string& f, int& out) {
  const std::string t = rinex_trim(f);
  if (t.empty() || t.size() > 9) return false;
  int v = 0;
  std::size_t i = 0;
  bool neg = false;
  if (t[0] == '-' || t[0] == '+') { neg = t[0] == '-'; i = 1; }
  if (i >= t.size()) return false;
  for (; i < t.size(); ++i) {
    if (t[i] < '0' || t[i] > '9') return false;
    v = v * 10 + (t[i] - '0');
  }
  out = neg ? -v : v;
  return true;
}

/// "22.4299102" -> whole seconds and ns (exact, up to 9 decimals).
bool parse_seconds(const std::string& f, int& s, std::int64_t& ns) {
  const std::string t = rinex_trim(f);
  const auto dot = t.find('.');
  if (!parse_int(t.substr(0, dot), s)) return false;
  ns = 0;
  if (dot == std::string::npos) return true;
  const std::string frac = t.substr(dot + 1);
  if (frac.size() > 9) return false;
  std::int64_t scale = 100'000'000;
  for (char c : frac) {
    if (c < '0' || c > '9') return false;
    ns += (c - '0') * scale;
    scale /= 10;
  }
  return true;
}

int android_constellation(Constellation c) { return static_cast<int>(c); }

int android_svid(const SatId& s) { return s.sys == Constellation::kQzss ? s.prn + 192 : s.prn; }

/// Time of transmission in the satellite system's own time of week / day (Android
/// ReceivedSvTimeNanos conventions), from GPS time.
std::int64_t system_time_ns(Constellation sys, std::int64_t gps_ns, int leap_s) {
  auto mod = [](std::int64_t a, std::int64_t m) { const std::int64_t r = a % m; return r < 0 ? r + m : r; };
  switch (sys) {
    case Constellation::kBeidou: return mod(gps_ns - 14 * kNsPerS, geo::kNsPerWeek);
    case Constellation::kGlonass: return mod(gps_ns - std::int64_t{leap_s} * kNsPerS + 3 * kNsPerHour, geo::kNsPerDay);
    default: return mod(gps_ns, geo::kNsPerWeek);
  }
}

std::int64_t code_state_bits(Constellation sys) {
  if (sys == Constellation::kGlonass) return state_bit::kCodeLock | state_bit::kGloTodDecoded;
  return state_bit::kCodeLock | state_bit::kTowDecoded;
}

char band_of(Constellation sys, double f_hz) {
  if (!std::isfinite(f_hz)) return sys == Constellation::kBeidou ? '2' : '1';
  if (sys == Constellation::kGlonass) {
    if (f_hz > 1590e6 && f_hz < 1610e6) return '1';
    if (f_hz > 1237e6 && f_hz < 1255e6) return '2';
    return 0;
  }
  const struct { double f; char b; } bands[] = {
      {1575.42e6, '1'}, {1227.60e6, '2'}, {1176.45e6, '5'}, {1207.14e6, '7'}, {1191.795e6, '8'},
      {1278.75e6, '6'}, {1561.098e6, '2'}, {1268.52e6, '6'}};
  for (const auto& b : bands) {
    if (std::fabs(f_hz - b.f) < 2e6) {
      if (sys == Constellation::kBeidou && b.b == '1' ) return '1';
      if (sys != Constellation::kBeidou && std::fabs(b.f - 1561.098e6) < 1.0) continue;
      if (sys != Constellation::kBeidou && std::fabs(b.f - 1268.52e6) < 1.0) continue;
      return b.b;
    }
  }
  return 0;
}

char default_attribute(Constellation sys, char band) {
  if (band == '5') return 'X';
  if (sys == Constellation::kBeidou) return band == '1' ? 'P' : 'I';
  return 'C';
}

}  // namespace

std::int64_t RinexObsReport::skipped_total() const {
  std::int64_t n = 0;
  for (const auto& [k, v] : skipped_by_reason) n += v;
  return n;
}

bool looks_like_rinex_obs(const std::string& first_line) {
  return first_line.size() >= 61 && label(first_line) == "RINEX VERSION / TYPE" &&
         (rinex_field(first_line, 20, 1) == "O" || rinex_field(first_line, 20, 16).find("OBSERVATION") != std::string::npos);
}

double rinex_band_carrier_hz(Constellation sys, char band, int k) {
  switch (sys) {
    case Constellation::kGps: case Constellation::kQzss:
      if (band == '1') return 1575.42e6;
      if (band == '2') return 1227.60e6;
      if (band == '5') return 1176.45e6;
      if (band == '6' && sys == Constellation::kQzss) return 1278.75e6;
      return kNaN;
    case Constellation::kGalileo:
      if (band == '1') return 1575.42e6;
      if (band == '5') return 1176.45e6;
      if (band == '7') return 1207.14e6;
      if (band == '8') return 1191.795e6;
      if (band == '6') return 1278.75e6;
      return kNaN;
    case Constellation::kBeidou:
      if (band == '1') return 1575.42e6;
      if (band == '2') return 1561.098e6;
      if (band == '5') return 1176.45e6;
      if (band == '7') return 1207.14e6;
      if (band == '8') return 1191.795e6;
      if (band == '6') return 1268.52e6;
      return kNaN;
    case Constellation::kGlonass:
      if (k < -7 || k > 6) return kNaN;
      if (band == '1') return 1602.0e6 + k * 0.5625e6;
      if (band == '2') return 1246.0e6 + k * 0.4375e6;
      return kNaN;
    default: return kNaN;
  }
}

RinexObsReader::RinexObsReader(std::istream& in, std::string name) : in_(in), name_(std::move(name)) { read_header(); }

bool RinexObsReader::getline(std::string& l) {
  if (!std::getline(in_, l)) return false;
  if (!l.empty() && l.back() == '\r') l.pop_back();
  ++line_no_;
  return true;
}

void RinexObsReader::skip(const std::string& why) {
  ++report_.skipped_by_reason[why];
  if (report_.issues.size() < 100) report_.issues.push_back(name_ + ":" + std::to_string(line_no_) + ": " + why);
}

void RinexObsReader::read_header() {
  auto fail = [&](const std::string& why) {
    throw std::runtime_error(name_ + ":" + std::to_string(line_no_) + ": " + why);
  };
  std::string l;
  if (!getline(l)) fail("empty file (no RINEX header)");
  if (!looks_like_rinex_obs(l)) fail("not a RINEX observation file (no 'OBSERVATION DATA' RINEX VERSION / TYPE line)");
  const auto v = parse_rinex_double(rinex_field(l, 0, 9));
  if (!v || *v < 3.0 || *v >= 4.0)
    fail("RINEX observation version " + rinex_trim(rinex_field(l, 0, 9)) + " not supported (3.00-3.05 are)");
  header_.version = *v;
  header_.file_system = rinex_field(l, 40, 1).empty() || rinex_field(l, 40, 1) == " " ? 'G' : l[40];
  char cont_sys = 0;
  int cont_left = 0;
  int glo_left = 0;
  for (;;) {
    if (!getline(l)) fail("end of file before END OF HEADER");
    const std::string lab = label(l);
    if (lab == "END OF HEADER") break;
    if (lab == "SYS / # / OBS TYPES") {
      int n = 0;
      std::size_t col = 7;
      if (l[0] != ' ') {
        cont_sys = l[0];
        if (constellation_from_rinex_letter(cont_sys) == Constellation::kUnknown) fail("bad system letter in SYS / # / OBS TYPES");
        if (!parse_int(rinex_field(l, 3, 3), n) || n < 0 || n > 99) fail("bad observation type count");
        cont_left = n;
        header_.obs_types[cont_sys].clear();
      } else if (cont_left <= 0) {
        fail("SYS / # / OBS TYPES continuation without a system");
      }
      for (int i = 0; i < 13 && cont_left > 0; ++i, col += 4, --cont_left) {
        const std::string t = rinex_trim(rinex_field(l, col, 3));
        if (t.size() != 3) fail("bad observation type '" + t + "'");
        header_.obs_types[cont_sys].push_back(t);
      }
    } else if (lab == "GLONASS SLOT / FRQ #") {
      // I3,1X,8(A3,1X,I2,1X); read by tokens because some writers (Google's converter) shift
      // the columns by one
      std::istringstream tok(rinex_field(l, 0, 60));
      std::string t;
      if (glo_left <= 0) {
        int n = 0;
        if (!(tok >> t) || !parse_int(t, n) || n < 0 || n > 99) fail("bad GLONASS SLOT / FRQ # count");
        glo_left = n;
      }
      while (glo_left > 0 && tok >> t) {
        --glo_left;
        std::string kt;
        int slot = 0, k = 0;
        if (t.size() != 3 || t[0] != 'R' || !parse_int(t.substr(1), slot) || !(tok >> kt) || !parse_int(kt, k) ||
            k < -7 || k > 6) {
          skip("header: bad GLONASS SLOT / FRQ # entry");
          continue;
        }
        header_.glonass_channel[slot] = k;
      }
    } else if (lab == "COMMENT") {
      if (rinex_trim(rinex_field(l, 0, 60)) == kAndroidClockComment) header_.android_clock_offset = true;
    } else if (lab == "TIME OF FIRST OBS") {
      const std::string ts = rinex_trim(rinex_field(l, 48, 3));
      if (!ts.empty()) header_.time_system = ts;
    } else if (lab == "APPROX POSITION XYZ") {
      for (int i = 0; i < 3; ++i) {
        const auto x = parse_rinex_double(rinex_field(l, 14 * static_cast<std::size_t>(i), 14));
        header_.approx_xyz_m[i] = x ? *x : 0.0;
      }
    }
  }
  if (header_.obs_types.empty()) fail("no SYS / # / OBS TYPES in the header");
  const std::string& ts = header_.time_system;
  if (ts != "GPS" && ts != "GAL" && ts != "BDT" && ts != "GLO" && ts != "QZS")
    fail("unsupported time system '" + ts + "' (GPS, GAL, QZS, BDT, GLO are)");
}

bool RinexObsReader::next(RinexObsEpoch& out) {
  std::string l;
  while (getline(l)) {
    if (l.empty() || l[0] != '>') {
      if (!rinex_trim(l).empty()) skip("record outside an epoch");
      continue;
    }
    int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0, flag = 0, n = 0;
    std::int64_t sub_ns = 0;
    if (!parse_int(rinex_field(l, 2, 4), y) || !parse_int(rinex_field(l, 7, 2), mo) || !parse_int(rinex_field(l, 10, 2), d) ||
        !parse_int(rinex_field(l, 13, 2), h) || !parse_int(rinex_field(l, 16, 2), mi) || !parse_seconds(rinex_field(l, 18, 11), s, sub_ns) ||
        !parse_int(rinex_field(l, 31, 1), flag) || !parse_int(rinex_field(l, 32, 3), n) || n < 0) {
      skip("epoch: malformed epoch line");
      continue;
    }
    if (flag >= 2 && flag <= 5) {  // event: n special records follow
      for (int i = 0; i < n && getline(l); ++i) {}
      ++report_.skipped_by_reason["epoch: event record (flag 2-5)"];
      continue;
    }
    const std::string epoch_line = l;
    const bool bad_time = y < 1980 || y > 2200 || mo < 1 || mo > 12 || d < 1 || d > 31 || h < 0 || h > 23 ||
                          mi < 0 || mi > 59 || s < 0 || s > 60 || flag < 0 || flag > 6;
    std::vector<std::string> lines;
    for (int i = 0; i < n; ++i) {
      if (!getline(l)) break;
      lines.push_back(l);
    }
    if (static_cast<int>(lines.size()) < n) { skip("epoch: file ends inside an epoch"); return false; }
    if (bad_time) { skip("epoch: date/time out of range"); continue; }
    if (flag == 6) { ++report_.skipped_by_reason["epoch: cycle slip records (flag 6)"]; continue; }
    out = RinexObsEpoch{};
    out.flag = flag;
    if (flag == 1) ++discontinuities_;
    out.clock_discontinuity_count = discontinuities_;
    const double cal_s = geo::calendar_to_epoch_seconds(y, mo, d, h, mi, 0.0) + s;
    std::int64_t ns = static_cast<std::int64_t>(std::llround(cal_s)) * kNsPerS + sub_ns;
    const std::string& ts = header_.time_system;
    if (ts == "BDT") ns += 14 * kNsPerS;
    if (ts == "GLO") ns += geo::leap_seconds_at_gps_ns(ns) * kNsPerS;
    out.gps_ns = ns;
    const std::string off = rinex_trim(rinex_field(epoch_line, 41, 15));
    if (!off.empty()) {
      const auto v = parse_rinex_double(off);
      if (v && std::fabs(*v) < 1e3) out.clock_offset_s = *v;
      else skip("epoch: bad receiver clock offset (ignored)");
    }
    for (const std::string& sl : lines) {
      SatId sat;
      sat.sys = constellation_from_rinex_letter(sl.empty() ? '?' : sl[0]);
      int prn = 0;
      if (sl.size() < 3 || sat.sys == Constellation::kUnknown || !parse_int(rinex_field(sl, 1, 2), prn) || prn < 1) {
        skip("satellite: malformed satellite record");
        continue;
      }
      sat.prn = prn;
      const auto it = header_.obs_types.find(sl[0]);
      if (it == header_.obs_types.end()) { skip("satellite: system not in the header's obs types"); continue; }
      RinexSatObs so;
      so.sat = sat;
      const auto& types = it->second;
      bool bad = false;
      for (std::size_t i = 0; i < types.size(); ++i) {
        const std::string f = rinex_field(sl, 3 + 16 * i, 14);
        const std::string lli = rinex_field(sl, 3 + 16 * i + 14, 1);
        if (rinex_trim(f).empty()) continue;
        const auto v = parse_rinex_double(f);
        if (!v) { bad = true; break; }
        const std::string& t = types[i];
        const std::string code = t.substr(1, 2);
        auto sig = std::find_if(so.signals.begin(), so.signals.end(), [&](const RinexSignalObs& o) { return o.code == code; });
        if (sig == so.signals.end()) { so.signals.push_back(RinexSignalObs{}); sig = so.signals.end() - 1; sig->code = code; }
        switch (t[0]) {
          case 'C': sig->pseudorange_m = *v; break;
          case 'L': {
            sig->phase_cycles = *v;
            int li = 0;
            if (!lli.empty() && lli != " " && parse_int(lli, li)) sig->phase_lli = li;
            break;
          }
          case 'D': sig->doppler_hz = *v; break;
          case 'S': sig->cn0_dbhz = *v; break;
          default: break;  // ionosphere / channel observables are not used
        }
      }
      if (bad) { skip("satellite: non-numeric observation"); continue; }
      ++report_.satellite_records;
      report_.signals += static_cast<std::int64_t>(so.signals.size());
      out.sats.push_back(std::move(so));
    }
    ++report_.epochs;
    return true;
  }
  return false;
}

std::vector<GnssRawSample> rinex_epoch_to_raw(const RinexObsEpoch& ep, const RinexObsHeader& hdr,
                                              std::map<std::string, std::int64_t>& skipped) {
  std::vector<GnssRawSample> rows;
  const int leap = geo::leap_seconds_at_gps_ns(ep.gps_ns);
  for (const RinexSatObs& so : ep.sats) {
    int k = 99;
    if (so.sat.sys == Constellation::kGlonass) {
      const auto it = hdr.glonass_channel.find(so.sat.prn);
      if (it != hdr.glonass_channel.end()) k = it->second;
    }
    for (const RinexSignalObs& sig : so.signals) {
      const double f = rinex_band_carrier_hz(so.sat.sys, sig.code.empty() ? '?' : sig.code[0], k);
      if (!std::isfinite(f)) { ++skipped["rinex: no carrier frequency (unknown band or GLONASS slot)"]; continue; }
      const double lambda = kSpeedOfLight_mps / f;
      GnssRawSample r;
      r.t_ns = ep.gps_ns;
      // Android clock model: receive time = TimeNanos - (FullBiasNanos + BiasNanos) = epoch.
      // A pdnav-written file carries the change of FullBias + Bias in the clock offset
      // field, which the engine removes from phase and Doppler exactly as for the log.
      const double off_ns = hdr.android_clock_offset ? ep.clock_offset_s * 1e9 : 0.0;
      r.full_bias_nanos = static_cast<std::int64_t>(std::floor(off_ns));
      r.bias_nanos = off_ns - static_cast<double>(r.full_bias_nanos);
      r.time_nanos = ep.gps_ns + r.full_bias_nanos;
      r.leap_second = leap;
      r.hardware_clock_discontinuity_count = ep.clock_discontinuity_count;
      r.constellation_type = android_constellation(so.sat.sys);
      r.svid = android_svid(so.sat);
      r.carrier_frequency_hz = f;
      r.code_type = sig.code.size() > 1 ? sig.code.substr(1, 1) : std::string();
      r.cn0_dbhz = sig.cn0_dbhz;
      r.time_offset_nanos = 0.0;
      if (std::isfinite(sig.pseudorange_m) && sig.pseudorange_m > 0.0 && sig.pseudorange_m < 1e9) {
        const double pr_ns = sig.pseudorange_m / kSpeedOfLight_mps * 1e9;
        const double whole = std::floor(pr_ns);
        const std::int64_t tx_gps_ns = ep.gps_ns - static_cast<std::int64_t>(whole);
        r.received_sv_time_nanos = system_time_ns(so.sat.sys, tx_gps_ns, leap);
        r.time_offset_nanos = (pr_ns - whole) + r.bias_nanos;  // the sub-ns rest of the code (BiasNanos is subtracted again)
        r.state = code_state_bits(so.sat.sys);
      }
      if (std::isfinite(sig.doppler_hz)) r.pseudorange_rate_mps = -sig.doppler_hz * lambda;
      if (std::isfinite(sig.phase_cycles) && sig.phase_cycles != 0.0) {
        r.accumulated_delta_range_m = sig.phase_cycles * lambda;
        r.accumulated_delta_range_state = adr_bit::kValid | ((sig.phase_lli & 1) ? adr_bit::kCycleSlip : 0);
      }
      rows.push_back(std::move(r));
    }
  }
  return rows;
}

// ----------------------------------------------------------------------------- writer

RinexObsWriter::RinexObsWriter(std::string program) : program_(std::move(program)) {}

bool RinexObsWriter::add(const GnssRawSample& r, std::string* why) {
  auto no = [&](const char* reason) { if (why) *why = reason; return false; };
  const SatId sat = SatId::from_android(r.constellation_type, r.svid);
  const char letter = rinex_letter(sat.sys);
  if (sat.sys != Constellation::kGps && sat.sys != Constellation::kGlonass && sat.sys != Constellation::kGalileo &&
      sat.sys != Constellation::kBeidou && sat.sys != Constellation::kQzss)
    return no("rinex: unsupported constellation");
  if (sat.sys == Constellation::kGlonass && (sat.prn < 1 || sat.prn > 24)) return no("rinex: GLONASS slot unknown");
  if (sat.prn < 1 || sat.prn > 99) return no("rinex: bad svid");
  GpsTime rx;
  if (r.time_nanos == kMissingInt || !receive_gps_time(r, rx)) return no("rinex: no GPS time (FullBiasNanos missing)");
  const double sub_bias_ns = std::isfinite(r.bias_nanos) ? r.bias_nanos : 0.0;
  if (r.time_nanos != current_time_nanos_) {
    // a new epoch: epoch time = receive time without the per-row offset, to 100 ns
    const double off = (std::isfinite(r.time_offset_nanos) ? r.time_offset_nanos : 0.0);
    RinexObsEpoch e;
    const double frac = rx.frac_ns - off;
    const std::int64_t rem = rx.ns % 100;
    e.gps_ns = rx.ns - rem + static_cast<std::int64_t>(std::llround((static_cast<double>(rem) + frac) / 100.0)) * 100;
    const bool disc = r.hardware_clock_discontinuity_count != last_disc_ && last_disc_ != kMissingInt;
    last_disc_ = r.hardware_clock_discontinuity_count;
    if (!have_ref_ || disc) { ref_full_bias_ns_ = r.full_bias_nanos; ref_bias_ns_ = sub_bias_ns; have_ref_ = true; }
    // The code is referred to the corrected receive time (TimeNanos - FullBias - Bias), the
    // carrier phase and Doppler stay on the hardware clock (as Android reports them); the
    // epoch's receiver clock offset field carries the change of FullBias + Bias since the
    // reference, so a reader can put them on one clock (RINEX 3.04 Table A2, cols 42-56).
    // exact int64 difference first: FullBiasNanos ~ -1e18 has a 256 ns ulp as a double
    std::int64_t d_full = 0;
    if (__builtin_sub_overflow(r.full_bias_nanos, ref_full_bias_ns_, &d_full)) d_full = std::int64_t{1} << 62;
    e.clock_offset_s = (static_cast<double>(d_full) + (sub_bias_ns - ref_bias_ns_)) * 1e-9;
    if (!(std::fabs(e.clock_offset_s) < 900.0)) {
      ref_full_bias_ns_ = r.full_bias_nanos;
      ref_bias_ns_ = sub_bias_ns;
      e.clock_offset_s = 0.0;
      disc_ = true;
    }
    epoch_disc_ = disc || disc_;
    e.flag = epoch_disc_ ? 1 : 0;  // flag 1 ("power failure"): the receiver clock restarted
    disc_ = false;
    epochs_.push_back(e);
    current_time_nanos_ = r.time_nanos;
  }
  RinexObsEpoch& e = epochs_.back();
  const double f = std::isfinite(r.carrier_frequency_hz) && r.carrier_frequency_hz > 1e8
                       ? r.carrier_frequency_hz : default_carrier_hz(sat.sys, 0);
  const char band = band_of(sat.sys, f);
  if (!band) return no("rinex: carrier frequency not a RINEX band");
  double freq = f;
  if (sat.sys == Constellation::kGlonass) {
    // FDMA: the frequency number from the carrier frequency
    const double base = band == '1' ? 1602.0e6 : 1246.0e6, step = band == '1' ? 0.5625e6 : 0.4375e6;
    if (!std::isfinite(r.carrier_frequency_hz)) return no("rinex: GLONASS without CarrierFrequencyHz (channel unknown)");
    const int k = static_cast<int>(std::lround((f - base) / step));
    if (k < -7 || k > 6) return no("rinex: GLONASS frequency number out of range");
    glonass_channel_[sat.prn] = k;
    freq = base + k * step;
  }
  const char attr = !r.code_type.empty() && r.code_type.size() == 1 && r.code_type[0] >= 'A' && r.code_type[0] <= 'Z'
                        ? r.code_type[0] : default_attribute(sat.sys, band);
  const std::string code{band, attr};
  const double lambda = kSpeedOfLight_mps / freq;
  RinexSignalObs sig;
  sig.code = code;
  std::string reason;
  const int leap = (r.leap_second != kMissingInt && r.leap_second >= 0 && r.leap_second < 100)
                       ? static_cast<int>(r.leap_second) : geo::leap_seconds_at_gps_ns(rx.ns);
  if (r.received_sv_time_nanos != kMissingInt && r.received_sv_time_nanos >= 0) {
    const double pr = pseudorange_m(r, rx, leap, reason);
    if (std::isfinite(pr) && pr > 1e7 && pr < 1e8) sig.pseudorange_m = pr;
  }
  const std::int64_t st = r.accumulated_delta_range_state;
  if (st != kMissingInt && (st & adr_bit::kValid) && std::isfinite(r.accumulated_delta_range_m) &&
      r.accumulated_delta_range_m != 0.0) {
    const double cyc = r.accumulated_delta_range_m / lambda;
    if (std::fabs(cyc) < 1e9) {
      sig.phase_cycles = cyc;
      if ((st & adr_bit::kReset) || (st & adr_bit::kCycleSlip) || epoch_disc_) sig.phase_lli = 1;
    }
  }
  if (std::isfinite(r.pseudorange_rate_mps) && std::fabs(r.pseudorange_rate_mps) < 1e5)
    sig.doppler_hz = -r.pseudorange_rate_mps / lambda;
  if (std::isfinite(r.cn0_dbhz) && r.cn0_dbhz > 0 && r.cn0_dbhz < 1000) sig.cn0_dbhz = r.cn0_dbhz;
  if (!std::isfinite(sig.pseudorange_m) && !std::isfinite(sig.phase_cycles) && !std::isfinite(sig.doppler_hz))
    return no("rinex: no code, phase or Doppler");
  auto so = std::find_if(e.sats.begin(), e.sats.end(), [&](const RinexSatObs& o) { return o.sat == sat; });
  if (so == e.sats.end()) { e.sats.push_back(RinexSatObs{sat, {}}); so = e.sats.end() - 1; }
  if (std::any_of(so->signals.begin(), so->signals.end(), [&](const RinexSignalObs& o) { return o.code == code; }))
    return no("rinex: duplicate signal in epoch (first kept)");
  so->signals.push_back(sig);
  auto& list = codes_[letter];
  if (std::find(list.begin(), list.end(), code) == list.end()) list.push_back(code);
  return true;
}

std::int64_t RinexObsWriter::finish(std::ostream& out) {
  char buf[128];
  auto line = [&](const std::string& body, const char* lab) {
    std::string b = body;
    b.resize(60, ' ');
    out << b << lab << "\n";
  };
  std::snprintf(buf, sizeof buf, "%9.2f%11s%-20s%-20s", 3.04, "", "OBSERVATION DATA", "M: Mixed");
  line(buf, "RINEX VERSION / TYPE");
  std::string date = "00000000 000000 UTC";
  if (!epochs_.empty()) {
    const std::int64_t unix_ms = geo::gps_ns_to_unix_ms(epochs_.front().gps_ns);
    const std::int64_t days = unix_ms / 86'400'000, ms_day = unix_ms % 86'400'000;
    // civil from days since 1970-01-01 (Hinnant's algorithm)
    std::int64_t z = days + 719468, era = (z >= 0 ? z : z - 146096) / 146097;
    const std::int64_t doe = z - era * 146097, yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    const std::int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100), mp = (5 * doy + 2) / 153;
    const std::int64_t dd = doy - (153 * mp + 2) / 5 + 1, mm = mp < 10 ? mp + 3 : mp - 9, yy = yoe + era * 400 + (mm <= 2);
    std::snprintf(buf, sizeof buf, "%04lld%02lld%02lld %02lld%02lld%02lld UTC", static_cast<long long>(yy),
                  static_cast<long long>(mm), static_cast<long long>(dd), static_cast<long long>(ms_day / 3'600'000),
                  static_cast<long long>(ms_day / 60'000 % 60), static_cast<long long>(ms_day / 1000 % 60));
    date = buf;
  }
  std::snprintf(buf, sizeof buf, "%-20s%-20s%-20s", program_.c_str(), "pdnav", date.c_str());
  line(buf, "PGM / RUN BY / DATE");
  line("pdnav", "MARKER NAME");
  line("NON_GEODETIC", "MARKER TYPE");
  line(std::string(20, ' ') + "Unknown", "OBSERVER / AGENCY");
  std::snprintf(buf, sizeof buf, "%-20s%-20s%-20s", "Unknown", "Android phone", "");
  line(buf, "REC # / TYPE / VERS");
  std::snprintf(buf, sizeof buf, "%-20s%-20s", "Unknown", "Android phone");
  line(buf, "ANT # / TYPE");
  std::snprintf(buf, sizeof buf, "%14.4f%14.4f%14.4f", 0.0, 0.0, 0.0);
  line(buf, "APPROX POSITION XYZ");
  line(buf, "ANTENNA: DELTA H/E/N");
  std::map<char, std::vector<std::string>> types;
  for (auto& [sys, codes] : codes_) {
    std::sort(codes.begin(), codes.end());
    for (const auto& c : codes)
      for (char t : {'C', 'L', 'D', 'S'}) types[sys].push_back(std::string(1, t) + c);
    std::string body;
    std::snprintf(buf, sizeof buf, "%c  %3zu", sys, types[sys].size());
    body = buf;
    for (std::size_t i = 0; i < types[sys].size(); ++i) {
      if (i > 0 && i % 13 == 0) { line(body, "SYS / # / OBS TYPES"); body = "      "; }
      body += " " + types[sys][i];
    }
    line(body, "SYS / # / OBS TYPES");
  }
  line("DBHZ", "SIGNAL STRENGTH UNIT");
  line("0", "RCV CLOCK OFFS APPL");
  line(kAndroidClockComment, "COMMENT");
  line("phase and Doppler on the hardware clock; code on TimeNanos", "COMMENT");
  line("- FullBiasNanos - BiasNanos; epoch clock offset = change", "COMMENT");
  line("of FullBiasNanos + BiasNanos (s) since the first epoch", "COMMENT");
  auto epoch_fields = [&](std::int64_t gps_ns, char* b, std::size_t n) {
    // GPS calendar (no leap seconds): days since the GPS epoch + 1980-01-06
    const std::int64_t days = gps_ns / geo::kNsPerDay, ns_day = gps_ns % geo::kNsPerDay;
    std::int64_t z = days + 3657 + 719468, era = z / 146097;  // 1980-01-06 is day 3657 after 1970-01-01
    const std::int64_t doe = z - era * 146097, yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    const std::int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100), mp = (5 * doy + 2) / 153;
    const std::int64_t dd = doy - (153 * mp + 2) / 5 + 1, mm = mp < 10 ? mp + 3 : mp - 9, yy = yoe + era * 400 + (mm <= 2);
    const std::int64_t h = ns_day / kNsPerHour, mi = ns_day / (60 * kNsPerS) % 60, s = ns_day / kNsPerS % 60;
    const std::int64_t sub = ns_day % kNsPerS / 100;  // 0.1 us units
    std::snprintf(b, n, "%4lld %02lld %02lld %02lld %02lld %2lld.%07lld", static_cast<long long>(yy),
                  static_cast<long long>(mm), static_cast<long long>(dd), static_cast<long long>(h),
                  static_cast<long long>(mi), static_cast<long long>(s), static_cast<long long>(sub));
  };
  if (!epochs_.empty()) {
    char t[64];
    epoch_fields(epochs_.front().gps_ns, t, sizeof t);
    std::snprintf(buf, sizeof buf, "  %s     %-3s", t, "GPS");
    line(buf, "TIME OF FIRST OBS");
  }
  if (codes_.count('R')) {
    std::string body;
    std::snprintf(buf, sizeof buf, "%3zu ", glonass_channel_.size());
    body = buf;
    int i = 0;
    for (const auto& [slot, k] : glonass_channel_) {
      if (i > 0 && i % 8 == 0) { line(body, "GLONASS SLOT / FRQ #"); body = "    "; }
      std::snprintf(buf, sizeof buf, "R%02d %2d ", slot, k);
      body += buf;
      ++i;
    }
    line(body, "GLONASS SLOT / FRQ #");
    line(" C1C    0.000 C1P    0.000 C2C    0.000 C2P    0.000", "GLONASS COD/PHS/BIS");
  }
  line("", "END OF HEADER");
  for (const RinexObsEpoch& e : epochs_) {
    if (e.sats.empty()) continue;
    char t[64];
    epoch_fields(e.gps_ns, t, sizeof t);
    std::snprintf(buf, sizeof buf, "> %s  %1d%3zu      %15.12f", t, e.flag, e.sats.size(), e.clock_offset_s);
    out << buf << "\n";
    for (const RinexSatObs& so : e.sats) {
      const char sys = rinex_letter(so.sat.sys);
      std::snprintf(buf, sizeof buf, "%c%02d", sys, so.sat.prn);
      std::string l = buf;
      for (const std::string& ty : types[sys]) {
        const std::string code = ty.substr(1, 2);
        const auto sig = std::find_if(so.signals.begin(), so.signals.end(), [&](const RinexSignalObs& o) { return o.code == code; });
        double v = kNaN;
        int lli = 0;
        if (sig != so.signals.end()) {
          if (ty[0] == 'C') v = sig->pseudorange_m;
          if (ty[0] == 'L') { v = sig->phase_cycles; lli = sig->phase_lli; }
          if (ty[0] == 'D') v = sig->doppler_hz;
          if (ty[0] == 'S') v = sig->cn0_dbhz;
        }
        if (std::isfinite(v) && std::fabs(v) < 1e10) {
          std::snprintf(buf, sizeof buf, "%14.3f%c ", v, lli ? static_cast<char>('0' + lli) : ' ');
          l += buf;
        } else {
          l += std::string(16, ' ');
        }
      }
      while (!l.empty() && l.back() == ' ') l.pop_back();
      out << l << "\n";
    }
  }
  std::int64_t n = 0;
  for (const auto& e : epochs_) n += !e.sats.empty();
  return n;
}

}  // namespace pdnav::gnss
