#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/rinex.h"

namespace pdnav::gnss {
namespace {

constexpr std::size_t kMaxIssues = 100;
constexpr int kMaxHeaderLines = 2000;

struct Line {
  std::string text;
  int number = 0;
};

/// Thrown inside the record parser; caught per record and counted.
struct RecordError {
  std::string reason;
};

std::string header_label(const std::string& line) { return rinex_trim(rinex_field(line, 60, 20)); }

double need_double(const std::string& f) {
  const auto v = parse_rinex_double(f);
  if (!v) throw RecordError{"non-numeric field '" + rinex_trim(f) + "'"};
  return *v;
}

int need_int(const std::string& f, int lo, int hi, const char* what) {
  const double v = need_double(f);
  if (v != std::floor(v) || v < lo || v > hi) throw RecordError{std::string("bad ") + what + " '" + rinex_trim(f) + "'"};
  return static_cast<int>(v);
}

/// Layout of the body lines: prefix width and first-line geometry differ between 2 and 3.
struct Layout {
  bool v3 = true;
  std::size_t prefix() const { return v3 ? 4 : 3; }
  std::size_t first_values_col() const { return v3 ? 23 : 22; }
};

struct Epoch {
  int year, month, day, hour, minute;
  double second;
  double calendar_s() const { return geo::calendar_to_epoch_seconds(year, month, day, hour, minute, second); }
};

Epoch parse_epoch(const std::string& l, const Layout& lay) {
  Epoch e{};
  if (lay.v3) {
    e.year = need_int(rinex_field(l, 4, 4), 1980, 2200, "year");
    e.month = need_int(rinex_field(l, 9, 2), 1, 12, "month");
    e.day = need_int(rinex_field(l, 12, 2), 1, 31, "day");
    e.hour = need_int(rinex_field(l, 15, 2), 0, 24, "hour");
    e.minute = need_int(rinex_field(l, 18, 2), 0, 59, "minute");
    e.second = need_double(rinex_field(l, 21, 2));
  } else {
    const int yy = need_int(rinex_field(l, 2, 3), 0, 99, "year");
    e.year = yy < 80 ? 2000 + yy : 1900 + yy;
    e.month = need_int(rinex_field(l, 5, 3), 1, 12, "month");
    e.day = need_int(rinex_field(l, 8, 3), 1, 31, "day");
    e.hour = need_int(rinex_field(l, 11, 3), 0, 24, "hour");
    e.minute = need_int(rinex_field(l, 14, 3), 0, 59, "minute");
    e.second = need_double(rinex_field(l, 17, 5));
  }
  if (e.second < 0 || e.second > 61) throw RecordError{"bad second"};
  return e;
}

/// All broadcast values of a record: 3 on the first line, 4 per continuation line.
std::vector<double> record_values(const std::vector<Line>& rec, const Layout& lay) {
  std::vector<double> v;
  for (int i = 0; i < 3; ++i) v.push_back(need_double(rinex_field(rec[0].text, lay.first_values_col() + 19 * i, 19)));
  for (std::size_t k = 1; k < rec.size(); ++k)
    for (int i = 0; i < 4; ++i) v.push_back(need_double(rinex_field(rec[k].text, lay.prefix() + 19 * i, 19)));
  return v;
}

/// Integer-valued broadcast field (IODE, flags, health); refuses values an int cannot hold.
int to_int_field(double v, const char* what) {
  if (!(std::abs(v) < 2.0e9)) throw RecordError{std::string("bad ") + what};
  return static_cast<int>(v);
}

double week_wrapped_time(double toc_sys_s, double toe_sow) {
  const double toc_sow = std::fmod(toc_sys_s, static_cast<double>(geo::kSecondsPerWeek));
  return toc_sys_s + geo::wrap_week_s(toe_sow - toc_sow);
}

TimeNs seconds_to_ns(double s) { return static_cast<TimeNs>(std::llround(s * 1e9)); }

KeplerEphemeris parse_kepler(const SatId& sat, const Epoch& ep, const std::vector<double>& v) {
  if (v.size() < 29) throw RecordError{"truncated record"};
  KeplerEphemeris k;
  k.sat = sat;
  k.af0_s = v[0]; k.af1_sps = v[1]; k.af2_sps2 = v[2];
  k.iode = to_int_field(v[3], "IODE");
  k.crs_m = v[4]; k.delta_n_radps = v[5]; k.m0_rad = v[6];
  k.cuc_rad = v[7]; k.e = v[8]; k.cus_rad = v[9]; k.sqrt_a_sqrtm = v[10];
  const double toe_sow = v[11];
  k.cic_rad = v[12]; k.omega0_rad = v[13]; k.cis_rad = v[14];
  k.i0_rad = v[15]; k.crc_m = v[16]; k.omega_rad = v[17]; k.omega_dot_radps = v[18];
  k.idot_radps = v[19];
  k.accuracy_m = v[23];
  k.health = v[24];
  k.group_delay_s = v[25];
  if (!(k.sqrt_a_sqrtm > 2000.0 && k.sqrt_a_sqrtm < 10000.0)) throw RecordError{"implausible sqrt(A)"};
  if (!(k.e >= 0.0 && k.e < 0.5)) throw RecordError{"implausible eccentricity"};
  if (!(toe_sow >= 0.0 && toe_sow <= 604800.0)) throw RecordError{"implausible toe"};
  if (!(std::abs(k.af0_s) < 1.0 && std::abs(k.af1_sps) < 1e-3 && std::abs(k.af2_sps2) < 1e-3))
    throw RecordError{"implausible clock"};
  const double sys_offset_s = sat.sys == Constellation::kBeidou ? 14.0 : 0.0;  // BDT = GPST - 14 s
  const double toc_sys = ep.calendar_s();
  k.toc_gps_ns = seconds_to_ns(toc_sys + sys_offset_s);
  k.toe_gps_ns = seconds_to_ns(week_wrapped_time(toc_sys, toe_sow) + sys_offset_s);
  if (sat.sys == Constellation::kGalileo) {
    k.data_source = to_int_field(v[20], "data sources");
    const bool fnav = (k.data_source & 0x2) != 0 && (k.data_source & 0x5) == 0;
    // Single-frequency E1 users: BGD(E1,E5b) with the I/NAV clock, BGD(E1,E5a) with F/NAV
    // (OS SIS ICD 5.1.5). Health: E1-B DVS/HS bits 0-2 (I/NAV) or E5a bits 3-5 (F/NAV).
    k.group_delay_s = fnav ? v[25] : v[26];
    const int health = to_int_field(v[24], "health");
    k.health = fnav ? (health & 0x38) : (health & 0x07);
  }
  if (sat.sys == Constellation::kBeidou) k.bds_geo = sat.prn <= 5 || sat.prn >= 59;
  return k;
}

GlonassEphemeris parse_glonass(const SatId& sat, const Epoch& ep, const std::vector<double>& v) {
  if (v.size() < 15) throw RecordError{"truncated record"};
  GlonassEphemeris g;
  g.sat = sat;
  g.minus_tau_n_s = v[0];
  g.gamma_n = v[1];
  g.pos_m = Eigen::Vector3d(v[3], v[7], v[11]) * 1e3;
  g.vel_mps = Eigen::Vector3d(v[4], v[8], v[12]) * 1e3;
  g.acc_mps2 = Eigen::Vector3d(v[5], v[9], v[13]) * 1e3;
  g.health = to_int_field(v[6], "health");
  const double k = v[10];
  if (k != std::floor(k) || k < -7 || k > 13) throw RecordError{"bad GLONASS frequency number"};
  g.channel = static_cast<int>(k);
  const double r = g.pos_m.norm();
  if (!(r > 2.0e7 && r < 3.0e7) || g.vel_mps.norm() > 1e4 || g.acc_mps2.norm() > 1e-3 || std::abs(g.minus_tau_n_s) > 1.0 ||
      std::abs(g.gamma_n) > 1e-3)
    throw RecordError{"implausible GLONASS state"};
  // RINEX epochs of GLONASS records are UTC (RINEX 3.04 6.10); GPST = UTC + leap seconds.
  const double utc_s = ep.calendar_s();
  const auto unix_ms = static_cast<std::int64_t>(std::llround(utc_s * 1e3)) + geo::kGpsEpochUnixMs;
  g.tb_gps_ns = seconds_to_ns(utc_s + geo::leap_seconds_at_unix_ms(unix_ms));
  return g;
}

std::size_t min_lines(Constellation sys) { return sys == Constellation::kGlonass ? 4 : 8; }

class Parser {
 public:
  Parser(std::istream& in, std::string name) : in_(in), name_(std::move(name)) { out_.report.file = name_; }

  RinexNavData run() {
    read_header();
    read_body();
    return std::move(out_);
  }

 private:
  bool next_line(Line& l) {
    if (!std::getline(in_, l.text)) return false;
    if (!l.text.empty() && l.text.back() == '\r') l.text.pop_back();
    l.number = ++line_no_;
    return true;
  }

  [[noreturn]] void fail(int line, const std::string& reason) const {
    throw std::runtime_error(name_ + ":" + std::to_string(line) + ": " + reason);
  }

  void read_header() {
    Line l;
    if (!next_line(l)) fail(0, "empty file");
    if (header_label(l.text) != "RINEX VERSION / TYPE") fail(l.number, "not a RINEX file (no RINEX VERSION / TYPE)");
    const auto ver = parse_rinex_double(rinex_field(l.text, 0, 9));
    if (!ver || *ver < 2.0 || *ver >= 4.0) fail(l.number, "unsupported RINEX version '" + rinex_trim(rinex_field(l.text, 0, 9)) + "'");
    out_.version = *ver;
    lay_.v3 = *ver >= 3.0;
    const char type = rinex_field(l.text, 20, 1).empty() ? ' ' : l.text[20];
    if (lay_.v3) {
      if (type != 'N') fail(l.number, "not a navigation file (type '" + std::string(1, type) + "')");
      out_.file_system = rinex_field(l.text, 40, 1).empty() ? 'G' : l.text[40];
    } else {
      if (type != 'N' && type != 'G') fail(l.number, "unsupported RINEX 2 file type '" + std::string(1, type) + "'");
      out_.file_system = type == 'G' ? 'R' : 'G';
    }
    for (int i = 0; i < kMaxHeaderLines; ++i) {
      if (!next_line(l)) fail(line_no_, "no END OF HEADER");
      const std::string label = header_label(l.text);
      if (label == "END OF HEADER") return;
      header_line(l, label);
    }
    fail(line_no_, "header too long (no END OF HEADER)");
  }

  void header_line(const Line& l, const std::string& label) {
    if (label == "ION ALPHA" || label == "ION BETA") {
      set_klobuchar(l, label == "ION ALPHA", 2);
    } else if (label == "IONOSPHERIC CORR") {
      const std::string kind = rinex_field(l.text, 0, 4);
      if (kind == "GPSA" || kind == "GPSB") set_klobuchar(l, kind == "GPSA", 5);
    }
  }

  void set_klobuchar(const Line& l, bool alpha, std::size_t col) {
    std::array<double, 4> c{};
    for (std::size_t i = 0; i < 4; ++i) {
      const auto v = parse_rinex_double(rinex_field(l.text, col + 12 * i, 12));
      if (!v) { issue(l.number, "bad ionosphere coefficients"); return; }
      c[i] = *v;
    }
    if (!out_.klobuchar) out_.klobuchar = KlobucharParams{};
    (alpha ? out_.klobuchar->alpha : out_.klobuchar->beta) = c;
  }

  bool is_record_start(const std::string& t) const {
    return !rinex_trim(rinex_field(t, 0, lay_.prefix())).empty();
  }

  void read_body() {
    std::vector<Line> rec;
    Line l;
    while (next_line(l)) {
      if (rinex_trim(l.text).empty()) continue;
      if (is_record_start(l.text)) {
        if (!rec.empty()) parse_record(rec);
        rec.clear();
      } else if (rec.empty()) {
        skip(l.number, "continuation line without a record");
        continue;
      }
      rec.push_back(l);
    }
    if (!rec.empty()) parse_record(rec);
  }

  SatId record_sat(const std::string& t) const {
    SatId s;
    if (lay_.v3) {
      s.sys = constellation_from_rinex_letter(t[0]);
      if (s.sys == Constellation::kUnknown) throw RecordError{"unknown system '" + std::string(1, t[0]) + "'"};
      s.prn = need_int(rinex_field(t, 1, 2), 1, 99, "satellite number");
    } else {
      s.sys = out_.file_system == 'R' ? Constellation::kGlonass : Constellation::kGps;
      s.prn = need_int(rinex_field(t, 0, 2), 1, 99, "satellite number");
    }
    return s;
  }

  void parse_record(const std::vector<Line>& rec) {
    try {
      const SatId sat = record_sat(rec[0].text);
      if (sat.sys == Constellation::kIrnss || sat.sys == Constellation::kSbas) {
        ++out_.report.skipped_by_reason[std::string(to_string(sat.sys)) + " not supported"];
        return;
      }
      if (rec.size() < min_lines(sat.sys)) throw RecordError{"truncated record"};
      const Epoch ep = parse_epoch(rec[0].text, lay_);
      const std::vector<double> v = record_values(rec, lay_);
      if (sat.sys == Constellation::kGlonass) out_.glonass.push_back(parse_glonass(sat, ep, v));
      else out_.kepler.push_back(parse_kepler(sat, ep, v));
      ++out_.report.records_by_system[to_string(sat.sys)];
    } catch (const RecordError& e) {
      skip(rec[0].number, e.reason);
    }
  }

  void skip(int line, const std::string& reason) {
    ++out_.report.skipped_by_reason[reason];
    issue(line, reason);
  }

  void issue(int line, const std::string& reason) {
    if (out_.report.issues.size() < kMaxIssues)
      out_.report.issues.push_back(name_ + ":" + std::to_string(line) + ": " + reason);
  }

  std::istream& in_;
  std::string name_;
  int line_no_ = 0;
  Layout lay_;
  RinexNavData out_;
};

}  // namespace

std::string rinex_field(const std::string& line, std::size_t col, std::size_t width) {
  if (col >= line.size()) return {};
  return line.substr(col, width);
}

std::string rinex_trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

std::optional<double> parse_rinex_double(const std::string& f) {
  std::string s = rinex_trim(f);
  if (s.empty()) return 0.0;
  for (char& c : s)
    if (c == 'D' || c == 'd') c = 'E';
  const char* b = s.c_str();
  char* end = nullptr;
  const double v = std::strtod(b, &end);
  if (end == b || *end != '\0' || !std::isfinite(v)) return std::nullopt;
  return v;
}

RinexNavData read_rinex_nav(std::istream& in, const std::string& name) { return Parser(in, name).run(); }

RinexNavData read_rinex_nav_file(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ":0: cannot open");
  return read_rinex_nav(f, path);
}

}  // namespace pdnav::gnss
