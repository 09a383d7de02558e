// libFuzzer target: arbitrary bytes -> a sequence of samples with arbitrary values (NaN, inf,
// huge, backwards and repeated times) -> fusion::Navigator running dead reckoning, the
// terrain engine on a small synthetic DEM and the GNSS engine on a trimmed real RINEX file.
// The Navigator must never crash, never throw from feed(), and never report a valid
// estimate with a non-finite position or covariance.
//
// Input format (little endian; tools/fuzz `seeds-navigator` writes seeds from real logs):
//   byte 0: config. bits 0-1 mode (auto, dr, terrain, gnss); bit 2 synthetic DEM;
//           bit 3 RINEX navigation file; bits 4-5 particles (50, 1, 200, 0);
//           bit 6 terrain preset "paper" (else "srtm"); bit 7 start at the DEM centre.
//   then records: kind byte (low 4 bits: kind mod 13; bit 7: an int64 absolute time in ns
//   follows, else an int16 time step in units of 0.1 ms), then the kind's payload:
//     0 accel, 1 gyro, 2 mag, 5 orientation: 3 x f32 | 3 pressure: f32 Pa
//     4 rotation vector: 5 x f32 (x, y, z, w, heading accuracy) | 6 step detector: -
//     7 step counter: i32 | 8 fix: f64 lat, f64 lon, f32 alt, f32 accuracy
//     9 GNSS raw: i64 TimeNanos, FullBiasNanos, ReceivedSvTimeNanos, State, LeapSecond;
//       f64 BiasNanos, TimeOffsetNanos, Cn0DbHz, PseudorangeRate, ReceivedSvTimeUncertainty,
//       CarrierFrequencyHz; u8 svid, u8 constellation
//     10 set_start: f64 lat, f64 lon, f32 sigma | 11 output(): - | 12 meta: u8 key, u8 n, n bytes
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pdnav/fusion/navigator.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/terrain/dem.h"

namespace {

using pdnav::Sample;

constexpr double kDemLat0 = 42.5063;  // Andorra la Vella; the DEM centre
constexpr double kDemLon0 = 1.5218;
constexpr int kDemCells = 48;
constexpr double kDemCell_m = 30.0;

/// Made once per process: a synthetic DEM tile and a trimmed RINEX nav file, written to temp
/// files and loaded once; every input's Navigator shares them (NavigatorConfig::dem,
/// ::ephemeris), so an execution costs the samples, not reloading the files (their readers
/// have their own targets, fuzz_dem_reader and fuzz_rinex_reader).
struct Fixture {
  std::shared_ptr<const pdnav::terrain::Dem> dem;
  std::shared_ptr<const pdnav::gnss::EphemerisStore> ephemeris;
  /// PDNAV_FUZZ_CLAMP_TIMES=1 steers a long run around the known, reported findings
  /// (docs/reliability.md): every time (sample t_ns, TimeNanos, FullBiasNanos) within +-2^61
  /// (int64 overflow of time differences) and start/fix sigmas above 1e4 m or infinite set to
  /// 1e4 m (a "valid" estimate at infinity). Default: unclamped, every value possible.
  bool clamp_times = false;
};

std::uint32_t crc32(const unsigned char* p, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return c ^ 0xFFFFFFFFu;
}

/// A hilly 48x48 tile of 30 m cells (docs/dem-format.md) with a few void cells.
std::string write_synthetic_dem(const std::string& dir) {
  std::vector<float> z(static_cast<std::size_t>(kDemCells * kDemCells));
  for (int r = 0; r < kDemCells; ++r) {
    for (int c = 0; c < kDemCells; ++c) {
      const double x = c * kDemCell_m, y = r * kDemCell_m;
      double h = 1100.0 + 40.0 * std::sin(x / 170.0) * std::cos(y / 230.0) + 0.05 * x;
      if ((r * 7 + c * 3) % 97 == 0) h = -32768.0;  // voids
      z[static_cast<std::size_t>(r * kDemCells + c)] = static_cast<float>(h);
    }
  }
  std::vector<unsigned char> data(z.size() * 4);
  for (std::size_t i = 0; i < z.size(); ++i) {
    std::uint32_t u = 0;
    std::memcpy(&u, &z[i], 4);
    for (int b = 0; b < 4; ++b) data[i * 4 + static_cast<std::size_t>(b)] = static_cast<unsigned char>(u >> (8 * b));
  }
  const double half = 0.5 * kDemCells * kDemCell_m;
  std::ostringstream h;
  h.precision(12);
  h << "PDEM 1\ncrs local_enu\norigin_lat_deg " << kDemLat0 << "\norigin_lon_deg " << kDemLon0
    << "\nproj4 +proj=ortho_+lat_0=" << kDemLat0 << "_+lon_0=" << kDemLon0
    << "_+x_0=0_+y_0=0_+ellps=WGS84_+units=m_+no_defs\ncols " << kDemCells << "\nrows " << kDemCells
    << "\ncell_m " << kDemCell_m << "\nx0_m " << -half << "\ny0_m " << -half
    << "\nnodata -32768.0\nvertical_datum egm96\nresampling bilinear\nvoid_fill none\n"
    << "voids_source 24\nvoids 24\nmin_m 1000.000\nmax_m 1200.000\nsource synthetic\n"
    << "source_sha256 0\ndata_crc32 ";
  char crc[16];
  std::snprintf(crc, sizeof crc, "%08x", crc32(data.data(), data.size()));
  h << crc << "\nend_header\n";
  const std::string path = dir + "/synthetic.pdem";
  std::ofstream f(path, std::ios::binary);
  const std::string head = h.str();
  f.write(head.data(), static_cast<std::streamsize>(head.size()));
  f.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
  return path;
}

/// The real GPS broadcast file of the Mountain View log, cut to its header and the records
/// of 21-22 h (the log's epoch).
std::string write_trimmed_rinex(const std::string& dir) {
  std::ifstream in(std::string(PDNAV_SHARED_DATA_DIR) + "/gnss-mountainview/hour2350.16n");
  if (!in) return "";
  std::ostringstream out;
  std::string line;
  bool header = true, keep = false;
  while (std::getline(in, line)) {
    if (header) {
      out << line << '\n';
      if (line.find("END OF HEADER") != std::string::npos) header = false;
      continue;
    }
    if (line.size() > 22 && line.compare(0, 3, "   ") != 0) {  // a record's first line
      const int hour = std::atoi(line.substr(12, 3).c_str());
      keep = hour == 21 || hour == 22;
    }
    if (keep) out << line << '\n';
  }
  const std::string path = dir + "/trimmed.16n";
  std::ofstream(path) << out.str();
  return path;
}

Fixture& fixture() {
  static Fixture fx = [] {
    char tmpl[] = "/tmp/pdnav_fuzz_navigator_XXXXXX";
    const char* dir = mkdtemp(tmpl);
    Fixture f;
    if (dir == nullptr) return f;
    // A fixture that fails to load throws here: the target aborts at its first input, loudly.
    f.dem = std::make_shared<const pdnav::terrain::Dem>(pdnav::terrain::Dem::load(write_synthetic_dem(dir)));
    const std::string nav_path = write_trimmed_rinex(dir);
    if (!nav_path.empty()) {
      auto eph = std::make_shared<pdnav::gnss::EphemerisStore>();
      eph->load_rinex_nav(nav_path);
      f.ephemeris = eph;
    }
    const char* clamp = std::getenv("PDNAV_FUZZ_CLAMP_TIMES");
    f.clamp_times = clamp != nullptr && clamp[0] == '1';
    return f;
  }();
  return fx;
}

/// Reads little-endian fields from the fuzz input; every read fails softly at the end.
class Reader {
 public:
  Reader(const std::uint8_t* p, std::size_t n) : p_(p), n_(n) {}
  bool has(std::size_t k) const { return n_ - pos_ >= k; }
  std::uint8_t u8() { return p_[pos_++]; }
  template <typename T>
  T get() {
    T v;
    std::memcpy(&v, p_ + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  double f32() { return static_cast<double>(get<float>()); }
  double f64() { return get<double>(); }
  std::int64_t i64() { return get<std::int64_t>(); }

 private:
  const std::uint8_t* p_;
  std::size_t n_;
  std::size_t pos_ = 0;
};

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "fuzz_navigator: %s\n", what);
  std::abort();
}

void check_estimate(const pdnav::Estimate& e) {
  if (!e.valid()) return;
  const bool finite = std::isfinite(e.position.lat_rad) && std::isfinite(e.position.lon_rad) &&
                      std::isfinite(e.position.h_m) &&
                      std::isfinite(e.en_m.x()) && std::isfinite(e.en_m.y()) &&
                      e.cov_en_m2.allFinite() && std::isfinite(e.vertical_sigma_m);
  if (!finite) {
    std::fprintf(stderr, "fuzz_navigator: %s estimate (%s, %s): lat %g lon %g h %g en %g %g cov %g %g %g %g\n",
                 pdnav::to_string(e.engine), pdnav::to_string(e.status), e.reason.c_str(), e.position.lat_rad,
                 e.position.lon_rad, e.position.h_m, e.en_m.x(), e.en_m.y(), e.cov_en_m2(0, 0), e.cov_en_m2(0, 1),
                 e.cov_en_m2(1, 0), e.cov_en_m2(1, 1));
    fail("valid estimate with a non-finite position or covariance");
  }
}

void check_output(const pdnav::fusion::Navigator& nav) {
  const auto out = nav.output(50);
  check_estimate(out.estimate);
  for (const auto& e : out.engines) check_estimate(e);
}

pdnav::fusion::NavigatorConfig make_config(std::uint8_t c, const Fixture& fx) {
  using pdnav::fusion::EngineMode;
  static const EngineMode kModes[] = {EngineMode::kAuto, EngineMode::kDeadReckoning,
                                      EngineMode::kTerrain, EngineMode::kGnss};
  static const int kParticles[] = {50, 1, 200, 0};
  pdnav::fusion::NavigatorConfig cfg;
  cfg.mode = kModes[c & 3];
  if (c & 4) cfg.dem = fx.dem;
  if (c & 8) cfg.ephemeris = fx.ephemeris;
  cfg.particles = kParticles[(c >> 4) & 3];
  cfg.terrain_preset = (c & 64) ? "paper" : "srtm";
  if (c & 128) {
    cfg.start_lat_deg = kDemLat0;
    cfg.start_lon_deg = kDemLon0;
  }
  return cfg;
}

template <typename S>
S stamped(pdnav::TimeNs t) {
  S s;
  s.t_ns = t;
  return s;
}

Eigen::Vector3d vec3(Reader& r) {
  const double x = r.f32(), y = r.f32(), z = r.f32();
  return {x, y, z};
}

/// Payload size in bytes of each record kind (see the header comment).
constexpr std::size_t kPayload[13] = {12, 12, 12, 4, 20, 12, 0, 4, 24, 90, 20, 0, 2};

const char* const kMetaKeys[] = {"StartLatitudeDegrees", "StartLongitudeDegrees", "StartSigmaMeters",
                                 "UserHeightMeters", "Device", "DemSha256"};

/// A double as an integer field: kMissingInt unless finite and in range.
std::int64_t to_i64(double v) {
  return (std::isfinite(v) && std::fabs(v) < 9e18) ? static_cast<std::int64_t>(v) : pdnav::kMissingInt;
}

/// A start/fix sigma in clamp mode: +inf and anything above 1e4 m become 1e4 m.
double clamp_sigma(double v, bool clamp) { return clamp && v > 1e4 ? 1e4 : v; }

std::int64_t clamp61(std::int64_t v) {
  constexpr std::int64_t kLim = std::int64_t{1} << 61;  // differences stay within int64
  return v < -kLim ? -kLim : (v > kLim ? kLim : v);
}

pdnav::GnssRawSample raw_sample(Reader& r, pdnav::TimeNs t, bool clamp_time) {
  auto s = stamped<pdnav::GnssRawSample>(t);
  s.time_nanos = r.i64();
  s.full_bias_nanos = r.i64();
  if (clamp_time) {
    s.time_nanos = clamp61(s.time_nanos);
    s.full_bias_nanos = clamp61(s.full_bias_nanos);
  }
  s.received_sv_time_nanos = r.i64();
  s.state = r.i64();
  s.leap_second = r.i64();
  s.bias_nanos = r.f64();
  s.time_offset_nanos = r.f64();
  s.cn0_dbhz = r.f64();
  s.pseudorange_rate_mps = r.f64();
  s.received_sv_time_uncertainty_nanos = to_i64(r.f64());
  s.carrier_frequency_hz = r.f64();
  s.svid = r.u8();
  s.constellation_type = r.u8() % 8;
  return s;
}

/// Decodes and applies one record; false when the input is exhausted.
bool apply_record(Reader& r, pdnav::fusion::Navigator& nav, std::uint64_t& t, bool clamp_times) {
  if (!r.has(1)) return false;
  const std::uint8_t head = r.u8();
  const unsigned kind = (head & 0x0Fu) % 13u;
  if (head & 0x80u) {
    if (!r.has(8)) return false;
    t = static_cast<std::uint64_t>(r.i64());
  } else {
    if (!r.has(2)) return false;
    t += static_cast<std::uint64_t>(static_cast<std::int64_t>(r.get<std::int16_t>()) * 100000);
  }
  if (clamp_times) t = static_cast<std::uint64_t>(clamp61(static_cast<std::int64_t>(t)));
  const auto t_ns = static_cast<pdnav::TimeNs>(t);
  if (!r.has(kPayload[kind])) return false;
  switch (kind) {
    case 0: { auto s = stamped<pdnav::AccelSample>(t_ns); s.acc_mps2 = vec3(r); nav.feed(s); break; }
    case 1: { auto s = stamped<pdnav::GyroSample>(t_ns); s.rate_radps = vec3(r); nav.feed(s); break; }
    case 2: { auto s = stamped<pdnav::MagSample>(t_ns); s.field_ut = vec3(r); nav.feed(s); break; }
    case 3: { auto s = stamped<pdnav::PressureSample>(t_ns); s.pressure_pa = r.f32(); nav.feed(s); break; }
    case 4: {
      auto s = stamped<pdnav::RotationVectorSample>(t_ns);
      const double x = r.f32(), y = r.f32(), z = r.f32(), w = r.f32();
      s.quat_xyzw = Eigen::Vector4d(x, y, z, w);
      s.heading_accuracy_rad = r.f32();
      nav.feed(s);
      break;
    }
    case 5: {
      auto s = stamped<pdnav::OrientationSample>(t_ns);
      s.yaw_deg = r.f32(); s.roll_deg = r.f32(); s.pitch_deg = r.f32();
      nav.feed(s);
      break;
    }
    case 6: nav.feed(stamped<pdnav::StepDetectorSample>(t_ns)); break;
    case 7: { auto s = stamped<pdnav::StepCounterSample>(t_ns); s.count = r.get<std::int32_t>(); nav.feed(s); break; }
    case 8: {
      auto s = stamped<pdnav::FixSample>(t_ns);
      s.provider = "GPS";
      s.lat_deg = r.f64(); s.lon_deg = r.f64(); s.alt_m = r.f32(); s.accuracy_m = clamp_sigma(r.f32(), clamp_times);
      nav.feed(s);
      break;
    }
    case 9: nav.feed(raw_sample(r, t_ns, clamp_times)); break;
    case 10: {
      const double lat = r.f64(), lon = r.f64(), sigma = clamp_sigma(r.f32(), clamp_times);
      nav.set_start(lat, lon, sigma, t_ns);
      break;
    }
    case 11: check_output(nav); break;
    default: {
      auto s = stamped<pdnav::MetaSample>(t_ns);
      s.key = kMetaKeys[r.u8() % (sizeof kMetaKeys / sizeof kMetaKeys[0])];
      const std::size_t n = r.u8();
      for (std::size_t i = 0; i < n && r.has(1); ++i) s.value.push_back(static_cast<char>(r.u8()));
      nav.feed(s);
      break;
    }
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const Fixture& fx = fixture();
  Reader r(data, size);
  const auto cfg = make_config(r.u8(), fx);
  std::unique_ptr<pdnav::fusion::Navigator> nav;
  try {
    nav = std::make_unique<pdnav::fusion::Navigator>(cfg, 0x5eed);
  } catch (const std::exception&) {
    return 0;  // a rejected configuration (e.g. 0 particles) is a clear error, not a crash
  }
  std::uint64_t t = 0;
  int records = 0;
  while (records < 20000 && apply_record(r, *nav, t, fx.clamp_times)) ++records;
  check_output(*nav);
  check_estimate(nav->estimate());
  return 0;
}
