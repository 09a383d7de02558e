#include "pdnav/gnss/clock_file.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/rinex.h"
#include "pdnav/gnss/sp3.h"
#include "line_reader.h"

namespace pdnav::gnss {
namespace {

bool has_label(const std::string& l, const char* label) { return l.size() >= 60 && l.find(label, 60) != std::string::npos; }

std::vector<std::string> tokens(const std::string& l) {
  std::istringstream s(l);
  std::vector<std::string> out;
  for (std::string t; s >> t;) out.push_back(t);
  return out;
}

class ClockParser {
 public:
  ClockParser(std::istream& in, std::string name) : lines_(in, std::move(name)) {}

  ClockFile run() {
    header();
    std::string l;
    while (next(l)) record(l);
    for (auto& [sat, v] : out_.sats) {
      std::stable_sort(v.begin(), v.end(), [](const ClockSample& a, const ClockSample& b) { return a.gps_ns < b.gps_ns; });
      const auto before = v.size();
      v.erase(std::unique(v.begin(), v.end(), [](const ClockSample& a, const ClockSample& b) { return a.gps_ns == b.gps_ns; }),
              v.end());
      if (v.size() != before) {
        out_.skipped["AS: repeated epoch"] += static_cast<std::int64_t>(before - v.size());
        out_.records -= static_cast<std::int64_t>(before - v.size());
      }
    }
    return std::move(out_);
  }

 private:
  bool next(std::string& l) { return lines_.next(l); }
  [[noreturn]] void fail(const std::string& reason) const { lines_.fail(reason); }

  void header() {
    std::string l;
    if (!next(l)) fail("empty file (not a RINEX clock file)");
    if (!has_label(l, "RINEX VERSION / TYPE")) fail("not a RINEX clock file (first line is not RINEX VERSION / TYPE)");
    const auto v = parse_rinex_double(l.substr(0, 9));
    if (!v || *v < 3.0 || *v >= 4.0) fail("unsupported RINEX clock version '" + l.substr(0, 9) + "' (3.00-3.04 read)");
    const auto t = tokens(l.substr(9, 51));
    if (t.empty() || t[0][0] != 'C') fail("RINEX file type is not C (clock data)");
    out_.version = *v;
    while (next(l)) {
      if (has_label(l, "END OF HEADER")) {
        return;
      }
      if (has_label(l, "TIME SYSTEM ID")) {
        const auto ts = tokens(l.substr(0, 60));
        if (!ts.empty()) out_.time_system = ts[0];
        if (!product_time_system_supported(out_.time_system))
          fail("unsupported TIME SYSTEM ID '" + out_.time_system + "'");
      }
    }
    fail("no END OF HEADER");
  }

  TimeNs to_gps_ns(double calendar_s) const { return product_time_to_gps_ns(calendar_s, out_.time_system); }

  void skip(const std::string& why) { ++out_.skipped[why]; }

  void record(const std::string& l) {
    const auto t = tokens(l);
    if (t.empty()) return;  // blank line (any white space, as the tokenizer sees it)
    const std::string& type = t[0];
    if (type != "AS" && type != "AR" && type != "CR" && type != "DR" && type != "MS") {
      skip("unknown record type");
      return;
    }
    // type name yyyy mm dd hh mi ss n value1 [value2]
    if (t.size() < 10) { skip_record(type, "too few fields", 0); return; }
    int ymdhm[5];
    for (int i = 0; i < 5; ++i) {
      const auto x = parse_rinex_double(t[static_cast<std::size_t>(2 + i)]);
      if (!x || *x != std::floor(*x) || std::fabs(*x) > 1e5) { skip_record(type, "bad epoch", 0); return; }
      ymdhm[i] = static_cast<int>(*x);
    }
    const auto sec = parse_rinex_double(t[7]);
    const auto n_values = parse_rinex_double(t[8]);
    if (!n_values || *n_values < 1 || *n_values > 6 || *n_values != std::floor(*n_values)) {
      skip_record(type, "bad number of data values", 0);
      return;
    }
    const int n = static_cast<int>(*n_values);
    const int continuation = n > 2 ? 1 : 0;  // values 3-6 are on one continuation line
    if (type != "AS") { skip_record(type, "not a satellite clock (" + type + ")", continuation); return; }
    if (!sec || ymdhm[0] < 1980 || ymdhm[0] > 2200 || ymdhm[1] < 1 || ymdhm[1] > 12 || ymdhm[2] < 1 || ymdhm[2] > 31 ||
        ymdhm[3] < 0 || ymdhm[3] > 23 || ymdhm[4] < 0 || ymdhm[4] > 59 || *sec < 0 || *sec >= 61) {
      skip_record(type, "bad epoch", continuation);
      return;
    }
    SatId sat;
    const std::string& nm = t[1];
    sat.sys = nm.size() == 3 ? constellation_from_rinex_letter(nm[0]) : Constellation::kUnknown;
    const auto prn = nm.size() == 3 ? parse_rinex_double(nm.substr(1)) : std::nullopt;
    if (sat.sys == Constellation::kUnknown || !prn || *prn < 1 || *prn > 99 || *prn != std::floor(*prn)) {
      skip_record(type, "bad satellite name '" + nm.substr(0, 8) + "'", continuation);
      return;
    }
    sat.prn = static_cast<int>(*prn);
    const auto clk = parse_rinex_double(t[9]);
    if (!clk || !std::isfinite(*clk) || std::fabs(*clk) > 1.0) {
      skip_record(type, "bad clock value", continuation);
      return;
    }
    ClockSample s;
    s.gps_ns = to_gps_ns(geo::calendar_to_epoch_seconds(ymdhm[0], ymdhm[1], ymdhm[2], ymdhm[3], ymdhm[4], *sec));
    s.clock_s = *clk;
    if (n >= 2 && t.size() >= 11) {
      const auto sig = parse_rinex_double(t[10]);
      if (sig && std::isfinite(*sig) && *sig >= 0) s.sigma_s = *sig;
    }
    out_.sats[sat].push_back(s);
    ++out_.records;
    skip_continuation(continuation);
  }

  void skip_record(const std::string& type, const std::string& why, int continuation) {
    skip(type + ": " + why);
    skip_continuation(continuation);
  }

  void skip_continuation(int n) {
    std::string l;
    for (int i = 0; i < n && next(l); ++i) {}
  }

  detail::LineReader lines_;
  ClockFile out_;
};

}  // namespace

std::int64_t ClockFile::skipped_total() const {
  std::int64_t n = 0;
  for (const auto& kv : skipped) n += kv.second;
  return n;
}

ClockFile read_rinex_clock(std::istream& in, const std::string& name) { return ClockParser(in, name).run(); }

ClockFile read_rinex_clock_file(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ":0: cannot open");
  return read_rinex_clock(f, path);
}

bool interpolate_clock(const std::vector<ClockSample>& v, TimeNs t, const ClockInterpolationOptions& opt,
                       double& clock_s, double& rate_sps, std::string* why_not) {
  auto refuse = [&](const char* why) {
    if (why_not) *why_not = why;
    return false;
  };
  if (v.empty()) return refuse("no precise clock");
  if (t < v.front().gps_ns || t > v.back().gps_ns) return refuse("outside the clock file span");
  auto hi = std::upper_bound(v.begin(), v.end(), t, [](TimeNs x, const ClockSample& s) { return x < s.gps_ns; });
  if (hi == v.end()) --hi;  // t == last sample
  if (hi == v.begin()) ++hi;
  if (hi == v.end()) {  // a single sample, exactly at t
    clock_s = v.front().clock_s;
    rate_sps = 0.0;
    return v.front().gps_ns == t ? true : refuse("gap in the precise clock");
  }
  const auto lo = hi - 1;
  const double step_s = static_cast<double>(hi->gps_ns - lo->gps_ns) * 1e-9;
  if (!(step_s > 0.0) || step_s > opt.max_interval_s) return refuse("gap in the precise clock");
  const double f = static_cast<double>(t - lo->gps_ns) * 1e-9 / step_s;
  rate_sps = (hi->clock_s - lo->clock_s) / step_s;
  clock_s = lo->clock_s + f * (hi->clock_s - lo->clock_s);
  if (why_not) why_not->clear();
  return true;
}

}  // namespace pdnav::gnss
