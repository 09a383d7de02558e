// writer -> reader is lossless, field by field, for every line type (random values including
// NaN, +-inf, -0, subnormals, extreme integers, strings with commas/percent/newlines).
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "io_test_util.h"
#include "pdnav/io/log_format.h"
#include "pdnav/io/log_writer.h"

namespace pdnav {
namespace {

using Gen = std::mt19937_64;

double random_double(Gen& g) {
  switch (g() % 10) {
    case 0: return kNaN;
    case 1: return (g() & 1) ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
    case 2: return -0.0;
    case 3: return std::numeric_limits<double>::denorm_min() * static_cast<double>(g() % 1000 + 1);
    case 4: return static_cast<double>(static_cast<std::int32_t>(g()));
    case 5: { double x; std::uint64_t u = g(); std::memcpy(&x, &u, sizeof x); return x; }  // any bits
    case 6: return std::numeric_limits<double>::max() * ((g() & 1) ? 1 : -1);
    default: return std::uniform_real_distribution<double>(-1e6, 1e6)(g);
  }
}
std::int64_t random_i64(Gen& g) {
  switch (g() % 5) {
    case 0: return kMissingInt;
    case 1: return std::numeric_limits<std::int64_t>::max();
    case 2: return std::numeric_limits<std::int64_t>::min() + 1;
    default: return static_cast<std::int64_t>(g());
  }
}
std::string random_text(Gen& g) {
  static const char kChars[] = "abcXYZ019 ,%#\n\r\t;:\"'\xc3\xa9";
  std::string s(g() % 12, ' ');
  for (char& c : s) c = kChars[g() % (sizeof kChars - 1)];
  return s;
}

void fill_value(double& x, Gen& g) { x = random_double(g); }
void fill_value(std::int64_t& x, Gen& g) { x = random_i64(g); }
void fill_value(int& x, Gen& g) { x = static_cast<int>(static_cast<std::int32_t>(g())); }
void fill_value(bool& x, Gen& g) { x = (g() & 1) != 0; }
void fill_value(std::string& x, Gen& g) { x = random_text(g); }
void fill_value(std::vector<std::uint8_t>& x, Gen& g) {
  x.resize(g() % 41);
  for (auto& b : x) b = static_cast<std::uint8_t>(g());
}
template <int N> void fill_value(Eigen::Matrix<double, N, 1>& v, Gen& g) {
  for (int i = 0; i < N; ++i) v[i] = random_double(g);
}

::testing::AssertionResult same(double a, double b) {
  if (std::isnan(a) && std::isnan(b)) return ::testing::AssertionSuccess();
  if (std::memcmp(&a, &b, sizeof a) == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " != " << b;
}
template <class T> ::testing::AssertionResult same(const T& a, const T& b) {
  if (a == b) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "values differ";
}
template <int N>
::testing::AssertionResult same(const Eigen::Matrix<double, N, 1>& a, const Eigen::Matrix<double, N, 1>& b) {
  for (int i = 0; i < N; ++i)
    if (!same(a[i], b[i])) return ::testing::AssertionFailure() << "component " << i << ": " << a[i] << " != " << b[i];
  return ::testing::AssertionSuccess();
}

// Field lists written from pdnav/geo/samples.h, independently of the io schema.
#define SENSOR3(F, v) F(t_ns) F(utc_ms) F(v)
#define ACCEL(F) SENSOR3(F, acc_mps2)
#define GYRO(F) SENSOR3(F, rate_radps)
#define MAG(F) SENSOR3(F, field_ut)
#define UACCEL(F) F(t_ns) F(utc_ms) F(acc_mps2) F(bias_mps2)
#define UGYRO(F) F(t_ns) F(utc_ms) F(rate_radps) F(drift_radps)
#define UMAG(F) F(t_ns) F(utc_ms) F(field_ut) F(bias_ut)
#define ORIENT(F) F(t_ns) F(utc_ms) F(yaw_deg) F(roll_deg) F(pitch_deg)
#define PRESSURE(F) F(t_ns) F(utc_ms) F(pressure_pa)
#define ROTVEC(F) F(t_ns) F(utc_ms) F(quat_xyzw) F(heading_accuracy_rad)
#define STEPDET(F) F(t_ns) F(utc_ms)
#define STEPCNT(F) F(t_ns) F(utc_ms) F(count)
#define RAW(F) F(t_ns) F(utc_ms) F(time_nanos) F(leap_second) F(time_uncertainty_nanos) \
  F(full_bias_nanos) F(bias_nanos) F(bias_uncertainty_nanos) F(drift_nanos_per_second) \
  F(drift_uncertainty_nanos_per_second) F(hardware_clock_discontinuity_count) F(svid) \
  F(time_offset_nanos) F(state) F(received_sv_time_nanos) F(received_sv_time_uncertainty_nanos) \
  F(cn0_dbhz) F(pseudorange_rate_mps) F(pseudorange_rate_uncertainty_mps) \
  F(accumulated_delta_range_state) F(accumulated_delta_range_m) \
  F(accumulated_delta_range_uncertainty_m) F(carrier_frequency_hz) F(carrier_cycles) \
  F(carrier_phase) F(carrier_phase_uncertainty) F(multipath_indicator) F(snr_db) \
  F(constellation_type) F(agc_db) F(baseband_cn0_dbhz) F(full_inter_signal_bias_nanos) \
  F(full_inter_signal_bias_uncertainty_nanos) F(satellite_inter_signal_bias_nanos) \
  F(satellite_inter_signal_bias_uncertainty_nanos) F(code_type) F(chipset_elapsed_realtime_nanos)
#define FIX(F) F(t_ns) F(utc_ms) F(provider) F(lat_deg) F(lon_deg) F(alt_m) F(speed_mps) \
  F(accuracy_m) F(bearing_deg) F(speed_accuracy_mps) F(bearing_accuracy_deg) F(vertical_accuracy_m)
#define NAV(F) F(t_ns) F(svid) F(type) F(status) F(message_id) F(sub_message_id) F(data)
#define STATUS(F) F(t_ns) F(utc_ms) F(signal_count) F(signal_index) F(constellation_type) F(svid) \
  F(carrier_frequency_hz) F(cn0_dbhz) F(azimuth_deg) F(elevation_deg) F(used_in_fix) \
  F(has_almanac) F(has_ephemeris) F(baseband_cn0_dbhz)
#define AGC(F) F(t_ns) F(utc_ms) F(time_nanos) F(agc_db) F(carrier_frequency_hz) F(constellation_type)
#define TRUTH(F) F(t_ns) F(lat_deg) F(lon_deg) F(h_m) F(heading_deg)
#define META(F) F(t_ns) F(key) F(value)
#define GAMEROTVEC(F) F(t_ns) F(utc_ms) F(quat_xyzw)
#define SENSACC_CHECK(F) F(t_ns) F(utc_ms) F(sensor_type) F(accuracy)

#define FILL_FIELD(f) fill_value(s.f, g);
#define CHECK_FIELD(f) EXPECT_TRUE(same(a.f, b.f)) << ctx << " field " #f;
#define SAMPLE_TYPE(Type, FIELDS)                                                          \
  void fill_sample(Type& s, Gen& g) { FIELDS(FILL_FIELD) }                                 \
  void check_sample(const Type& a, const Type& b, const std::string& ctx) { FIELDS(CHECK_FIELD) }
SAMPLE_TYPE(AccelSample, ACCEL)
SAMPLE_TYPE(GyroSample, GYRO)
SAMPLE_TYPE(MagSample, MAG)
SAMPLE_TYPE(UncalAccelSample, UACCEL)
SAMPLE_TYPE(UncalGyroSample, UGYRO)
SAMPLE_TYPE(UncalMagSample, UMAG)
SAMPLE_TYPE(OrientationSample, ORIENT)
SAMPLE_TYPE(PressureSample, PRESSURE)
SAMPLE_TYPE(RotationVectorSample, ROTVEC)
SAMPLE_TYPE(StepDetectorSample, STEPDET)
SAMPLE_TYPE(StepCounterSample, STEPCNT)
SAMPLE_TYPE(GnssRawSample, RAW)
SAMPLE_TYPE(FixSample, FIX)
SAMPLE_TYPE(NavMessageSample, NAV)
SAMPLE_TYPE(GnssStatusSample, STATUS)
SAMPLE_TYPE(AgcSample, AGC)
SAMPLE_TYPE(TruthSample, TRUTH)
SAMPLE_TYPE(MetaSample, META)
SAMPLE_TYPE(GameRotationVectorSample, GAMEROTVEC)
// SensorAccuracy: the reader accepts only Android's values (sensor type > 0, SENSOR_STATUS -1..3).
void fill_sample(SensorAccuracySample& s, Gen& g) {
  s.utc_ms = random_i64(g);
  s.sensor_type = static_cast<int>(g() % 40 + 1);
  s.accuracy = static_cast<int>(g() % 5) - 1;
}
void check_sample(const SensorAccuracySample& a, const SensorAccuracySample& b, const std::string& ctx) {
  SENSACC_CHECK(CHECK_FIELD)
}

template <std::size_t... I> Sample make_sample(std::size_t k, std::index_sequence<I...>) {
  Sample s;
  ((k == I ? (s.emplace<I>(), 0) : 0), ...);
  return s;
}

/// n random samples of every type, interleaved, times increasing.
std::vector<Sample> random_samples(int per_type, std::uint64_t seed) {
  Gen g(seed);
  std::vector<Sample> out;
  TimeNs t = 1'000'000'000;
  for (int i = 0; i < per_type; ++i) {
    for (std::size_t k = 0; k < std::variant_size_v<Sample>; ++k) {
      Sample s = make_sample(k, std::make_index_sequence<std::variant_size_v<Sample>>{});
      std::visit([&](auto& x) { fill_sample(x, g); x.t_ns = t; }, s);
      t += static_cast<TimeNs>(g() % 10'000'000);  // 0..10 ms, equal times allowed
      out.push_back(std::move(s));
    }
  }
  return out;
}

void check_all(const std::vector<Sample>& in, const std::vector<Sample>& out) {
  ASSERT_EQ(in.size(), out.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    ASSERT_EQ(in[i].index(), out[i].index()) << "sample " << i;
    const std::string ctx = "sample " + std::to_string(i) + " (" + std::string(io::line_type_name(in[i])) + ")";
    std::visit([&](const auto& a) { check_sample(a, std::get<std::decay_t<decltype(a)>>(out[i]), ctx); }, in[i]);
    EXPECT_TRUE(io::same_sample(in[i], out[i])) << ctx;
  }
}

TEST(LogRoundTrip, EveryLineTypeIsLosslessThroughWriterAndReader) {
  const std::vector<Sample> in = random_samples(200, 42);
  auto stream = std::make_unique<std::ostringstream>();
  std::ostringstream* raw = stream.get();
  {
    io::LogWriter w(std::move(stream), "mem");
    for (const Sample& s : in) w.write(s);
    EXPECT_EQ(w.lines_written(), static_cast<std::int64_t>(in.size()));
    w.close();
    const test::ReadResult r = test::read_text(raw->str());
    EXPECT_EQ(r.stats.skipped_total(), 0) << (r.stats.issues.empty() ? "" : r.stats.issues[0].to_string());
    check_all(in, r.samples);
    EXPECT_EQ(r.stats.samples_by_type.size(), std::variant_size_v<Sample>);
  }
}

TEST(LogRoundTrip, LinesWithoutHeaderUseTheDefaultColumns) {
  const std::vector<Sample> in = random_samples(20, 7);
  std::string text;
  for (const Sample& s : in) text += io::format_line(s) + "\n";
  const test::ReadResult r = test::read_text(text);
  EXPECT_EQ(r.stats.skipped_total(), 0);
  check_all(in, r.samples);
}

TEST(LogRoundTrip, DefaultColumnsMatchTheWrittenHeader) {
  const std::string h = io::log_header("Pixel 7, test");
  for (std::string_view type : io::line_type_names()) {
    const auto cols = io::default_columns(type);
    ASSERT_GE(cols.size(), 2u) << type;
    std::string line = "# " + cols[0];
    for (std::size_t i = 1; i < cols.size(); ++i) line += "," + cols[i];
    EXPECT_NE(h.find(line + "\n"), std::string::npos) << line;
  }
  EXPECT_NE(h.find("# Version: pdnav-log 1"), std::string::npos);
  EXPECT_TRUE(io::default_columns("NoSuchType").empty());
}

TEST(LogRoundTrip, PressureIsHectopascalInTheFileAndPascalInTheSample) {
  PressureSample p;
  p.t_ns = 5;
  p.pressure_pa = 101325.3;
  const std::string line = io::format_line(p);
  EXPECT_EQ(line, "Pressure,,5,1013.253");
  const test::ReadResult r = test::read_text("Pressure,1,6,1013.25\nPressure,1,7,9.8765432109876e2\n");
  ASSERT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(std::get<PressureSample>(r.samples[0]).pressure_pa, 101325.0);
  EXPECT_EQ(std::get<PressureSample>(r.samples[1]).pressure_pa, 98765.432109876);
}

TEST(LogRoundTrip, GnssLoggerNumbersKeepTheirExactText) {
  GnssRawSample raw;
  raw.t_ns = 16136559319000;
  raw.full_bias_nanos = -1383435750910273353;
  raw.received_sv_time_nanos = 258211922049091;
  raw.cn0_dbhz = 28.924739837646484;
  raw.accumulated_delta_range_uncertainty_m = 3.4028234663852886e38;
  const std::string line = io::format_line(raw);
  EXPECT_NE(line.find(",-1383435750910273353,"), std::string::npos) << line;
  EXPECT_NE(line.find(",258211922049091,"), std::string::npos) << line;
  EXPECT_NE(line.find(",28.924739837646484,"), std::string::npos) << line;
  EXPECT_NE(line.find(",3.4028234663852886e+38,"), std::string::npos) << line;
}

}  // namespace
}  // namespace pdnav
