#include "pdnav/gnss/sp3.h"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/rinex.h"
#include "line_reader.h"

namespace pdnav::gnss {
namespace {

class Sp3Parser {
 public:
  // Empty lines read as one blank: the record dispatch looks at l[0] of every line.
  Sp3Parser(std::istream& in, std::string name)
      : lines_(in, std::move(name), detail::LineReader::EmptyLine::kAsBlank) {}

  Sp3File run() {
    std::string l;
    if (!next(l)) fail("empty file");
    if (l.size() < 3 || l[0] != '#' || (l[1] != 'c' && l[1] != 'd' && l[1] != 'a' && l[1] != 'b'))
      fail("not an SP3 file (first line must start with #c or #d)");
    out_.version = l[1];
    while (next(l)) {
      if (l.rfind("EOF", 0) == 0) break;
      if (l.rfind("%c", 0) == 0 && !time_system_seen_) {
        time_system_seen_ = true;
        const std::string ts = rinex_trim(rinex_field(l, 9, 3));
        if (!ts.empty() && ts != "ccc") out_.time_system = ts;
        offset_check();
      } else if (l[0] == '*') {
        epoch_line(l);
      } else if (l[0] == 'P') {
        position_line(l);
      }  // '+', '++', '%f', '%i', '/*', 'V', 'EP', 'EV': not needed
    }
    return std::move(out_);
  }

 private:
  bool next(std::string& l) { return lines_.next(l); }
  [[noreturn]] void fail(const std::string& reason) const { lines_.fail(reason); }

  void offset_check() const {
    const std::string& ts = out_.time_system;
    if (!product_time_system_supported(ts) || ts == "QZS")
      fail("unsupported SP3 time system '" + ts + "'");
  }

  double number(const std::string& f) const {
    const auto v = parse_rinex_double(f);
    if (!v) fail("non-numeric field '" + rinex_trim(f) + "'");
    return *v;
  }

  TimeNs to_gps_ns(double calendar_s) const { return product_time_to_gps_ns(calendar_s, out_.time_system); }

  int integer(const std::string& f) const {
    const double v = number(f);
    if (!(std::abs(v) < 1e6)) fail("bad epoch");
    return static_cast<int>(v);
  }

  void epoch_line(const std::string& l) {
    const int y = integer(rinex_field(l, 3, 4));
    const int mo = integer(rinex_field(l, 8, 2));
    const int d = integer(rinex_field(l, 11, 2));
    const int h = integer(rinex_field(l, 14, 2));
    const int mi = integer(rinex_field(l, 17, 2));
    const double s = number(rinex_field(l, 20, 11));
    if (y < 1980 || y > 2200 || mo < 1 || mo > 12 || d < 1 || d > 31 || h < 0 || h > 23 || mi < 0 || mi > 59 || s < 0 ||
        s >= 61)
      fail("bad epoch");
    Sp3Epoch e;
    e.gps_ns = to_gps_ns(geo::calendar_to_epoch_seconds(y, mo, d, h, mi, s));
    out_.epochs.push_back(std::move(e));
  }

  void position_line(const std::string& l) {
    if (out_.epochs.empty()) fail("position record before the first epoch");
    SatId sat;
    sat.sys = constellation_from_rinex_letter(l.size() > 1 ? l[1] : '?');
    const auto prn = parse_rinex_double(rinex_field(l, 2, 2));
    const auto x = parse_rinex_double(rinex_field(l, 4, 14));
    const auto y = parse_rinex_double(rinex_field(l, 18, 14));
    const auto z = parse_rinex_double(rinex_field(l, 32, 14));
    const auto c = parse_rinex_double(rinex_field(l, 46, 14));
    if (sat.sys == Constellation::kUnknown || !prn || *prn < 1 || *prn > 99 || !x || !y || !z || l.size() < 46) {
      ++out_.skipped_lines;
      return;
    }
    if (*x == 0.0 && *y == 0.0 && *z == 0.0) {  // SP3: bad or absent position
      ++out_.skipped_lines;
      return;
    }
    sat.prn = static_cast<int>(*prn);
    Sp3Sample s;
    s.pos = geo::Ecef(*x * 1e3, *y * 1e3, *z * 1e3);
    s.has_clock = c && std::abs(*c) < 999999.0 && rinex_trim(rinex_field(l, 46, 14)) != "";
    s.clock_s = s.has_clock ? *c * 1e-6 : 0.0;
    out_.epochs.back().sats[sat] = s;
  }

  detail::LineReader lines_;
  bool time_system_seen_ = false;
  Sp3File out_;
};

}  // namespace

bool product_time_system_supported(const std::string& ts) {
  return ts == "GPS" || ts == "GAL" || ts == "QZS" || ts == "UTC" || ts == "TAI" || ts == "BDT";
}

TimeNs product_time_to_gps_ns(double calendar_s, const std::string& ts) {
  double gps_s = calendar_s;
  if (ts == "UTC") {
    const auto unix_ms = static_cast<std::int64_t>(std::llround(calendar_s * 1e3)) + geo::kGpsEpochUnixMs;
    gps_s += geo::leap_seconds_at_unix_ms(unix_ms);
  } else if (ts == "TAI") {
    gps_s -= 19.0;
  } else if (ts == "BDT") {
    gps_s += 14.0;
  }
  return static_cast<TimeNs>(std::llround(gps_s * 1e9));
}

Sp3File read_sp3(std::istream& in, const std::string& name) { return Sp3Parser(in, name).run(); }

Sp3File read_sp3_file(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ":0: cannot open");
  return read_sp3(f, path);
}

}  // namespace pdnav::gnss
