// GetSensorData (LOPSI, CAR-CSIC; the IPIN competition's logger) text log: '%' comment header
// (device, and a "LogFile Data format" line per type, e.g. 'ACCE;AppTimestamp(s);
// SensorTimestamp(s);Acc_X(m/s^2);...'), then one ';'-separated line per reading. Columns are
// mapped by the names of those format lines when the header has them, else by the IPIN
// logfile description's default layout. docs/log-format.md "Other loggers" has the mapping.
//
// Time: AppTimestamp (s since the recording started, one clock for every type) is the common
// base. Sensor lines also carry SensorTimestamp (the sensor event's own clock: precise
// intervals, but a base of its own); each sensor type is put on the app clock by the offset
// AppTimestamp - SensorTimestamp of its first line, so its samples keep the sensor's spacing.
#include <algorithm>
#include <array>
#include <deque>
#include <optional>
#include <cmath>
#include <map>

#include "io/line_source.h"
#include "io/readers.h"
#include "io/skip_reasons.h"
#include "io/table_source.h"
#include "io/text.h"
#include "pdnav/io/log_format.h"

namespace pdnav::io::detail {

namespace {

constexpr const char* kNonFinite = "non-finite value";
constexpr const char* kTooFewFields = "too few fields";
constexpr std::size_t kMaxDistinct = 64;

/// A column name without its unit and spaces, lower case: "Acc_X(m/s^2)" -> "acc_x".
std::string key_of(std::string_view s) {
  s = trim(s);
  const auto p = s.find('(');
  if (p != std::string_view::npos) s = s.substr(0, p);
  std::string out;
  for (char c : s)
    if (c != ' ' && c != '\'') out.push_back(c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c);
  return out;
}

/// The IPIN logfile description's layouts (the fallback when the header does not list them).
const std::map<std::string, std::vector<std::string>>& default_layouts() {
  static const std::map<std::string, std::vector<std::string>> k{
      {"ACCE", {"apptimestamp", "sensortimestamp", "acc_x", "acc_y", "acc_z", "accuracy"}},
      {"GYRO", {"apptimestamp", "sensortimestamp", "gyr_x", "gyr_y", "gyr_z", "accuracy"}},
      {"MAGN", {"apptimestamp", "sensortimestamp", "mag_x", "mag_y", "mag_z", "accuracy"}},
      {"PRES", {"apptimestamp", "sensortimestamp", "pres", "accuracy"}},
      {"AHRS", {"apptimestamp", "sensortimestamp", "pitchx", "rolly", "yawz", "quat(2)", "quat(3)", "quat(4)", "accuracy"}},
      {"GNSS", {"apptimestamp", "sensortimestamp", "latit", "long", "altitude", "bearing", "accuracy", "speed", "satinview", "satinuse"}},
      {"POSI", {"timestamp", "counter", "latitude", "longitude", "floorid", "buildingid"}},
  };
  return k;
}

struct Layout {
  std::map<std::string, int> col;  // key -> field index after the type token (0-based)
  int operator[](const std::string& k) const {
    auto it = col.find(k);
    return it == col.end() ? -1 : it->second;
  }
};

Layout make_layout(const std::vector<std::string>& keys) {
  Layout l;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    std::string k = keys[i];
    // "Quat(2)" keeps its index (the key would be "quat" three times)
    if (k.rfind("quat(", 0) != 0) k = key_of(k);
    if (!k.empty() && !l.col.count(k)) l.col[k] = static_cast<int>(i);
  }
  return l;
}

class GsdSource : public SampleSource {
 public:
  GsdSource(std::unique_ptr<std::istream> in, std::string name, std::uint64_t size, SourceOptions opt)
      : in_(std::move(in)), src_(*in_), name_(std::move(name)), size_(size), opt_(opt) {
    for (const auto& [t, keys] : default_layouts()) layouts_[t] = make_layout(keys);
  }

  bool next(Sample& out) override {
    if (pop(out)) return true;
    Line line;
    while (src_.next(line)) {
      ++line_no_;
      ++stats_.lines;
      const std::string_view text = trim(line.text);
      try {
        if (line.too_long) throw RowSkip{kTooLong, ""};
        if (text.empty()) continue;
        if (!line.terminated && text.front() != '%') {
          // the logger writes "\nTYPE;..." so the last line has no newline: it is whole
          // when it has all of its type's fields; otherwise it was cut
          torn_ = true;
        }
        if (text.front() == '%') { header(text); continue; }
        data(text);
        if (pop(out)) return true;
      } catch (const RowSkip& s) {
        skip(s);
      }
    }
    if (src_.read_error()) throw IoError(name_, line_no_, "read error");
    if (!finished_) {
      finished_ = true;
      if (opt_.require_samples && stats_.samples == 0)
        throw IoError(name_, 0, "no samples: " + std::to_string(stats_.lines) + " lines, " +
                                    std::to_string(stats_.skipped_total()) + " skipped");
    }
    return false;
  }
  const ReadStats& stats() const override {
    stats_.samples_by_type = by_type_;
    return stats_;
  }
  double progress() const override {
    return size_ == 0 ? 0.0 : std::min(1.0, static_cast<double>(src_.bytes_consumed()) / static_cast<double>(size_));
  }
  const std::string& name() const override { return name_; }
  const std::map<std::string, std::string>& header_info() const override { return info_; }
  Format format() const override { return Format::kGetSensorData; }

 private:
  bool pop(Sample& out) {
    if (queue_.empty()) return false;
    out = std::move(queue_.front());
    queue_.pop_front();
    ++stats_.samples;
    ++by_type_[std::string(line_type_name(out))];
    return true;
  }
  void skip(const RowSkip& s) {
    if (s.malformed && opt_.log.strict) throw IoError(name_, line_no_, s.category + (s.detail.empty() ? "" : ": " + s.detail));
    ++stats_.skipped_by_reason[s.category];
    if (stats_.issues.size() < opt_.log.max_reported_issues)
      stats_.issues.push_back(LogIssue{name_, line_no_, s.category + (s.detail.empty() ? "" : ": " + s.detail)});
  }

  /// '%' lines: "% Model: \tPixel 3" style info, and "'TYPE;col;col...'" format descriptions.
  void header(std::string_view text) {
    text = trim(text.substr(1));
    const auto q1 = text.find('\'');
    const auto q2 = text.rfind('\'');
    if (q1 != std::string_view::npos && q2 != std::string_view::npos && q2 > q1 + 5) {
      const std::string_view fmt = text.substr(q1 + 1, q2 - q1 - 1);
      const auto semi = fmt.find(';');
      if (semi == 4) {
        const std::string type(fmt.substr(0, 4));
        std::vector<std::string> keys;
        std::string_view rest = fmt.substr(5);
        for (;;) {
          const auto s = rest.find(';');
          const std::string_view k = rest.substr(0, s);
          if (!trim(k).empty()) keys.emplace_back(lower_ascii(trim(k)));  // "Mag_X(uT);;Mag_Y" has an empty name
          if (s == std::string_view::npos) break;
          rest = rest.substr(s + 1);
        }
        if (layouts_.size() < kMaxDistinct || layouts_.count(type)) layouts_[type] = make_layout(keys);
      }
      return;
    }
    const auto colon = text.find(':');
    if (colon != std::string_view::npos && colon > 0 && colon < 40) {
      const std::string key = printable(trim(text.substr(0, colon)), 40);
      const std::string value = printable(trim(text.substr(colon + 1)), 200);
      if (!value.empty() && (info_.size() < kMaxDistinct || info_.count(key))) info_[key] = value;
      if (key == "Model") model_ = value;
      if (key == "Manufacturer") manufacturer_ = value;
    }
  }

  double num(const std::vector<std::string_view>& f, int i, const char* what, bool required = true) {
    if (i < 0 || static_cast<std::size_t>(i + 1) >= f.size()) {
      if (required) throw RowSkip{kTooFewFields, std::string("no ") + what + " field (" + std::to_string(f.size()) + " fields)"};
      return kNaN;
    }
    const std::string_view s = trim(f[static_cast<std::size_t>(i + 1)]);
    if (s.empty() && !required) return kNaN;
    double v = 0.0;
    if (!parse_f64(s, v)) throw RowSkip{kNonNumeric, std::string(what) + " '" + printable(s) + "'"};
    if (!std::isfinite(v)) {
      if (required) throw RowSkip{kNonFinite, std::string(what) + " '" + printable(s) + "'"};
      return kNaN;
    }
    return v;
  }

  static TimeNs to_ns(double s) {
    if (!(std::fabs(s) < 4.0e9)) throw RowSkip{kInvalidTime, "timestamp out of range"};
    return static_cast<TimeNs>(std::llround(s * 1e9));
  }

  /// App time of a line; for sensor types, the sensor time on the app clock.
  TimeNs line_time(const std::string& type, const Layout& l, const std::vector<std::string_view>& f, bool sensor_clock) {
    int app_col = l["apptimestamp"];
    if (app_col < 0) app_col = l["timestamp"];
    const double app = num(f, app_col, "AppTimestamp");
    if (!sensor_clock || l["sensortimestamp"] < 0) return to_ns(app);
    const double sensor = num(f, l["sensortimestamp"], "SensorTimestamp", false);
    if (std::isnan(sensor)) return to_ns(app);
    auto it = offset_ns_.find(type);
    if (it == offset_ns_.end()) it = offset_ns_.emplace(type, to_ns(app) - to_ns(sensor)).first;
    return to_ns(sensor) + it->second;
  }

  void check_order(const std::string& type, TimeNs t) {
    auto it = last_t_.find(type);
    if (it != last_t_.end() && t < it->second && opt_.log.drop_backwards_time)
      throw RowSkip{kBackwards, type + " t=" + std::to_string(t) + " ns < previous " + std::to_string(it->second) + " ns"};
    if (it == last_t_.end()) last_t_.emplace(type, t);
    else it->second = t;
  }

  /// Meta rows (format, device) before the first sample, at its time.
  void emit_meta_once(TimeNs t) {
    if (meta_done_) return;
    meta_done_ = true;
    queue_.push_back(MetaSample{t, "SourceFormat", "getsensordata"});
    if (!model_.empty()) queue_.push_back(MetaSample{t, "Device", manufacturer_.empty() ? model_ : manufacturer_ + " " + model_});
  }

  /// Parses one data line into queue_ (nothing on a skip, which throws RowSkip).
  void data(std::string_view text) {
    fields_.clear();
    std::size_t start = 0;
    for (;;) {
      const auto s = text.find(';', start);
      fields_.push_back(text.substr(start, s == std::string_view::npos ? std::string_view::npos : s - start));
      if (s == std::string_view::npos) break;
      start = s + 1;
    }
    const std::string type(trim(fields_[0]));
    auto lit = layouts_.find(type);
    if (lit == layouts_.end() || !is_read(type)) {
      if (torn_) throw RowSkip{kTorn, "no newline at end of file"};
      std::string reason = "line type '" + printable(type, 8) + "' not used";
      if (!stats_.skipped_by_reason.count(reason) && unknown_++ >= kMaxDistinct) reason = "line type not used (more names)";
      throw RowSkip{reason, "", false};
    }
    const Layout& l = lit->second;
    const std::size_t need = static_cast<std::size_t>(l.col.empty() ? 0 : std::max_element(l.col.begin(), l.col.end(), [](auto& a, auto& b) { return a.second < b.second; })->second) + 1;
    if (torn_ && fields_.size() < need + 1) throw RowSkip{kTorn, "no newline at end of file and " + std::to_string(fields_.size()) + " fields"};
    Sample s;
    std::optional<OrientationSample> angles;
    if (type == "ACCE" || type == "GYRO" || type == "MAGN") {
      const char* names[3][3] = {{"acc_x", "acc_y", "acc_z"}, {"gyr_x", "gyr_y", "gyr_z"}, {"mag_x", "mag_y", "mag_z"}};
      const int k = type == "ACCE" ? 0 : type == "GYRO" ? 1 : 2;
      const Eigen::Vector3d v(num(fields_, l[names[k][0]], names[k][0]), num(fields_, l[names[k][1]], names[k][1]),
                              num(fields_, l[names[k][2]], names[k][2]));
      const TimeNs t = line_time(type, l, fields_, true);
      if (k == 0) s = AccelSample{t, kMissingInt, v};
      else if (k == 1) s = GyroSample{t, kMissingInt, v};
      else s = MagSample{t, kMissingInt, v};
    } else if (type == "PRES") {
      PressureSample p;
      p.t_ns = line_time(type, l, fields_, true);
      const int c = l["pres"];
      if (c < 0 || static_cast<std::size_t>(c + 1) >= fields_.size()) throw RowSkip{kTooFewFields, "no Pres field"};
      double pa = 0.0;
      const std::string_view txt = trim(fields_[static_cast<std::size_t>(c + 1)]);
      if (!parse_f64_pow10(txt, 2, pa)) throw RowSkip{kNonNumeric, "Pres '" + printable(txt) + "'"};
      if (!std::isfinite(pa)) throw RowSkip{kNonFinite, "Pres '" + printable(txt) + "'"};
      if (pa < 30000.0 || pa > 110000.0) throw RowSkip{kOutOfRange, "Pres " + printable(txt) + " mbar outside 300..1100 (wrong unit?)"};
      p.pressure_pa = pa;
      s = p;
    } else if (type == "AHRS") {
      // Quat(2..4) are Android's rotation vector x,y,z (TYPE_ROTATION_VECTOR values[0..2],
      // phone -> east-north-up); w = sqrt(1 - x^2 - y^2 - z^2)
      const double x = num(fields_, l["quat(2)"], "Quat(2)"), y = num(fields_, l["quat(3)"], "Quat(3)"),
                   z = num(fields_, l["quat(4)"], "Quat(4)");
      const double n2 = x * x + y * y + z * z;
      if (n2 > 1.0 + 1e-3) throw RowSkip{kOutOfRange, "rotation vector norm " + std::to_string(std::sqrt(n2)) + " > 1"};
      RotationVectorSample r;
      r.t_ns = line_time(type, l, fields_, true);
      r.quat_xyzw = Eigen::Vector4d(x, y, z, std::sqrt(std::max(0.0, 1.0 - n2)));
      r.quat_xyzw.normalize();
      // and the angles as GnssLogger's OrientationDeg (degrees, Android getOrientation)
      OrientationSample o;
      o.t_ns = r.t_ns;
      o.pitch_deg = num(fields_, l["pitchx"], "PitchX", false);
      o.roll_deg = num(fields_, l["rolly"], "RollY", false);
      o.yaw_deg = num(fields_, l["yawz"], "YawZ", false);
      s = r;
      if (std::isfinite(o.yaw_deg)) angles = o;
    } else if (type == "GNSS") {
      FixSample f;
      f.t_ns = line_time(type, l, fields_, false);
      f.provider = "GPS";
      f.lat_deg = num(fields_, l["latit"] >= 0 ? l["latit"] : l["latitude"], "Latit");
      f.lon_deg = num(fields_, l["long"] >= 0 ? l["long"] : l["longitude"], "Long");
      if (std::fabs(f.lat_deg) > 90.0 || std::fabs(f.lon_deg) > 180.0) throw RowSkip{kOutOfRange, "latitude/longitude"};
      f.alt_m = num(fields_, l["altitude"], "Altitude", false);
      f.bearing_deg = num(fields_, l["bearing"], "Bearing", false);
      f.accuracy_m = num(fields_, l["accuracy"], "Accuracy", false);
      f.speed_mps = num(fields_, l["speed"], "Speed", false);
      for (double* v : {&f.bearing_deg, &f.accuracy_m, &f.speed_mps})
        if (*v < 0.0) *v = kNaN;
      const double utc = num(fields_, l["utctime"], "UTCTime", false);  // later versions: fix time, Unix ms
      if (std::isfinite(utc) && utc > 0 && utc < 4.0e15) f.utc_ms = static_cast<std::int64_t>(std::llround(utc));
      s = f;
    } else if (type == "POSI") {
      TruthSample tr;
      tr.t_ns = line_time(type, l, fields_, false);
      tr.lat_deg = num(fields_, l["latitude"], "Latitude");
      tr.lon_deg = num(fields_, l["longitude"], "Longitude");
      if (std::fabs(tr.lat_deg) > 90.0 || std::fabs(tr.lon_deg) > 180.0) throw RowSkip{kOutOfRange, "latitude/longitude"};
      s = tr;  // floor and building IDs: no field in Truth (height unknown: NaN)
    }
    check_order(type, sample_time_ns(s));
    emit_meta_once(sample_time_ns(s));
    queue_.push_back(std::move(s));
    if (angles) queue_.push_back(*angles);
  }

  bool is_read(const std::string& t) const {
    return t == "ACCE" || t == "GYRO" || t == "MAGN" || t == "PRES" || t == "AHRS" || t == "GNSS" || t == "POSI";
  }

  std::unique_ptr<std::istream> in_;
  LineSource src_;
  std::string name_;
  std::uint64_t size_;
  SourceOptions opt_;
  std::int64_t line_no_ = 0;
  bool torn_ = false, finished_ = false, meta_done_ = false;
  std::size_t unknown_ = 0;
  std::map<std::string, Layout> layouts_;
  std::map<std::string, TimeNs> offset_ns_, last_t_;
  std::vector<std::string_view> fields_;
  std::deque<Sample> queue_;  // samples of the current line (Meta rows before the first)
  std::string model_, manufacturer_;
  std::map<std::string, std::string> info_;
  mutable ReadStats stats_;
  std::map<std::string, std::int64_t> by_type_;
};

}  // namespace

std::unique_ptr<SampleSource> open_getsensordata(std::unique_ptr<std::istream> in, std::string name, std::uint64_t size,
                                                 SourceOptions opt) {
  if (!in) throw IoError(name, 0, "null stream");
  return std::make_unique<GsdSource>(std::move(in), std::move(name), size, opt);
}

}  // namespace pdnav::io::detail
