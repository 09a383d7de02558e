// phyphox (RWTH Aachen) CSV export: a zip (or its unpacked folder) of one table per export
// set ("Accelerometer.csv", "Raw Data.csv", ...), quoted header names with the unit in
// parentheses ("Time (s)", "Acceleration x (m/s^2)"), values as "0.000000000E0", "NaN" where a
// column is shorter; separator ',' ';' or tab with '.' or ',' as decimal mark (the export
// dialog's choices), plus meta/device.csv ("property","value") and meta/time.csv ("event",
// "experiment time","system time","system time text": START/PAUSE rows mapping the
// experiment clock to Unix seconds). Format from phyphox-android DataExport.java and
// SimpleExperimentCreator.java; docs/log-format.md "Other loggers".
#include <cmath>
#include <memory>

#include "io/readers.h"
#include "io/skip_reasons.h"
#include "io/table_source.h"
#include "io/text.h"

namespace pdnav::io::detail {

namespace {

constexpr const char* kNaNRow = "NaN (a shorter column's padding)";

/// A number in the export's notation: decimal comma when the separator is not ','.
bool number(std::string_view s, char sep, double& out) {
  if (sep == ',') return parse_f64(s, out);
  std::string t(trim(s));
  for (char& c : t)
    if (c == ',') c = '.';
  return parse_f64(t, out);
}

/// "Acceleration x (m/s^2)" -> name "acceleration x", unit "m/s^2".
struct Column {
  std::string name, unit;
};
Column split_column(const std::string& header) {
  Column c;
  const auto open = header.rfind('(');
  const auto close = header.rfind(')');
  if (open != std::string::npos && close != std::string::npos && close > open) {
    c.unit = std::string(trim(std::string_view(header).substr(open + 1, close - open - 1)));
    c.name = lower_ascii(trim(std::string_view(header).substr(0, open)));
  } else {
    c.name = lower_ascii(trim(header));
  }
  return c;
}

/// The experiment clock -> Unix time, piecewise from meta/time.csv (each START/PAUSE row
/// pins one experiment time to one system time; a sample takes the latest row at or before it).
struct TimeMap {
  std::vector<std::pair<double, std::int64_t>> rows;  // (experiment s, system Unix ns)
  bool known() const { return !rows.empty(); }
  /// Unix ns of experiment time t_s; false when not representable.
  bool unix_ns(double t_s, std::int64_t& out) const {
    const std::pair<double, std::int64_t>* r = &rows.front();
    for (const auto& p : rows)
      if (p.first <= t_s) r = &p;
    const double d_ns = (t_s - r->first) * 1e9;  // small: exact to well below a nanosecond
    if (!(std::fabs(d_ns) < 1e17)) return false;
    out = r->second + static_cast<std::int64_t>(std::llround(d_ns));
    return out > 0;
  }
};

/// "1710000032.250" (Unix seconds, phyphox writes 3 decimals) as exact integer nanoseconds.
bool unix_text_ns(std::string_view s, char sep, std::int64_t& out) {
  s = trim(s);
  const char dec = sep == ',' ? '.' : ',';
  std::size_t p = s.find(dec);
  if (p == std::string_view::npos) p = s.find('.');
  std::int64_t whole = 0, frac = 0;
  if (!parse_i64(s.substr(0, p), whole) || whole <= 0 || whole > 4000000000LL) return false;
  if (p != std::string_view::npos) {
    std::string f(s.substr(p + 1));
    if (f.size() > 9) f.resize(9);
    for (char c : f)
      if (c < '0' || c > '9') return false;
    f.append(9 - f.size(), '0');
    if (!parse_i64(f, frac)) return false;
  }
  out = whole * 1000000000LL + frac;
  return true;
}

/// What one table holds, found from its column names.
enum class Kind { kNone, kAccel, kGyro, kMag, kPressure, kLocation };

struct Layout {
  Kind kind = Kind::kNone;
  int t = -1;
  int v[3] = {-1, -1, -1};
  double scale = 1.0;  // to the sample's unit
  // location
  int lat = -1, lon = -1, alt = -1, speed = -1, dir = -1, hacc = -1, vacc = -1;
  std::string what;  // for "not used"
};

[[noreturn]] void bad_unit(const TableFile& f, const std::string& col, const std::string& unit, const char* expected) {
  throw IoError(f.where(), 1, "unit '" + printable(unit, 20) + "' of column '" + printable(col, 40) +
                                  "' not understood (expected " + expected + ")");
}

double unit_scale(const TableFile& f, const std::string& col, const std::string& unit, Kind k) {
  const std::string u = lower_ascii(unit);
  switch (k) {
    case Kind::kAccel:
      if (u == "m/s^2" || u == "m/s\xc2\xb2" || u == "m/s2") return 1.0;
      if (u == "g") return 9.80665;  // standard gravity
      bad_unit(f, col, unit, "m/s^2");
    case Kind::kGyro:
      if (u == "rad/s") return 1.0;
      if (u == "\xc2\xb0/s" || u == "deg/s") return kPi / 180.0;
      bad_unit(f, col, unit, "rad/s");
    case Kind::kMag:
      if (u == "\xc2\xb5t" || u == "\xce\xbct" || u == "ut" || u == "microtesla") return 1.0;
      if (u == "nt") return 1e-3;
      bad_unit(f, col, unit, "\xc2\xb5T");
    case Kind::kPressure:
      if (u == "hpa" || u == "mbar") return 100.0;
      if (u == "pa") return 1.0;
      if (u == "kpa") return 1000.0;
      bad_unit(f, col, unit, "hPa");
    default:
      return 1.0;
  }
}

Layout layout_of(const TableFile& f) {
  Layout l;
  std::vector<Column> cols;
  for (const std::string& h : f.header()) cols.push_back(split_column(h));
  auto find = [&](std::initializer_list<const char*> names) {
    for (const char* n : names)
      for (std::size_t i = 0; i < cols.size(); ++i)
        if (cols[i].name == n) return static_cast<int>(i);
    return -1;
  };
  l.t = find({"time"});
  if (l.t >= 0 && lower_ascii(cols[static_cast<std::size_t>(l.t)].unit) != "s")
    bad_unit(f, f.header()[static_cast<std::size_t>(l.t)], cols[static_cast<std::size_t>(l.t)].unit, "s");
  struct Family {
    Kind kind;
    const char* prefix;
  };
  // phyphox's names: "Acceleration x", "Gyroscope x", "Magnetic field x", "Pressure",
  // "Latitude"; "Linear Acceleration x" (without g) is a different sensor and not used
  for (const Family& fam : {Family{Kind::kAccel, "acceleration "}, Family{Kind::kGyro, "gyroscope "},
                            Family{Kind::kMag, "magnetic field "}}) {
    const int x = find({(std::string(fam.prefix) + "x").c_str()});
    const int y = find({(std::string(fam.prefix) + "y").c_str()});
    const int z = find({(std::string(fam.prefix) + "z").c_str()});
    if (x >= 0 && y >= 0 && z >= 0) {
      l.kind = fam.kind;
      l.v[0] = x;
      l.v[1] = y;
      l.v[2] = z;
      const double sx = unit_scale(f, f.header()[static_cast<std::size_t>(x)], cols[static_cast<std::size_t>(x)].unit, fam.kind);
      for (int a : {y, z})
        if (unit_scale(f, f.header()[static_cast<std::size_t>(a)], cols[static_cast<std::size_t>(a)].unit, fam.kind) != sx)
          throw IoError(f.where(), 1, "axes of one sensor in different units");
      l.scale = sx;
      return l;
    }
  }
  if (const int p = find({"pressure"}); p >= 0) {
    l.kind = Kind::kPressure;
    l.v[0] = p;
    l.scale = unit_scale(f, f.header()[static_cast<std::size_t>(p)], cols[static_cast<std::size_t>(p)].unit, Kind::kPressure);
    return l;
  }
  l.lat = find({"latitude"});
  l.lon = find({"longitude"});
  if (l.lat >= 0 && l.lon >= 0) {
    l.kind = Kind::kLocation;
    l.alt = find({"height", "altitude"});
    l.speed = find({"velocity", "speed"});
    l.dir = find({"direction", "bearing"});
    l.hacc = find({"horizontal accuracy"});
    l.vacc = find({"vertical accuracy"});
    return l;
  }
  for (const Column& c : cols)
    if (c.name != "time") { l.what = c.name; break; }
  return l;
}

/// Next row of a meta/ table, passing over rows that next_row rejects (torn, over-long): they
/// carry no metadata and are not counted. False at the end of the file.
bool next_meta_row(TableFile& f) {
  for (;;) {
    try {
      return f.next_row();
    } catch (const RowSkip&) {
    }
  }
}

class PhyphoxBuilder {
 public:
  PhyphoxBuilder(std::unique_ptr<Container> c, SourceOptions opt) : c_(std::move(c)), opt_(opt) {}

  std::unique_ptr<SampleSource> build() {
    const std::string name = c_->entries().size() == 1 ? c_->where(c_->entries().front()) : c_->name();
    src_ = std::make_unique<MergedSource>(name, Format::kPhyphox, opt_, c_->total_bytes());
    read_meta();
    ReadStats& st = src_->mutable_stats();
    if (c_->entries().size() == 1)
      src_->set_hint("one table of a phyphox export: pass the export's folder or zip (with meta/) to read all of it");
    for (const Entry& e : c_->entries()) {
      const std::string p = lower_ascii(e.path);
      const std::string b = lower_ascii(e.base);
      if (p.find("meta/") != std::string::npos) continue;
      if (b.size() < 4 || b.substr(b.size() - 4) != ".csv") {
        st.not_used[c_->where(e)] = "not a CSV table";
        continue;
      }
      if (e.size == 0) {
        st.not_used[c_->where(e)] = "empty";
        continue;
      }
      table(e);
    }
    return std::move(src_);
  }

 private:
  void read_meta() {
    auto& info = src_->info();
    ReadStats& st = src_->mutable_stats();
    if (const Entry* e = c_->find_path("meta/device.csv")) {
      TableFile f(*c_, *e, 0);
      const int k = f.column("property"), v = f.column("value");
      if (k < 0 || v < 0) throw IoError(f.where(), 1, "meta/device.csv without \"property\",\"value\" header");
      std::string model, brand, manufacturer;
      while (next_meta_row(f)) {
        const std::string key = printable(f.field(k), 64), val = printable(f.field(v), 256);
        if (key.find(' ') != std::string::npos) continue;  // per-sensor rows ("accelerometer Resolution")
        if (info.size() < 64) info[key] = val;
        if (key == "deviceModel") model = val;
        if (key == "deviceManufacturer") manufacturer = val;
        if (key == "deviceBrand") brand = val;
        if (key == "version") src_->add_prefix(MetaSample{0, "AppVersion", "phyphox " + val});
      }
      if (manufacturer.empty()) manufacturer = brand;
      if (!model.empty()) src_->add_prefix(MetaSample{0, "Device", manufacturer.empty() ? model : manufacturer + " " + model});
      st.not_used[f.where()] = "metadata: read into Meta rows";
    }
    if (const Entry* e = c_->find_path("meta/time.csv")) {
      TableFile f(*c_, *e, 0);
      const int ev = f.column("event"), et = f.column("experiment time"), sy = f.column("system time");
      if (ev < 0 || et < 0 || sy < 0)
        throw IoError(f.where(), 1, "meta/time.csv without \"event\",\"experiment time\",\"system time\" header");
      while (next_meta_row(f)) {
        double x = 0;
        std::int64_t sys_ns = 0;
        if (!number(f.field(et), f.sep(), x) || !std::isfinite(x) || !unix_text_ns(f.field(sy), f.sep(), sys_ns))
          throw IoError(f.where(), f.line_no(), "time mapping row '" + printable(f.field(ev)) + "' has no usable times");
        if (!time_.rows.empty() && x < time_.rows.back().first)
          throw IoError(f.where(), f.line_no(), "experiment time goes backwards in the time mapping");
        time_.rows.emplace_back(x, sys_ns);
        if (time_.rows.size() == 1) info["StartSystemTime"] = printable(f.field(f.column("system time text")), 64);
      }
      st.not_used[f.where()] = "time mapping: experiment time -> Unix time";
    }
    if (!time_.known())
      info["Time"] = "experiment time since the start (no meta/time.csv: UTC unknown)";
    src_->add_prefix(MetaSample{0, "SourceFormat", "phyphox"});
  }

  void table(const Entry& e) {
    auto f = std::make_unique<TableFile>(*c_, e, 0);
    if (f->empty_file()) return;
    const Layout l = layout_of(*f);
    ReadStats& st = src_->mutable_stats();
    if (l.kind == Kind::kNone) {
      st.not_used[f->where()] = l.what.empty() ? "no sensor columns" : "'" + printable(l.what, 40) + "': nothing the core uses";
      return;
    }
    if (l.t < 0) throw IoError(f->where(), 1, "no \"Time (s)\" column");
    const TimeMap tm = time_;
    src_->add(std::move(f), [l, tm](const TableFile& t, Sample& out) {
      if (t.n_fields() != t.header().size())
        throw RowSkip{kWrongFieldCount, std::to_string(t.n_fields()) + " fields, header has " + std::to_string(t.header().size())};
      auto get = [&](int col) {
        double v = 0.0;
        if (col < 0) return kNaN;
        const std::string_view s = t.field(col);
        if (trim(s).empty()) return kNaN;
        if (!number(s, t.sep(), v)) throw RowSkip{kNonNumeric, t.header()[static_cast<std::size_t>(col)] + " '" + printable(s) + "'"};
        return v;
      };
      const double ts = get(l.t);
      if (std::isnan(ts)) throw RowSkip{kNaNRow, ""};
      if (!std::isfinite(ts) || ts < -1e6 || ts > 1e9) throw RowSkip{kInvalidTime, "time " + printable(t.field(l.t)) + " s"};
      TimeNs t_ns = 0;
      std::int64_t utc_ms = kMissingInt;
      if (tm.known()) {
        if (!tm.unix_ns(ts, t_ns)) throw RowSkip{kInvalidTime, "time " + printable(t.field(l.t)) + " s not mappable to UTC"};
        utc_ms = t_ns / 1000000;
      } else {
        t_ns = static_cast<TimeNs>(std::llround(ts * 1e9));
      }
      auto vec = [&] {
        Eigen::Vector3d v(get(l.v[0]), get(l.v[1]), get(l.v[2]));
        if (!v.allFinite()) throw RowSkip{kNaNRow, ""};
        return Eigen::Vector3d(l.scale * v);
      };
      switch (l.kind) {
        case Kind::kAccel: out = AccelSample{t_ns, utc_ms, vec()}; return true;
        case Kind::kGyro: out = GyroSample{t_ns, utc_ms, vec()}; return true;
        case Kind::kMag: out = MagSample{t_ns, utc_ms, vec()}; return true;
        case Kind::kPressure: {
          const double p = get(l.v[0]) * l.scale;
          if (std::isnan(p)) throw RowSkip{kNaNRow, ""};
          if (!(p >= 30000.0 && p <= 110000.0)) throw RowSkip{kOutOfRange, "pressure " + printable(t.field(l.v[0])) + " outside 300..1100 hPa"};
          PressureSample s;
          s.t_ns = t_ns;
          s.utc_ms = utc_ms;
          s.pressure_pa = p;
          out = s;
          return true;
        }
        case Kind::kLocation: {
          FixSample s;
          s.t_ns = t_ns;
          s.utc_ms = utc_ms;
          s.provider = "GPS";  // phyphox's location input is the GPS provider (Android) / Core Location (iOS)
          s.lat_deg = get(l.lat);
          s.lon_deg = get(l.lon);
          if (std::isnan(s.lat_deg) || std::isnan(s.lon_deg)) throw RowSkip{kNaNRow, ""};
          if (std::fabs(s.lat_deg) > 90.0 || std::fabs(s.lon_deg) > 180.0)
            throw RowSkip{kOutOfRange, "latitude/longitude " + printable(t.field(l.lat)) + "," + printable(t.field(l.lon))};
          s.alt_m = get(l.alt);
          s.speed_mps = get(l.speed);
          s.bearing_deg = get(l.dir);
          s.accuracy_m = get(l.hacc);
          s.vertical_accuracy_m = get(l.vacc);
          for (double* v : {&s.speed_mps, &s.bearing_deg, &s.accuracy_m, &s.vertical_accuracy_m})
            if (*v < 0.0) *v = kNaN;
          out = s;
          return true;
        }
        case Kind::kNone:
          break;
      }
      return false;
    });
  }

  std::unique_ptr<Container> c_;
  SourceOptions opt_;
  std::unique_ptr<MergedSource> src_;
  TimeMap time_;
};

}  // namespace

bool is_phyphox_header(const std::string& line) {
  std::vector<std::string> f;
  for (char sep : {',', ';', '\t'}) {
    split_fields(line, sep, f);
    if (f.size() >= 2 && lower_ascii(trim(f[0])) == "time (s)") return true;
  }
  return false;
}

std::unique_ptr<SampleSource> open_phyphox(std::unique_ptr<Container> c, SourceOptions opt) {
  return PhyphoxBuilder(std::move(c), opt).build();
}

}  // namespace pdnav::io::detail
