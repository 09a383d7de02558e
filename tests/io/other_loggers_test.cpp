// The readers of other loggers' recordings behind io::open_sample_source (docs/log-format.md
// "Other loggers"): Sensor Logger (the shared real walk; folder, zip, single file), phyphox and
// GetSensorData (fixtures written from their specifications, tests/data/loggers/SOURCE.md),
// format detection, and bad input per reader (truncated file, missing sensor file, unknown
// column, time going backwards, NaN, wrong units): a clear error with file and line, or a
// counted, reported skip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>

#include "pdnav/io/log_format.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/io/log_writer.h"
#include "pdnav/io/sample_source.h"
#include "zip_writer.h"

namespace pdnav {
namespace {

namespace fs = std::filesystem;
using io::Format;
using Files = std::vector<std::pair<std::string, std::string>>;

const std::string kWalk = std::string(PDNAV_SHARED_DATA_DIR) + "/walk-ethz-sensorlogger/2023-03-17_15-50-47";
const std::string kLoggers = std::string(PDNAV_TEST_DATA_DIR) + "/loggers";

struct Read {
  std::vector<Sample> samples;
  io::ReadStats stats;
  std::map<std::string, std::string> info;
  Format format = Format::kAuto;
};

Read drain(io::SampleSource& src) {
  Read r;
  Sample s;
  while (src.next(s)) r.samples.push_back(s);
  r.stats = src.stats();
  r.info = src.header_info();
  r.format = src.format();
  return r;
}
Read read_path(const std::string& path, Format f = Format::kAuto, io::SourceOptions opt = {}) {
  auto src = io::open_sample_source(path, f, opt);
  return drain(*src);
}
Read read_mem(Files files, Format f, io::SourceOptions opt = {}) {
  auto src = io::open_memory_source(std::move(files), "mem", f, opt);
  return drain(*src);
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
/// Every file under dir, paths relative to it ("meta/time.csv"), sorted.
Files load_folder(const std::string& dir, const std::string& prefix = "") {
  Files out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out.emplace_back(prefix + fs::relative(e.path(), dir).generic_string(), slurp(e.path()));
  std::sort(out.begin(), out.end());
  return out;
}

std::int64_t count_type(const Read& r, const std::string& type) {
  auto it = r.stats.samples_by_type.find(type);
  return it == r.stats.samples_by_type.end() ? 0 : it->second;
}
std::int64_t skipped(const Read& r, const std::string& reason) {
  auto it = r.stats.skipped_by_reason.find(reason);
  return it == r.stats.skipped_by_reason.end() ? 0 : it->second;
}
template <class S> std::vector<S> all_of(const Read& r) {
  std::vector<S> v;
  for (const Sample& s : r.samples)
    if (const auto* x = std::get_if<S>(&s)) v.push_back(*x);
  return v;
}
std::int64_t data_rows(const fs::path& csv) {  // lines after the header
  std::ifstream in(csv);
  std::string l;
  std::int64_t n = -1;
  while (std::getline(in, l))
    if (!l.empty()) ++n;
  return std::max<std::int64_t>(0, n);
}
/// First data row of a CSV as column name -> text.
std::map<std::string, std::string> first_row(const fs::path& csv) {
  std::ifstream in(csv);
  std::string h, d;
  std::getline(in, h);
  std::getline(in, d);
  std::map<std::string, std::string> m;
  std::stringstream hs(h), ds(d);
  std::string a, b;
  while (std::getline(hs, a, ',') && std::getline(ds, b, ',')) m[a] = b;
  return m;
}
void expect_same(const Read& a, const Read& b) {
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (std::size_t i = 0; i < a.samples.size(); ++i)
    ASSERT_TRUE(io::same_sample(a.samples[i], b.samples[i])) << "sample " << i << ": " << io::format_line(a.samples[i])
                                                             << " vs " << io::format_line(b.samples[i]);
}
void expect_time_ordered(const Read& r) {
  for (std::size_t i = 1; i < r.samples.size(); ++i)
    ASSERT_LE(sample_time_ns(r.samples[i - 1]), sample_time_ns(r.samples[i])) << "sample " << i;
}
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const io::IoError& e) {
    return e.what();
  }
  return "";
}

// ---- Sensor Logger: the shared real walk ------------------------------------------------

TEST(SensorLogger, SharedWalkFolderEveryRowNoSkipTimeOrdered) {
  const Read r = read_path(kWalk);
  EXPECT_EQ(r.format, Format::kSensorLogger);
  EXPECT_EQ(r.stats.skipped_total(), 0);
  const fs::path w(kWalk);
  EXPECT_EQ(count_type(r, "Accel"), data_rows(w / "TotalAcceleration.csv"));
  EXPECT_EQ(count_type(r, "Gyro"), data_rows(w / "Gyroscope.csv"));
  EXPECT_EQ(count_type(r, "Mag"), data_rows(w / "Magnetometer.csv"));
  EXPECT_EQ(count_type(r, "UncalGyro"), data_rows(w / "GyroscopeUncalibrated.csv"));
  EXPECT_EQ(count_type(r, "UncalMag"), data_rows(w / "MagnetometerUncalibrated.csv"));
  EXPECT_EQ(count_type(r, "Pressure"), data_rows(w / "Barometer.csv"));
  EXPECT_EQ(count_type(r, "Fix"), data_rows(w / "Location.csv"));
  EXPECT_GT(count_type(r, "Accel"), 30000);
  expect_time_ordered(r);
  // files without anything the core uses are listed, not skipped
  EXPECT_TRUE(r.stats.not_used.count((w / "Accelerometer.csv").string()));
  EXPECT_TRUE(r.stats.not_used.count((w / "Gravity.csv").string()));
  EXPECT_TRUE(r.stats.not_used.count((w / "Annotation.csv").string()));
  EXPECT_EQ(r.info.at("platform"), "android");
  // Meta rows from Metadata.csv come first
  ASSERT_TRUE(std::holds_alternative<MetaSample>(r.samples.front()));
  bool device = false;
  for (const auto& m : all_of<MetaSample>(r)) device |= m.key == "Device" && m.value == "SM-A520F";
  EXPECT_TRUE(device);
}

TEST(SensorLogger, ColumnsMappedByNameUnitsAndTime) {
  const Read r = read_path(kWalk);
  const fs::path w(kWalk);
  // the files are z,y,x: the first TotalAcceleration row by header name
  const auto acc_row = first_row(w / "TotalAcceleration.csv");
  const AccelSample a = all_of<AccelSample>(r).front();
  EXPECT_EQ(a.t_ns, std::stoll(acc_row.at("time")));
  EXPECT_EQ(a.utc_ms, a.t_ns / 1000000);
  EXPECT_DOUBLE_EQ(a.acc_mps2.x(), std::stod(acc_row.at("x")));
  EXPECT_DOUBLE_EQ(a.acc_mps2.y(), std::stod(acc_row.at("y")));
  EXPECT_DOUBLE_EQ(a.acc_mps2.z(), std::stod(acc_row.at("z")));
  EXPECT_NEAR(a.acc_mps2.norm(), 9.81, 0.5);  // with gravity
  // hPa -> Pa
  const auto p_row = first_row(w / "Barometer.csv");
  const PressureSample p = all_of<PressureSample>(r).front();
  EXPECT_NEAR(p.pressure_pa, std::stod(p_row.at("pressure")) * 100.0, 1e-9 * p.pressure_pa);
  // Location -> Fix
  const auto l_row = first_row(w / "Location.csv");
  const FixSample f = all_of<FixSample>(r).front();
  EXPECT_EQ(f.provider, "GPS");
  EXPECT_DOUBLE_EQ(f.lat_deg, std::stod(l_row.at("latitude")));
  EXPECT_DOUBLE_EQ(f.lon_deg, std::stod(l_row.at("longitude")));
  EXPECT_DOUBLE_EQ(f.accuracy_m, std::stod(l_row.at("horizontalAccuracy")));
  EXPECT_DOUBLE_EQ(f.alt_m, std::stod(l_row.at("altitude")));
  // no bias columns in this export: NaN, not zero
  EXPECT_TRUE(std::isnan(all_of<UncalGyroSample>(r).front().drift_radps.x()));
}

TEST(SensorLogger, ZipReadsLikeTheFolder) {
  const Read folder = read_path(kWalk);
  // the app's export: a zip holding the recording's folder, deflated
  const std::string zip = test::make_zip(load_folder(kWalk, "2023-03-17_15-50-47/"));
  const Read zipped = read_mem({{"walk.zip", zip}}, Format::kAuto);
  EXPECT_EQ(zipped.format, Format::kSensorLogger);
  EXPECT_EQ(zipped.stats.skipped_total(), 0);
  expect_same(folder, zipped);
  // also on disk, stored (method 0), detected from the content and not the name
  const fs::path tmp = fs::temp_directory_path() / "pdnav_sensorlogger_test.bin";
  std::ofstream(tmp, std::ios::binary) << test::make_zip(load_folder(kWalk), false);
  EXPECT_EQ(io::detect_format(tmp.string()), Format::kSensorLogger);
  expect_same(folder, read_path(tmp.string()));
  fs::remove(tmp);
}

TEST(SensorLogger, ImportThenReadBackIsIdentical) {
  const Read direct = read_path(kWalk);
  auto buf = std::make_unique<std::ostringstream>();
  auto* raw = buf.get();
  {
    io::LogWriter w(std::move(buf), "mem");
    for (const Sample& s : direct.samples) w.write(s);
    w.close();
    io::LogReader back(std::make_unique<std::istringstream>(raw->str()), "imported");
    Read b;
    Sample s;
    while (back.next(s)) b.samples.push_back(s);
    EXPECT_EQ(back.stats().skipped_total(), 0);
    expect_same(direct, b);
  }
}

TEST(SensorLogger, SingleCsvReadsOrSaysToPassTheFolder) {
  const Read g = read_path(kWalk + "/Gyroscope.csv");
  EXPECT_EQ(g.format, Format::kSensorLogger);
  EXPECT_EQ(count_type(g, "Gyro"), data_rows(fs::path(kWalk) / "Gyroscope.csv"));
  const std::string e = error_of([] { read_path(kWalk + "/Accelerometer.csv"); });
  EXPECT_NE(e.find("no samples"), std::string::npos) << e;
  EXPECT_NE(e.find("without gravity"), std::string::npos) << e;
  EXPECT_NE(e.find("pass the recording's folder or zip"), std::string::npos) << e;
}

// ---- Sensor Logger: bad input (small recordings in memory) --------------------------------

const std::string kMetaAndroid =
    "version,device name,recording time,platform,appVersion,device id,sensors,sampleRateMs\n"
    "3,Pixel,2024-01-01_10-00-00,android,1.30.0,abc,Gyroscope|TotalAcceleration,10|10\n";
std::string gyro_rows(int n, std::int64_t t0 = 1700000000000000000, std::int64_t dt = 10000000) {
  std::string s = "time,seconds_elapsed,z,y,x\n";
  for (int i = 0; i < n; ++i)
    s += std::to_string(t0 + i * dt) + "," + std::to_string(i * 0.01) + ",0.3,0.2,0.1\n";
  return s;
}

TEST(SensorLoggerBad, TruncatedFileSkipsTheTornRowWithFileAndLine) {
  std::string g = gyro_rows(5);
  g.resize(g.size() - 6);  // the last row cut mid-field, no newline
  const Read r = read_mem({{"Metadata.csv", kMetaAndroid}, {"Gyroscope.csv", g}}, Format::kSensorLogger);
  EXPECT_EQ(count_type(r, "Gyro"), 4);
  EXPECT_EQ(skipped(r, "torn last line"), 1);
  ASSERT_EQ(r.stats.issues.size(), 1u);
  EXPECT_EQ(r.stats.issues[0].file, "mem/Gyroscope.csv");
  EXPECT_EQ(r.stats.issues[0].line, 6);
  // a zip cut short has no central directory: an error naming the archive
  const std::string zip = test::make_zip({{"Gyroscope.csv", gyro_rows(50)}});
  const std::string e = error_of([&] { read_mem({{"w.zip", zip.substr(0, zip.size() / 2)}}, Format::kAuto); });
  EXPECT_NE(e.find("not a readable zip"), std::string::npos) << e;
  // a zip entry whose bytes are damaged: the CRC check catches it at the entry's end
  std::string bad = test::make_zip({{"Gyroscope.csv", gyro_rows(50)}}, false);
  bad[200] = bad[200] == '1' ? '2' : '1';
  const std::string e2 = error_of([&] { read_mem({{"w.zip", bad}}, Format::kSensorLogger); });
  EXPECT_NE(e2.find("CRC-32"), std::string::npos) << e2;
  EXPECT_NE(e2.find("w.zip:Gyroscope.csv"), std::string::npos) << e2;
}

TEST(SensorLoggerBad, MissingSensorFileAndMissingColumn) {
  // no TotalAcceleration: Gyro still read, acceleration without gravity listed as not used
  const Read r = read_mem({{"Metadata.csv", kMetaAndroid}, {"Gyroscope.csv", gyro_rows(3)},
                           {"Accelerometer.csv", gyro_rows(3)}}, Format::kSensorLogger);
  EXPECT_EQ(count_type(r, "Gyro"), 3);
  EXPECT_EQ(count_type(r, "Accel"), 0);
  EXPECT_NE(r.stats.not_used.at("mem/Accelerometer.csv").find("no TotalAcceleration"), std::string::npos);
  // nothing usable at all: an error, not an empty success
  const std::string e = error_of([] { read_mem({{"Metadata.csv", kMetaAndroid}}, Format::kSensorLogger); });
  EXPECT_NE(e.find("no samples"), std::string::npos) << e;
  // a known file without one of its columns: error at its header
  const std::string e2 = error_of([] {
    read_mem({{"Gyroscope.csv", "time,seconds_elapsed,z,y\n1700000000000000000,0,1,2\n"}}, Format::kSensorLogger);
  });
  EXPECT_NE(e2.find("mem/Gyroscope.csv:1: missing column 'x'"), std::string::npos) << e2;
}

TEST(SensorLoggerBad, UnknownColumnIsListedAndTheRestRead) {
  std::string g = "time,seconds_elapsed,z,y,x,temperature\n";
  g += "1700000000000000000,0,0.3,0.2,0.1,25\n1700000000010000000,0.01,0.3,0.2,0.1,25\n";
  const Read r = read_mem({{"Gyroscope.csv", g}}, Format::kSensorLogger);
  ASSERT_EQ(count_type(r, "Gyro"), 2);
  EXPECT_EQ(all_of<GyroSample>(r)[0].rate_radps, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(r.stats.not_used.count("mem/Gyroscope.csv column 'temperature'"), 1u);
  EXPECT_EQ(r.stats.skipped_total(), 0);
}

TEST(SensorLoggerBad, TimeGoingBackwardsNaNAndWrongUnits) {
  std::string g = gyro_rows(3);
  g += "1699999999000000000,0.5,0.1,0.1,0.1\n";  // backwards
  g += "1700000000050000000,0.05,NaN,0.1,0.1\n";  // NaN
  g += "1700000000060000000,0.06,abc,0.1,0.1\n";  // not a number
  g += "1700000000070000000,0.07,0.1,0.1\n";      // a field short
  std::string baro = "time,seconds_elapsed,relativeAltitude,pressure\n";
  baro += "1700000000000000000,0,0,947.7744140625\n";
  baro += "1700000000200000000,0.2,0,94.77\n";  // kPa: not a pressure in hPa
  const Read r = read_mem({{"Gyroscope.csv", g}, {"Barometer.csv", baro}}, Format::kSensorLogger);
  EXPECT_EQ(count_type(r, "Gyro"), 3);
  EXPECT_EQ(skipped(r, "time went backwards"), 1);
  EXPECT_EQ(skipped(r, "non-finite value"), 1);
  EXPECT_EQ(skipped(r, "non-numeric value"), 1);
  EXPECT_EQ(skipped(r, "wrong field count"), 1);
  EXPECT_EQ(count_type(r, "Pressure"), 1);
  EXPECT_EQ(skipped(r, "value out of range"), 1);
  EXPECT_EQ(all_of<PressureSample>(r)[0].pressure_pa, 94777.44140625);  // exact decimal shift
  expect_time_ordered(r);
  // strict: the first malformed row is an error with its file and line
  io::SourceOptions strict;
  strict.log.strict = true;
  const std::string e = error_of([&] { read_mem({{"Gyroscope.csv", g}}, Format::kSensorLogger, strict); });
  EXPECT_NE(e.find("mem/Gyroscope.csv:5: time went backwards"), std::string::npos) << e;
}

TEST(SensorLogger, IosConventionsSignAndUnits) {
  // iOS without "Standardise Units & Frames": no TotalAcceleration; user acceleration and
  // gravity in the inertial-force sign (flat on a table: gravity -z); uncalibrated in g
  const std::string meta =
      "version,device name,recording time,platform,appVersion,device id,sensors,sampleRateMs\n"
      "3,iPhone 13,2024-01-01_10-00-00,ios,1.30.0,x,Accelerometer|Gravity,10|10\n";
  const std::string user = "time,seconds_elapsed,z,y,x\n1700000000000000000,0,0.1,0.0,0.2\n1700000000010000000,0.01,0.1,0.0,0.2\n";
  const std::string grav = "time,seconds_elapsed,z,y,x\n1700000000000000000,0,-9.80665,0,0\n1700000000010000000,0.01,-9.80665,0,0\n";
  const std::string uncal = "time,seconds_elapsed,z,y,x\n1700000000000000000,0,-1.0,0.0,0.0\n";
  const Read r = read_mem({{"Metadata.csv", meta}, {"Accelerometer.csv", user}, {"Gravity.csv", grav},
                           {"AccelerometerUncalibrated.csv", uncal}}, Format::kSensorLogger);
  const auto acc = all_of<AccelSample>(r);
  ASSERT_EQ(acc.size(), 2u);
  // Android convention: flat on a table reads +g on z
  EXPECT_NEAR(acc[0].acc_mps2.z(), 9.80665 - 0.1, 1e-12);
  EXPECT_NEAR(acc[0].acc_mps2.x(), -0.2, 1e-12);
  const auto ua = all_of<UncalAccelSample>(r);
  ASSERT_EQ(ua.size(), 1u);
  EXPECT_NEAR(ua[0].acc_mps2.z(), 9.80665, 1e-12);
  // with the standardisation switch on, the Android convention is kept as written
  const std::string meta_std =
      "version,device name,recording time,platform,appVersion,standardisation\n3,iPhone 13,x,ios,1.30.0,true\n";
  const Read s = read_mem({{"Metadata.csv", meta_std}, {"AccelerometerUncalibrated.csv", uncal}}, Format::kSensorLogger);
  EXPECT_NEAR(all_of<UncalAccelSample>(s)[0].acc_mps2.z(), -1.0, 1e-12);
}

TEST(SensorLogger, RecordingFolderIsTheOneWithTheCsvFilesNotTheImages) {
  // a zip of the recording with a Camera/ folder holding more files than the sensor folder
  Files files{{"rec/Metadata.csv", kMetaAndroid}, {"rec/Gyroscope.csv", gyro_rows(4)}};
  for (int i = 0; i < 5; ++i) files.emplace_back("rec/Camera/" + std::to_string(1700000000000 + i) + ".jpg", "\xFF\xD8jpeg");
  const Read r = read_mem({{"rec.zip", test::make_zip(files)}}, Format::kAuto);
  EXPECT_EQ(count_type(r, "Gyro"), 4);
  EXPECT_EQ(r.stats.not_used.at("rec.zip:rec/Camera/1700000000000.jpg"), "outside the recording's folder");
}

TEST(SensorLogger, MergeIsTimeOrderedAcrossFiles) {
  // two files, interleaved times, one sample each 10 ms and 7 ms
  std::string a = "time,seconds_elapsed,z,y,x\n", m = a;
  for (int i = 0; i < 20; ++i) a += std::to_string(1700000000000000000 + i * 10000000LL) + ",0,0,0,9.8\n";
  for (int i = 0; i < 20; ++i) m += std::to_string(1700000000003000000 + i * 7000000LL) + ",0,1,2,3\n";
  const Read r = read_mem({{"TotalAcceleration.csv", a}, {"Magnetometer.csv", m}}, Format::kSensorLogger);
  EXPECT_EQ(r.samples.size(), 40u);
  expect_time_ordered(r);
}

/// A recording with Orientation.csv in a chosen frame convention, and its gravity and field.
struct Attitudes {
  Files files;
  std::vector<Eigen::Matrix3d> enu_from_dev;
};
Attitudes orientation_recording(const Eigen::Matrix3d& world_from_enu, bool inverse, bool garbage = false) {
  Attitudes a;
  std::string o = "time,seconds_elapsed,qz,qy,qx,qw,roll,pitch,yaw\n", g = "time,seconds_elapsed,z,y,x\n", m = g;
  for (int i = 0; i < 200; ++i) {
    const double t = i * 0.02;
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(0.5 * t + 0.3, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(0.2 * std::sin(t), Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(0.1 * std::cos(t), Eigen::Vector3d::UnitY())).toRotationMatrix();
    a.enu_from_dev.push_back(r);
    Eigen::Quaterniond q(world_from_enu * r);
    if (inverse) q = q.conjugate();
    if (garbage) q = Eigen::Quaterniond(std::cos(7.1 * i), std::sin(3.3 * i), std::cos(1.7 * i), std::sin(5.9 * i)).normalized();
    const Eigen::Vector3d gd = r.transpose() * Eigen::Vector3d(0, 0, 9.80665), md = r.transpose() * Eigen::Vector3d(0, 20, -43);
    const std::string ts = std::to_string(1700000000000000000 + i * 20000000LL) + "," + std::to_string(t) + ",";
    char buf[256];
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g,%.17g,0,0,0\n", q.z(), q.y(), q.x(), q.w());
    o += ts + buf;
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g\n", gd.z(), gd.y(), gd.x());
    g += ts + buf;
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g\n", md.z(), md.y(), md.x());
    m += ts + buf;
  }
  a.files = {{"Metadata.csv", kMetaAndroid}, {"Orientation.csv", o}, {"Gravity.csv", g}, {"Magnetometer.csv", m}};
  return a;
}

TEST(SensorLogger, OrientationFrameFoundFromGravityAndFieldThenRotationVectorIsPhoneToEnu) {
  Eigen::Matrix3d nwu;  // x north, y west, z up (an "x-north, z-vertical" frame)
  nwu << 0, 1, 0, -1, 0, 0, 0, 0, 1;
  Eigen::Matrix3d ned;  // x north, y east, z down
  ned << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  for (const auto& [frame, inverse] : {std::pair{Eigen::Matrix3d(Eigen::Matrix3d::Identity()), false},
                                       std::pair{nwu, false}, std::pair{nwu, true}, std::pair{ned, false}}) {
    const Attitudes a = orientation_recording(frame, inverse);
    const Read r = read_mem(a.files, Format::kSensorLogger);
    const auto rv = all_of<RotationVectorSample>(r);
    ASSERT_EQ(rv.size(), a.enu_from_dev.size()) << (r.stats.not_used.count("mem/Orientation.csv") ? r.stats.not_used.at("mem/Orientation.csv") : "");
    for (std::size_t i = 0; i < rv.size(); ++i) {
      const Eigen::Quaterniond q(rv[i].quat_xyzw[3], rv[i].quat_xyzw[0], rv[i].quat_xyzw[1], rv[i].quat_xyzw[2]);
      ASSERT_LT((q.toRotationMatrix() - a.enu_from_dev[i]).norm(), 1e-9) << "row " << i;
    }
    EXPECT_NE(r.info.at("OrientationFrame").find(inverse ? "world->phone" : "phone->world"), std::string::npos);
  }
  // a quaternion unrelated to gravity and field fits no convention: not used, with the figure
  const Read g = read_mem(orientation_recording(nwu, false, true).files, Format::kSensorLogger);
  EXPECT_EQ(count_type(g, "RotationVector"), 0);
  EXPECT_NE(g.stats.not_used.at("mem/Orientation.csv").find("no frame convention fits"), std::string::npos);
}

TEST(SensorLogger, JsonExportReadsLikeTheCsvFiles) {
  // the documented JSON layout: one array, records grouped by sensor, every value a string
  const Files csv = {{"Metadata.csv", kMetaAndroid}, {"Gyroscope.csv", gyro_rows(30)},
                     {"TotalAcceleration.csv", gyro_rows(25, 1700000000004000000, 12000000)}};
  std::string json = "[\n";
  bool first = true;
  for (const auto& [name, text] : csv) {
    std::stringstream in(text);
    std::string header, line;
    std::getline(in, header);
    std::vector<std::string> keys;
    std::stringstream hs(header);
    for (std::string k; std::getline(hs, k, ',');) keys.push_back(k);
    while (std::getline(in, line)) {
      std::stringstream ls(line);
      json += first ? "  {" : ",\n  {";
      first = false;
      json += "\"sensor\": \"" + name.substr(0, name.size() - 4) + "\"";
      std::size_t i = 0;
      for (std::string v; std::getline(ls, v, ','); ++i) json += ", \"" + keys[i] + "\": \"" + v + "\"";
      json += "}";
    }
  }
  json += "\n]\n";
  const Read from_csv = read_mem(csv, Format::kSensorLogger);
  const Read from_json = read_mem({{"export.json", json}}, Format::kAuto);
  EXPECT_EQ(from_json.format, Format::kSensorLogger);
  EXPECT_EQ(count_type(from_json, "Gyro"), 30);
  EXPECT_EQ(count_type(from_json, "Accel"), 25);
  expect_same(from_csv, from_json);
  // truncated, a record without "sensor", a nested value: errors naming the byte
  std::string e = error_of([&] { read_mem({{"export.json", json.substr(0, json.size() / 2)}}, Format::kAuto); });
  EXPECT_NE(e.find("export.json: not a readable Sensor Logger JSON export: JSON byte"), std::string::npos) << e;
  e = error_of([] { read_mem({{"x.json", "[{\"time\": \"1\"}]"}}, Format::kAuto); });
  EXPECT_NE(e.find("without \"sensor\""), std::string::npos) << e;
  e = error_of([] { read_mem({{"x.json", "[{\"sensor\": \"Gyroscope\", \"time\": [1]}]"}}, Format::kAuto); });
  EXPECT_NE(e.find("nested values"), std::string::npos) << e;
}

// ---- phyphox (fixture written from the spec) ----------------------------------------------

TEST(Phyphox, FixtureFolderTimeMappingUnitsAndPause) {
  const std::string dir = kLoggers + "/phyphox-walk";
  const Read r = read_path(dir);
  EXPECT_EQ(r.format, Format::kPhyphox);
  EXPECT_EQ(r.stats.skipped_total(), 0);
  EXPECT_EQ(count_type(r, "Accel"), data_rows(fs::path(dir) / "Accelerometer.csv"));
  EXPECT_EQ(count_type(r, "Gyro"), data_rows(fs::path(dir) / "Gyroscope.csv"));
  EXPECT_EQ(count_type(r, "Mag"), data_rows(fs::path(dir) / "Magnetometer.csv"));
  EXPECT_EQ(count_type(r, "Pressure"), data_rows(fs::path(dir) / "Pressure.csv"));
  EXPECT_EQ(count_type(r, "Fix"), data_rows(fs::path(dir) / "Location.csv"));
  EXPECT_TRUE(r.stats.not_used.count(dir + "/Linear Acceleration.csv"));
  expect_time_ordered(r);
  // meta/time.csv: START 0 s at 1710000000.250, PAUSE at 12 s, START again 20 s of wall time later
  const auto acc = all_of<AccelSample>(r);
  EXPECT_EQ(acc.front().t_ns, 1710000000250000000 + 3700000);  // first row: 3.7 ms experiment time
  for (const AccelSample& a : acc) {
    const double exp_s = (a.t_ns - 1710000000250000000) * 1e-9;
    EXPECT_FALSE(exp_s > 12.0 + 1e-6 && exp_s < 32.0 - 1e-6) << "a sample inside the pause";
  }
  const AccelSample after = *std::find_if(acc.begin(), acc.end(), [](const AccelSample& a) {
    return a.t_ns > 1710000000250000000 + 12000000000;
  });
  EXPECT_EQ(after.t_ns, 1710000000250000000 + 20000000000 + 12003700000);  // experiment 12.0037 s
  EXPECT_EQ(after.utc_ms, after.t_ns / 1000000);
  EXPECT_NEAR(all_of<PressureSample>(r).front().pressure_pa, 94776.9704, 1e-4);  // 947.769704 hPa at 0.074 s
  const FixSample f = all_of<FixSample>(r).front();
  EXPECT_NEAR(f.lat_deg, 47.40726706, 1e-8);
  EXPECT_DOUBLE_EQ(f.accuracy_m, 4.5);
  bool device = false;
  for (const auto& m : all_of<MetaSample>(r)) device |= m.key == "Device" && m.value == "Google Pixel 6a";
  EXPECT_TRUE(device);
}

TEST(Phyphox, SemicolonDecimalCommaAndZipReadTheSame) {
  const Read comma = read_path(kLoggers + "/phyphox-walk");
  expect_same(comma, read_path(kLoggers + "/phyphox-walk-semicolon"));
  const std::string zip = test::make_zip(load_folder(kLoggers + "/phyphox-walk"));
  const Read zipped = read_mem({{"export.zip", zip}}, Format::kAuto);
  EXPECT_EQ(zipped.format, Format::kPhyphox);
  expect_same(comma, zipped);
}

TEST(PhyphoxBad, ExcelRefusedWrongUnitTruncatedNaNBackwardsNoTimeMap) {
  // the Excel export: an .xlsx (a zip holding xl/workbook.xml) or an Excel 97 file
  const std::string xlsx = test::make_zip({{"[Content_Types].xml", "<Types/>"}, {"xl/workbook.xml", "<workbook/>"}});
  std::string e = error_of([&] { read_mem({{"export.zip", xlsx}}, Format::kAuto); });
  EXPECT_NE(e.find("Excel"), std::string::npos) << e;
  EXPECT_NE(e.find("CSV"), std::string::npos) << e;
  const fs::path xls = fs::temp_directory_path() / "pdnav_phyphox_test.xls";
  std::ofstream(xls, std::ios::binary) << std::string("\xD0\xCF\x11\xE0\xA1\xB1\x1A\xE1", 8) << std::string(512, '\0');
  e = error_of([&] { read_path(xls.string()); });
  EXPECT_NE(e.find("Excel 97"), std::string::npos) << e;
  fs::remove(xls);
  // a unit the reader does not know: error at the header
  e = error_of([] {
    read_mem({{"Accelerometer.csv", "\"Time (s)\",\"Acceleration x (ft/s^2)\",\"Acceleration y (ft/s^2)\","
                                    "\"Acceleration z (ft/s^2)\"\n1.0E0,0,0,32\n"}}, Format::kPhyphox);
  });
  EXPECT_NE(e.find("Accelerometer.csv:1: unit 'ft/s^2'"), std::string::npos) << e;
  // truncated last row, NaN padding, time backwards; no meta/time.csv: time since start, UTC unknown
  const std::string acc =
      "\"Time (s)\",\"Acceleration x (m/s^2)\",\"Acceleration y (m/s^2)\",\"Acceleration z (m/s^2)\"\n"
      "1.000000000E-2,0,0,9.8\n2.000000000E-2,0,0,9.8\n1.500000000E-2,0,0,9.8\n3.000000000E-2,NaN,NaN,NaN\n"
      "4.000000000E-2,0,0,9.8\n5.000000000E-2,0,0";
  const Read r = read_mem({{"Accelerometer.csv", acc}}, Format::kPhyphox);
  EXPECT_EQ(count_type(r, "Accel"), 3);
  EXPECT_EQ(skipped(r, "time went backwards"), 1);
  EXPECT_EQ(skipped(r, "NaN (a shorter column's padding)"), 1);
  EXPECT_EQ(skipped(r, "torn last line"), 1);
  EXPECT_EQ(all_of<AccelSample>(r)[0].t_ns, 10000000);
  EXPECT_EQ(all_of<AccelSample>(r)[0].utc_ms, kMissingInt);
  EXPECT_NE(r.info.at("Time").find("UTC unknown"), std::string::npos);
}

// ---- GetSensorData (fixture written from the spec) ----------------------------------------

std::int64_t lines_starting(const std::string& path, const std::string& prefix) {
  std::ifstream in(path);
  std::string l;
  std::int64_t n = 0;
  while (std::getline(in, l)) n += l.rfind(prefix, 0) == 0;
  return n;
}

TEST(GetSensorData, FixtureTypesClocksAndUnits) {
  const std::string path = kLoggers + "/getsensordata-walk.txt";
  const Read r = read_path(path);
  EXPECT_EQ(r.format, Format::kGetSensorData);
  EXPECT_EQ(count_type(r, "Accel"), lines_starting(path, "ACCE;"));
  EXPECT_EQ(count_type(r, "Gyro"), lines_starting(path, "GYRO;"));
  EXPECT_EQ(count_type(r, "Mag"), lines_starting(path, "MAGN;"));
  EXPECT_EQ(count_type(r, "Pressure"), lines_starting(path, "PRES;"));
  EXPECT_EQ(count_type(r, "RotationVector"), lines_starting(path, "AHRS;"));
  EXPECT_EQ(count_type(r, "OrientationDeg"), lines_starting(path, "AHRS;"));
  EXPECT_EQ(count_type(r, "Fix"), lines_starting(path, "GNSS;"));
  EXPECT_EQ(count_type(r, "Truth"), lines_starting(path, "POSI;"));
  // the types the core has no use for are counted skips, by name
  EXPECT_EQ(skipped(r, "line type 'LIGH' not used"), lines_starting(path, "LIGH;"));
  EXPECT_EQ(skipped(r, "line type 'WIFI' not used"), lines_starting(path, "WIFI;"));
  EXPECT_EQ(r.stats.skipped_total(), lines_starting(path, "LIGH;") + lines_starting(path, "WIFI;"));
  // sensor lines keep the sensor clock's spacing (50 Hz: 20 ms) although the app read them
  // with 4-9 ms of jitter; the first line of a type sits at its AppTimestamp
  const auto acc = all_of<AccelSample>(r);
  EXPECT_EQ(acc[0].t_ns, 16000000);
  for (std::size_t i = 1; i < acc.size(); ++i) ASSERT_NEAR(acc[i].t_ns - acc[i - 1].t_ns, 20000000, 1000001) << i;
  EXPECT_NEAR(all_of<PressureSample>(r).front().pressure_pa, 94776.98, 1e-6);  // mbar -> Pa
  const RotationVectorSample q = all_of<RotationVectorSample>(r)[50];
  EXPECT_NEAR(q.quat_xyzw.norm(), 1.0, 1e-12);
  EXPECT_GT(q.quat_xyzw.w(), 0.99);
  const TruthSample t = all_of<TruthSample>(r).front();
  EXPECT_EQ(t.t_ns, 500000000);
  EXPECT_TRUE(std::isnan(t.h_m));
  const FixSample f = all_of<FixSample>(r).front();
  EXPECT_EQ(f.provider, "GPS");
  EXPECT_DOUBLE_EQ(f.accuracy_m, 4.0);
  bool device = false;
  for (const auto& m : all_of<MetaSample>(r)) device |= m.key == "Device" && m.value == "Google Pixel 6a";
  EXPECT_TRUE(device);
}

TEST(GetSensorDataBad, TruncatedNaNBackwardsShortAndUnknown) {
  const std::string text =
      "% LogFile created by the 'GetSensorData' App for Android.\n"
      "ACCE;0.010;100.000;0.1;0.2;9.8;3\n"
      "ACCE;0.030;100.020;0.1;0.2;9.8;3\n"
      "ACCE;0.040;100.010;0.1;0.2;9.8;3\n"   // sensor clock backwards
      "ACCE;0.050;100.040;NaN;0.2;9.8;3\n"   // NaN
      "GYRO;0.060;100.050;0.1;0.2\n"         // a field short
      "PRES;0.070;100.060;94.7;0\n"          // kPa where mbar is specified
      "FOOO;0.080;1;2;3\n"                   // unknown type
      "ACCE;0.090;100.080;0.1;0.2;9.8;3\n"
      "ACCE;0.110;100.100;0.1;0.";          // cut by the end of the file
  const Read r = read_mem({{"log.txt", text}}, Format::kGetSensorData);
  EXPECT_EQ(count_type(r, "Accel"), 3);
  EXPECT_EQ(skipped(r, "time went backwards"), 1);
  EXPECT_EQ(skipped(r, "non-finite value"), 1);
  EXPECT_EQ(skipped(r, "too few fields"), 1);
  EXPECT_EQ(skipped(r, "value out of range"), 1);
  EXPECT_EQ(skipped(r, "line type 'FOOO' not used"), 1);
  EXPECT_EQ(skipped(r, "torn last line"), 1);
  ASSERT_FALSE(r.stats.issues.empty());
  EXPECT_EQ(r.stats.issues[0].to_string().rfind("log.txt:4: time went backwards", 0), 0u) << r.stats.issues[0].to_string();
  // a file of only comments and unknown lines is an error, not an empty success
  const std::string e = error_of([] { read_mem({{"log.txt", "% header\nWIFI;1;2;x;y;2437;-60\n"}}, Format::kGetSensorData); });
  EXPECT_NE(e.find("no samples"), std::string::npos) << e;
}

// ---- the face: detection and wrong input ---------------------------------------------------

TEST(SampleSource, DetectsFormatsFromContentAndRefusesTheRest) {
  EXPECT_EQ(io::detect_format(kWalk), Format::kSensorLogger);
  EXPECT_EQ(io::detect_format(kLoggers + "/phyphox-walk"), Format::kPhyphox);
  EXPECT_EQ(io::detect_format(kLoggers + "/getsensordata-walk.txt"), Format::kGetSensorData);
  EXPECT_EQ(io::detect_format(std::string(PDNAV_TEST_DATA_DIR) + "/logs/pixel7_v3_excerpt.txt"), Format::kGnssLogger);
  const fs::path tmp = fs::temp_directory_path() / "pdnav_not_a_log.txt";
  std::ofstream(tmp) << "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1::/usr/sbin:/usr/sbin/nologin\n";
  const std::string e = error_of([&] { io::open_sample_source(tmp.string()); });
  EXPECT_NE(e.find("expected a pdnav session log"), std::string::npos) << e;
  EXPECT_NE(e.find("found first line 'root:x:0:0"), std::string::npos) << e;
  std::ofstream(tmp, std::ios::trunc) << "% a MATLAB script\nx = 1;\n";  // '%' comments alone are not GetSensorData
  EXPECT_NE(error_of([&] { io::open_sample_source(tmp.string()); }).find("found first line '% a MATLAB script'"), std::string::npos);
  std::ofstream(tmp, std::ios::trunc).flush();
  EXPECT_NE(error_of([&] { io::open_sample_source(tmp.string()); }).find("empty file"), std::string::npos);
  fs::remove(tmp);
  EXPECT_NE(error_of([] { io::open_sample_source("/nonexistent/walk"); }).find("no such file"), std::string::npos);
  const fs::path empty_dir = fs::temp_directory_path() / "pdnav_empty_dir";
  fs::create_directories(empty_dir);
  EXPECT_NE(error_of([&] { io::open_sample_source(empty_dir.string()); }).find("found no files"), std::string::npos);
  fs::remove(empty_dir);
  EXPECT_THROW(io::parse_format("excel"), std::invalid_argument);
  for (const std::string& n : io::format_names()) EXPECT_EQ(io::format_name(io::parse_format(n)), n);
}

TEST(SampleSource, SessionLogThroughTheFaceIsTheLogReaderAndEmptyIsAnError) {
  const std::string path = std::string(PDNAV_TEST_DATA_DIR) + "/logs/mountainview_v1_4_excerpt.txt";
  io::LogReader direct(path);
  Read d;
  Sample s;
  while (direct.next(s)) d.samples.push_back(s);
  const Read f = read_path(path);
  expect_same(d, f);
  EXPECT_EQ(f.stats.skipped_total(), direct.stats().skipped_total());
  // a log with a header and nothing else: no samples is an error
  const std::string e = error_of([] { read_mem({{"x.txt", io::log_header("test")}}, Format::kSession); });
  EXPECT_NE(e.find("no samples"), std::string::npos) << e;
  // unless the caller asks otherwise (the app's replay shows an empty recording as empty)
  io::SourceOptions lenient;
  lenient.require_samples = false;
  EXPECT_TRUE(read_mem({{"x.txt", io::log_header("test")}}, Format::kSession, lenient).samples.empty());
}

}  // namespace
}  // namespace pdnav

namespace pdnav {
namespace {

/// Reads `file` through a named pipe written by a thread: detection sees the bytes once only.
io::ReadStats read_through_fifo(const std::string& file, std::size_t* samples) {
  const fs::path fifo = fs::temp_directory_path() / ("pdnav_fifo_" + std::to_string(::getpid()) + "_" +
                                                     fs::path(file).filename().string());
  fs::remove(fifo);
  EXPECT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string content = slurp(file);
  std::thread writer([&] {
    std::ofstream out(fifo, std::ios::binary);
    out << content;
  });
  auto src = io::open_sample_source(fifo.string());
  Read r = drain(*src);
  writer.join();
  fs::remove(fifo);
  *samples = r.samples.size();
  return r.stats;
}

TEST(SampleSourcePipe, ANamedPipeIsReadOnceWithEveryRowOfTheFile) {
  // the app replays from pipes too (MainActivityRoboTest); format detection used to open the
  // path again after sniffing it, which on a pipe lost the head and then waited for a writer
  for (const std::string file : {std::string(PDNAV_TEST_DATA_DIR) + "/logs/pixel7_v3_excerpt.txt",
                                 kLoggers + "/getsensordata-walk.txt"}) {
    const Read direct = read_path(file);
    std::size_t n = 0;
    const io::ReadStats piped = read_through_fifo(file, &n);
    EXPECT_EQ(n, direct.samples.size()) << file;
    EXPECT_GT(n, 100u) << file;
    EXPECT_EQ(piped.skipped_total(), direct.stats.skipped_total()) << file;
  }
}

}  // namespace
}  // namespace pdnav
