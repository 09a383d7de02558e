// Sensor Logger (Kelvin Choi; Android and iOS) export: a folder or zip of one CSV per sensor,
// header `time,seconds_elapsed,...`, `time` = Unix ns of the measurement (one clock for every
// file). Columns are mapped by name (Android writes z,y,x). Conventions from the app's
// documentation (github.com/tszheichoi/awesome-sensor-logger UNITS.md, COORDINATES.md,
// CROSSPLATFORM.md); docs/log-format.md "Other loggers" has the mapping table.
#include <cmath>
#include <set>

#include "io/readers.h"
#include "io/table_source.h"
#include "io/text.h"

namespace pdnav::io::detail {

namespace {

constexpr double kStandardGravity = 9.80665;  // Sensor Logger UNITS.md: g = 9.80665 m/s^2
constexpr std::int64_t kNsPerMsI = 1000000;

constexpr const char* kInvalidTime = "invalid time";
constexpr const char* kNonNumeric = "non-numeric value";
constexpr const char* kNonFinite = "non-finite value";
constexpr const char* kFieldCount = "wrong field count";
constexpr const char* kOutOfRange = "value out of range";

/// iOS exports (unless "Standardise Units & Frames" is on) negate every acceleration axis
/// (iOS reports inertial force, Android accelerating force) and give uncalibrated
/// acceleration in g; pdnav keeps Android's convention (CROSSPLATFORM.md).
struct Conventions {
  bool ios = false;
};

void check_fields(const TableFile& f) {
  if (f.n_fields() != f.header().size())
    throw RowSkip{kFieldCount, std::to_string(f.n_fields()) + " fields, header has " + std::to_string(f.header().size())};
}

TimeNs row_time(const TableFile& f, int col) {
  std::int64_t t = 0;
  const std::string_view s = f.field(col);
  if (!parse_i64(s, t)) throw RowSkip{kInvalidTime, "time '" + printable(s) + "' is not an integer (Unix ns)"};
  if (t <= 0 || t > (std::int64_t{1} << 62)) throw RowSkip{kInvalidTime, "time " + std::to_string(t) + " ns outside 0..2^62"};
  return t;
}

double value(const TableFile& f, int col) {
  double v = 0.0;
  const std::string_view s = f.field(col);
  if (!parse_f64(s, v)) throw RowSkip{kNonNumeric, f.header()[static_cast<std::size_t>(col)] + " '" + printable(s) + "'"};
  if (!std::isfinite(v)) throw RowSkip{kNonFinite, f.header()[static_cast<std::size_t>(col)] + " '" + printable(s) + "'"};
  return v;
}

/// An optional column: NaN when absent or empty.
double optional_value(const TableFile& f, int col) {
  if (col < 0 || trim(f.field(col)).empty()) return kNaN;
  return value(f, col);
}

int need(const TableFile& f, const char* name) {
  const int c = f.column(name);
  if (c < 0) {
    std::string have;
    for (const std::string& h : f.header()) have += (have.empty() ? "" : ",") + printable(h, 24);
    throw IoError(f.where(), 1, std::string("missing column '") + name + "' (header: " + printable(have, 200) + ")");
  }
  return c;
}

int any_of(const TableFile& f, std::initializer_list<const char*> names) {
  for (const char* n : names)
    if (const int c = f.column(n); c >= 0) return c;
  return -1;
}

struct Xyz {
  int t, x, y, z;
};
Xyz xyz_columns(const TableFile& f) { return Xyz{need(f, "time"), need(f, "x"), need(f, "y"), need(f, "z")}; }
Eigen::Vector3d xyz(const TableFile& f, const Xyz& c) { return {value(f, c.x), value(f, c.y), value(f, c.z)}; }
std::int64_t utc_ms_of(TimeNs t) { return t / kNsPerMsI; }

/// Columns a file may hold that the reader knows (time columns and the mapped values).
void list_unknown_columns(const TableFile& f, const std::set<std::string>& known, ReadStats& st) {
  for (const std::string& h : f.header()) {
    const std::string l = lower_ascii(h);
    if (known.count(l) == 0 && st.not_used.size() < 256)
      st.not_used[f.where() + " column '" + printable(h, 40) + "'"] = "unknown column (ignored)";
  }
}

const std::set<std::string> kXyzKnown{"time", "seconds_elapsed", "x", "y", "z"};

/// Bias columns of an uncalibrated file, if the export has them (names vary by version).
struct BiasCols {
  int x = -1, y = -1, z = -1;
};
BiasCols bias_columns(const TableFile& f, std::set<std::string>& known) {
  BiasCols b;
  const char* axes[3] = {"x", "y", "z"};
  int* out[3] = {&b.x, &b.y, &b.z};
  for (int i = 0; i < 3; ++i) {
    const std::string a = axes[i];
    for (const std::string& n : {"bias" + a, a + "bias", "bias_" + a, a + "_bias", "drift" + a, a + "drift"}) {
      const int c = f.column(n);
      if (c >= 0) { *out[i] = c; known.insert(n); break; }
    }
  }
  return b;
}

class SensorLoggerBuilder {
 public:
  SensorLoggerBuilder(std::unique_ptr<Container> c, SourceOptions opt) : c_(std::move(c)), opt_(opt) {}

  std::unique_ptr<SampleSource> build() {
    const std::string name = c_->entries().size() == 1 ? c_->where(c_->entries().front()) : c_->name();
    src_ = std::make_unique<MergedSource>(name, Format::kSensorLogger, opt_, c_->total_bytes());
    ReadStats& st = src_->mutable_stats();
    const std::string root = c_->root();
    std::vector<const Entry*> files;
    for (const Entry& e : c_->entries()) {
      const auto slash = e.path.find_last_of('/');
      const std::string dir = slash == std::string::npos ? std::string() : e.path.substr(0, slash);
      if (dir != root) { st.not_used[c_->where(e)] = "outside the recording's folder"; continue; }
      files.push_back(&e);
    }
    read_metadata();
    auto has = [&](const char* base) {
      const Entry* e = c_->find_path(base);
      return e != nullptr && e->size > 0;
    };
    const bool total = has("TotalAcceleration.csv");
    if (c_->entries().size() == 1)
      src_->set_hint("one file of a Sensor Logger recording: pass the recording's folder or zip to read all of it");
    for (const Entry* e : files) {
      const std::string b = lower_ascii(e->base);
      if (b == "metadata.csv") continue;
      if (e->size == 0) {  // zero bytes: the sensor was listed but not recorded
        st.not_used[c_->where(*e)] = "empty (sensor not recorded)";
        continue;
      }
      if (b == "totalacceleration.csv") add_xyz<AccelSample>(*e, accel_sign());
      else if (b == "accelerometer.csv") accelerometer(*e, total);
      else if (b == "gravity.csv") {
        if (!(conv_.ios && !total && has("Accelerometer.csv")))
          st.not_used[c_->where(*e)] = "gravity alone (the core reads acceleration with gravity)";
      } else if (b == "gyroscope.csv") add_xyz<GyroSample>(*e, 1.0);
      else if (b == "magnetometer.csv") add_xyz<MagSample>(*e, 1.0);
      else if (b == "gyroscopeuncalibrated.csv") add_uncal<UncalGyroSample>(*e, 1.0);
      else if (b == "magnetometeruncalibrated.csv") add_uncal<UncalMagSample>(*e, 1.0);
      else if (b == "accelerometeruncalibrated.csv") add_uncal<UncalAccelSample>(*e, conv_.ios ? -kStandardGravity : 1.0);
      else if (b == "barometer.csv") barometer(*e);
      else if (b == "location.csv") location(*e);
      else if (b == "orientation.csv") st.not_used[c_->where(*e)] = orientation_reason_;
      else st.not_used[c_->where(*e)] = "nothing the core uses";
    }
    return std::move(src_);
  }

 private:
  double accel_sign() const { return conv_.ios ? -1.0 : 1.0; }

  void read_metadata() {
    auto& info = src_->info();
    const Entry* e = c_->find_path("Metadata.csv");
    if (e == nullptr || e->size == 0) {
      info["Platform"] = "android (assumed: no Metadata.csv)";
      return;
    }
    TableFile f(*c_, *e);
    bool row = false;
    try {
      row = f.next_row();
    } catch (const RowSkip&) {
    }
    if (!row) throw IoError(f.where(), f.line_no(), "Metadata.csv has a header but no row");
    if (f.n_fields() != f.header().size())
      throw IoError(f.where(), f.line_no(), "Metadata row has " + std::to_string(f.n_fields()) + " fields, header has " +
                                                std::to_string(f.header().size()));
    std::string platform, standardisation;
    for (std::size_t i = 0; i < f.header().size(); ++i) {
      const std::string k = lower_ascii(f.header()[i]);
      const std::string v = printable(f.field(static_cast<int>(i)), 256);
      if (k == "device id") continue;  // a per-install identifier: not carried over
      if (k == "platform") platform = lower_ascii(v);
      if (k == "standardisation" || k == "standardization") standardisation = lower_ascii(v);
      if (info.size() < 64) info[printable(f.header()[i], 64)] = v;
      const char* meta = k == "device name" ? "Device" : k == "appversion" ? "AppVersion" : k == "platform" ? "Platform"
                       : k == "recording time" ? "RecordingTime" : nullptr;
      if (meta != nullptr) src_->add_prefix(MetaSample{0, meta, v});
    }
    const bool standard = standardisation == "true" || standardisation == "1" || standardisation == "yes" || standardisation == "on";
    conv_.ios = platform == "ios" && !standard;
    src_->add_prefix(MetaSample{0, "SourceFormat", "sensorlogger"});
    src_->mutable_stats().not_used[f.where()] = "metadata: read into Meta rows";
  }

  template <class S> void set_vec(S& s, const Eigen::Vector3d& v) {
    if constexpr (std::is_same_v<S, AccelSample> || std::is_same_v<S, UncalAccelSample>) s.acc_mps2 = v;
    else if constexpr (std::is_same_v<S, GyroSample> || std::is_same_v<S, UncalGyroSample>) s.rate_radps = v;
    else s.field_ut = v;
  }

  template <class S> void add_xyz(const Entry& e, double scale) {
    auto f = std::make_unique<TableFile>(*c_, e);
    if (f->empty_file()) return;
    const Xyz c = xyz_columns(*f);
    list_unknown_columns(*f, kXyzKnown, src_->mutable_stats());
    src_->add(std::move(f), [this, c, scale](const TableFile& t, Sample& out) {
      check_fields(t);
      S s;
      s.t_ns = row_time(t, c.t);
      s.utc_ms = utc_ms_of(s.t_ns);
      set_vec(s, scale * xyz(t, c));
      out = s;
      return true;
    });
  }

  template <class S> void add_uncal(const Entry& e, double scale) {
    auto f = std::make_unique<TableFile>(*c_, e);
    if (f->empty_file()) return;
    const Xyz c = xyz_columns(*f);
    std::set<std::string> known = kXyzKnown;
    const BiasCols b = bias_columns(*f, known);
    list_unknown_columns(*f, known, src_->mutable_stats());
    src_->add(std::move(f), [this, c, b, scale](const TableFile& t, Sample& out) {
      check_fields(t);
      S s;
      s.t_ns = row_time(t, c.t);
      s.utc_ms = utc_ms_of(s.t_ns);
      set_vec(s, scale * xyz(t, c));
      const Eigen::Vector3d bias(optional_value(t, b.x), optional_value(t, b.y), optional_value(t, b.z));
      if constexpr (std::is_same_v<S, UncalAccelSample>) s.bias_mps2 = scale * bias;
      else if constexpr (std::is_same_v<S, UncalGyroSample>) s.drift_radps = bias;
      else s.bias_ut = bias;
      out = s;
      return true;
    });
  }

  /// Accelerometer.csv is user acceleration (without gravity). Android: not used (the
  /// TotalAcceleration file has gravity). iOS writes no TotalAcceleration: the reading with
  /// gravity is -(user + gravity) per row of the same time in Gravity.csv.
  void accelerometer(const Entry& e, bool total) {
    ReadStats& st = src_->mutable_stats();
    const Entry* g = c_->find_path("Gravity.csv");
    if (total || !conv_.ios || g == nullptr || g->size == 0) {
      st.not_used[c_->where(e)] = total ? "acceleration without gravity (TotalAcceleration is read)"
                                        : "acceleration without gravity, and no TotalAcceleration.csv"
                                          + std::string(conv_.ios ? " nor Gravity.csv" : "");
      return;
    }
    auto f = std::make_unique<TableFile>(*c_, e);
    if (f->empty_file()) return;
    auto grav = std::make_shared<TableFile>(*c_, *g);
    if (grav->empty_file()) return;
    const Xyz c = xyz_columns(*f);
    const Xyz gc = xyz_columns(*grav);
    list_unknown_columns(*f, kXyzKnown, st);
    struct GState {
      bool have = false;
      TimeNs t = 0;
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
    };
    auto gs = std::make_shared<GState>();
    src_->add(std::move(f), [grav, gs, c, gc](const TableFile& t, Sample& out) {
      check_fields(t);
      AccelSample s;
      s.t_ns = row_time(t, c.t);
      s.utc_ms = utc_ms_of(s.t_ns);
      const Eigen::Vector3d user = xyz(t, c);
      while (!gs->have || gs->t < s.t_ns) {
        bool row = false;
        try {
          row = grav->next_row();
          if (row) {
            check_fields(*grav);
            gs->t = row_time(*grav, gc.t);
            gs->v = xyz(*grav, gc);
            gs->have = true;
          }
        } catch (const RowSkip&) {
          continue;  // a bad Gravity row: the acceleration rows at its time find no partner
        }
        if (!row) break;
      }
      if (!gs->have || gs->t != s.t_ns)
        throw RowSkip{"no Gravity row at the same time", "t=" + std::to_string(s.t_ns) + " ns"};
      s.acc_mps2 = -(user + gs->v);
      out = s;
      return true;
    });
    st.not_used[c_->where(*g)] = "read with Accelerometer.csv (iOS: acceleration with gravity = -(user + gravity))";
  }

  void barometer(const Entry& e) {
    auto f = std::make_unique<TableFile>(*c_, e);
    if (f->empty_file()) return;
    const int t = need(*f, "time"), p = need(*f, "pressure");
    list_unknown_columns(*f, {"time", "seconds_elapsed", "pressure", "relativealtitude"}, src_->mutable_stats());
    src_->add(std::move(f), [t, p](const TableFile& tf, Sample& out) {
      check_fields(tf);
      PressureSample s;
      s.t_ns = row_time(tf, t);
      s.utc_ms = utc_ms_of(s.t_ns);
      const std::string_view txt = tf.field(p);
      double pa = 0.0;
      if (!parse_f64_pow10(txt, 2, pa)) throw RowSkip{kNonNumeric, "pressure '" + printable(txt) + "'"};
      if (!std::isfinite(pa)) throw RowSkip{kNonFinite, "pressure '" + printable(txt) + "'"};
      // hPa (mbar) by the app's documentation; a value outside the atmosphere's range is a
      // unit mix-up (the watch barometer writes kPa), not a pressure
      if (pa < 30000.0 || pa > 110000.0)
        throw RowSkip{kOutOfRange, "pressure " + printable(txt) + " hPa outside 300..1100 hPa (wrong unit?)"};
      s.pressure_pa = pa;
      out = s;
      return true;
    });
  }

  void location(const Entry& e) {
    auto f = std::make_unique<TableFile>(*c_, e);
    if (f->empty_file()) return;
    struct Cols {
      int t, lat, lon, alt, speed, bearing, hacc, vacc, sacc, bacc;
    };
    const Cols c{need(*f, "time"), need(*f, "latitude"), need(*f, "longitude"), f->column("altitude"),
                 f->column("speed"), f->column("bearing"), f->column("horizontalAccuracy"),
                 f->column("verticalAccuracy"), f->column("speedAccuracy"), f->column("bearingAccuracy")};
    list_unknown_columns(*f, {"time", "seconds_elapsed", "latitude", "longitude", "altitude", "speed", "bearing",
                              "horizontalaccuracy", "verticalaccuracy", "speedaccuracy", "bearingaccuracy",
                              "altitudeabovemeansealevel"},
                         src_->mutable_stats());
    src_->add(std::move(f), [c](const TableFile& t, Sample& out) {
      check_fields(t);
      FixSample s;
      s.t_ns = row_time(t, c.t);
      s.utc_ms = utc_ms_of(s.t_ns);
      // Sensor Logger does not record the provider; its Location rows are the phone's
      // GNSS-based location (Android location services / iOS Core Location)
      s.provider = "GPS";
      s.lat_deg = value(t, c.lat);
      s.lon_deg = value(t, c.lon);
      if (std::fabs(s.lat_deg) > 90.0 || std::fabs(s.lon_deg) > 180.0)
        throw RowSkip{kOutOfRange, "latitude/longitude " + printable(t.field(c.lat)) + "," + printable(t.field(c.lon))};
      s.alt_m = optional_value(t, c.alt);  // WGS84 ellipsoidal height (UNITS.md)
      // negative speed, bearing and accuracies mean "invalid" (UNITS.md)
      auto valid = [&](int col) {
        const double v = optional_value(t, col);
        return v < 0.0 ? kNaN : v;
      };
      s.speed_mps = valid(c.speed);
      s.bearing_deg = valid(c.bearing);
      s.accuracy_m = valid(c.hacc);
      s.vertical_accuracy_m = valid(c.vacc);
      s.speed_accuracy_mps = valid(c.sacc);
      s.bearing_accuracy_deg = valid(c.bacc);
      out = s;
      return true;
    });
  }

  std::unique_ptr<Container> c_;
  SourceOptions opt_;
  Conventions conv_;
  std::unique_ptr<MergedSource> src_;
  std::string orientation_reason_ = "attitude quaternion: reference frame not documented for the rotation vector";
};

}  // namespace

bool is_sensorlogger_header(const std::string& line) {
  std::vector<std::string> f;
  split_fields(line, ',', f);
  return f.size() >= 2 && lower_ascii(f[0]) == "time" && lower_ascii(f[1]) == "seconds_elapsed";
}

std::unique_ptr<SampleSource> open_sensorlogger(std::unique_ptr<Container> c, SourceOptions opt) {
  return SensorLoggerBuilder(std::move(c), opt).build();
}

}  // namespace pdnav::io::detail
