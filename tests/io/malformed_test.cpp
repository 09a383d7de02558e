// Malformed, odd and hostile input: every bad line is skipped and counted with file:line and
// reason (or throws IoError in strict mode); nothing crashes.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "io_test_util.h"
#include "pdnav/io/log_writer.h"
#include "test_data.h"

namespace pdnav {
namespace {

using test::read_text;
using test::skipped;

TEST(Malformed, WrongFieldCountIsSkippedWithFileAndLine) {
  const auto r = read_text("Accel,1000,5000,1,2,3\nAccel,1001,6000,1,2\nAccel,1002,7000,1,2,3,4\nAccel,1003,8000,1,2,3\n");
  EXPECT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(skipped(r.stats, "wrong field count"), 2);
  ASSERT_EQ(r.stats.issues.size(), 2u);
  EXPECT_EQ(r.stats.issues[0].to_string(), "mem:2: wrong field count: Accel has 5 fields, header has 6");
  EXPECT_EQ(r.stats.issues[1].line, 3);
}

TEST(Malformed, NonNumericFieldIsSkipped) {
  const auto r = read_text("Accel,1000,5000,abc,2,3\nGyro,1000,5000,0.1,0x2,3\nMag,1000,5000,1,2,3\n");
  EXPECT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(skipped(r.stats, "non-numeric value"), 2);
  EXPECT_EQ(r.stats.issues[0].to_string(), "mem:1: non-numeric value: AccelXMps2 'abc' is not a number");
}

TEST(Malformed, NanOrInfInATimeIsSkippedButNanInAValueIsMissing) {
  const auto r = read_text("Accel,1000,NaN,1,2,3\nAccel,1000,inf,1,2,3\nAccel,1000,5000.5,1,2,3\n"
                           "Accel,1000,6000,NaN,,Infinity\n");
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(skipped(r.stats, "invalid time"), 3);
  const auto& a = std::get<AccelSample>(r.samples[0]);
  EXPECT_TRUE(std::isnan(a.acc_mps2.x()));
  EXPECT_TRUE(std::isnan(a.acc_mps2.y()));
  EXPECT_TRUE(std::isinf(a.acc_mps2.z()));
}

TEST(Malformed, TimeGoingBackwardsWithinATypeIsSkippedEqualTimesKept) {
  const std::string text = "Accel,1,7000,1,2,3\nGyro,1,1000,1,2,3\nAccel,1,6000,1,2,3\nAccel,1,7000,1,2,3\n";
  const auto r = read_text(text);
  EXPECT_EQ(r.samples.size(), 3u);
  EXPECT_EQ(skipped(r.stats, "time went backwards"), 1);
  EXPECT_EQ(r.stats.issues.at(0).line, 3);
  io::LogReaderOptions keep;
  keep.drop_backwards_time = false;
  EXPECT_EQ(read_text(text, keep).samples.size(), 4u);
}

TEST(Malformed, FixProvidersAreSeparateStreams) {
  const auto r = read_text("Fix,GPS,1,2,3,,,,100,,,5000,\nFix,NLP,1,2,3,,,,99,,,4000,\nFix,GPS,1,2,3,,,,98,,,3000,\n");
  EXPECT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(skipped(r.stats, "time went backwards"), 1);
}

TEST(Malformed, UnknownLineTypeIsCountedByNameAndNotMalformed) {
  io::LogReaderOptions strict;
  strict.strict = true;
  const auto r = read_text("NMEA,$GPGGA,1\nFoo,1\nFoo,2\nAccel,1,5000,1,2,3\n", strict);
  EXPECT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(skipped(r.stats, "unknown line type 'NMEA'"), 1);
  EXPECT_EQ(skipped(r.stats, "unknown line type 'Foo'"), 2);
}

TEST(Malformed, ManyDistinctUnknownTypesKeepBoundedStats) {
  std::string text;
  for (int i = 0; i < 500; ++i) text += "T" + std::to_string(i) + ",1\n";
  const auto r = read_text(text);
  EXPECT_LE(r.stats.skipped_by_reason.size(), 65u);
  EXPECT_EQ(r.stats.skipped_total(), 500);
  EXPECT_EQ(r.stats.issues.size(), 100u);  // max_reported_issues
}

TEST(Malformed, TornLastLineIsSkippedEvenIfItWouldParse) {
  auto r = read_text("Accel,1,5000,1,2,3\nAccel,1,6000,1,2");
  EXPECT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(skipped(r.stats, "torn last line"), 1);
  EXPECT_EQ(r.stats.issues.at(0).line, 2);
  r = read_text("Accel,1,5000,1,2,3\nAccel,1,6000,1,2,3");
  EXPECT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(skipped(r.stats, "torn last line"), 1);
}

TEST(Malformed, OverlongLineIsSkippedAndReadingContinues) {
  std::string text = "Meta,1,Key," + std::string(3u << 20, 'x') + "\nAccel,1,5000,1,2,3\n";
  const auto r = read_text(text);
  EXPECT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(skipped(r.stats, "line too long"), 1);
}

TEST(Malformed, EmptyInputIsAnIoErrorNamingTheFile) {
  const auto dir = test::scratch_dir("io_empty");
  const std::string path = (dir / "empty.txt").string();
  std::ofstream(path).close();
  io::LogReader reader(path);
  Sample s;
  try {
    reader.next(s);
    FAIL() << "no IoError";
  } catch (const io::IoError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
    EXPECT_NE(e.reason().find("empty"), std::string::npos);
  }
  EXPECT_FALSE(reader.next(s));  // reported once
}

TEST(Malformed, HeaderOnlyLogIsValidAndEmpty) {
  const auto r = read_text(io::log_header("x"));
  EXPECT_TRUE(r.samples.empty());
  EXPECT_EQ(r.stats.skipped_total(), 0);
}

TEST(Malformed, MissingFileOrDirectoryIsAnIoErrorWithThePath) {
  const std::string path = "/nonexistent/pdnav/log.txt";
  try {
    io::LogReader reader(path);
    FAIL() << "no IoError";
  } catch (const io::IoError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(std::string(e.what()), path + ": cannot open: no such file");
  }
  EXPECT_THROW(io::LogReader(test::scratch_dir("io_dir").string()), io::IoError);
}

TEST(Malformed, StrictModeThrowsAtTheFirstMalformedLine) {
  io::LogReaderOptions strict;
  strict.strict = true;
  try {
    read_text("# Header Description:\nAccel,1,5000,1,2,3\nAccel,1,6000,x,2,3\n", strict, "s.txt");
    FAIL() << "no IoError";
  } catch (const io::IoError& e) {
    EXPECT_EQ(e.file(), "s.txt");
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(std::string(e.what()), "s.txt:3: non-numeric value: AccelXMps2 'x' is not a number");
  }
}

TEST(Malformed, BadPercentEscapeIsSkipped) {
  const auto r = read_text("Meta,1,Device,Pixel%2C 7%25\nMeta,2,Device,bad%G1\nMeta,3,Device,bad%4\n");
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(std::get<MetaSample>(r.samples[0]).value, "Pixel, 7%");
  EXPECT_EQ(skipped(r.stats, "bad percent escape"), 2);
}

TEST(Malformed, ValuesOutOfRangeAreSkipped) {
  const auto r = read_text("Truth,99999999999999999999,1,2,3,4\nNav,1,2,3,4,5,10,1,-1,300\n"
                           "Status,1,2,3,1,99999999999,,,,,,,,,10\n");
  EXPECT_TRUE(r.samples.empty());
  EXPECT_EQ(skipped(r.stats, "invalid time"), 1);
  EXPECT_EQ(skipped(r.stats, "value out of range"), 2);
}

TEST(Malformed, SensorAccuracyOutsideAndroidsValuesIsSkipped) {
  // SensorAccuracy,utcTimeMillis,elapsedRealtimeNanos,SensorType,Accuracy
  const auto r = read_text("SensorAccuracy,1000,5000,2,3\nSensorAccuracy,1000,6000,2,4\n"
                           "SensorAccuracy,1000,7000,0,1\nSensorAccuracy,1000,8000,2,x\n"
                           "SensorAccuracy,1000,9000,2\nSensorAccuracy,1000,9500,2,-1\n");
  ASSERT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(std::get<SensorAccuracySample>(r.samples[0]).sensor_type, 2);
  EXPECT_EQ(std::get<SensorAccuracySample>(r.samples[0]).accuracy, 3);
  EXPECT_EQ(std::get<SensorAccuracySample>(r.samples[1]).accuracy, -1);
  EXPECT_EQ(skipped(r.stats, "value out of range"), 2);
  EXPECT_EQ(skipped(r.stats, "non-numeric value"), 1);
  EXPECT_EQ(skipped(r.stats, "wrong field count"), 1);
  ASSERT_GE(r.stats.issues.size(), 2u);
  EXPECT_EQ(r.stats.issues[0].to_string(), "mem:2: value out of range: Accuracy 4 is not a SENSOR_STATUS (-1..3)");
  EXPECT_EQ(r.stats.issues[1].to_string(), "mem:3: value out of range: SensorType 0 is not an Android sensor type (> 0)");
}

TEST(Malformed, GameRotationVectorHasNoHeadingAccuracyColumn) {
  // like RotationVector but without HeadingAccuracyRad: 7 fields, not 8
  const auto r = read_text("GameRotationVector,1000,5000,0.1,0.2,0.3,0.927\n"
                           "GameRotationVector,1000,6000,0.1,0.2,0.3,0.927,0.05\n"
                           "GameRotationVector,1000,7000,0.1,zz,0.3,0.927\n");
  ASSERT_EQ(r.samples.size(), 1u);
  const auto& q = std::get<GameRotationVectorSample>(r.samples[0]);
  EXPECT_EQ(q.t_ns, 5000);
  EXPECT_EQ(q.quat_xyzw[3], 0.927);
  EXPECT_EQ(skipped(r.stats, "wrong field count"), 1);
  EXPECT_EQ(skipped(r.stats, "non-numeric value"), 1);
}

TEST(Time, LinesWithOnlyUtcWaitForAnOffsetThenMapThroughIt) {
  // Status has UnixTimeMillis only (GnssLogger): before any sensor line there is no base.
  const std::string status = "# Status,UnixTimeMillis,SignalCount,SignalIndex,ConstellationType,Svid,"
                             "CarrierFrequencyHz,Cn0DbHz,AzimuthDegrees,ElevationDegrees,UsedInFix,"
                             "HasAlmanacData,HasEphemerisData,BasebandCn0DbHz\n";
  const auto r = read_text(status + "Status,1000000,30,0,1,5,1575420030,30,120,45,1,1,1,25\n"
                                    "Accel,1000500,77000000000,0,0,9.8\n"
                                    "Status,1001000,30,0,1,5,1575420030,30,120,45,1,0,1,25\n");
  ASSERT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(skipped(r.stats, "no elapsed-time base yet"), 1);
  const auto& st = std::get<GnssStatusSample>(r.samples[1]);
  EXPECT_EQ(st.t_ns, 77000000000 + 500 * kNsPerMs);  // offset = elapsed - utc of the Accel line
  EXPECT_TRUE(st.used_in_fix);
  EXPECT_FALSE(st.has_almanac);
  EXPECT_EQ(st.svid, 5);
}

TEST(Time, GnssLoggerNavLinesTakeTheLatestSampleTime) {
  const auto r = read_text("# Nav,Svid,Type,Status,MessageId,Sub-messageId,Data(Bytes)\n"
                           "Nav,3,257,1,17,2,1,2\n"
                           "Accel,1,5000,1,2,3\n"
                           "Nav,5,257,1,0,3,-117,-128,127,0,255\n"
                           "Nav,6,257,1,0,3\n");
  ASSERT_EQ(r.samples.size(), 3u);
  EXPECT_EQ(skipped(r.stats, "no elapsed-time base yet"), 1);
  const auto& nav = std::get<NavMessageSample>(r.samples[1]);
  EXPECT_EQ(nav.t_ns, 5000);
  EXPECT_EQ(nav.svid, 5);
  EXPECT_EQ(nav.sub_message_id, 3);
  EXPECT_EQ(nav.data, (std::vector<std::uint8_t>{0x8B, 0x80, 0x7F, 0x00, 0xFF}));
  EXPECT_TRUE(std::get<NavMessageSample>(r.samples[2]).data.empty());
}

TEST(Header, ColumnsAreFoundByNameInAnyOrderWithAliasesAndUnknownsIgnored) {
  const auto r = read_text(
      "#   Accel, elapsedRealtimeNanos ,Foo,AccelZMps2,AccelXMps2,AccelYMps2,UTCTIMEMILLIS\n"
      "Accel,5000,junk,3,1,2,1234\n"
      "# Fix,Provider,Latitude,Longitude,Altitude,Speed,Accuracy,(UTC)TimeInMs,elapsedRealtimeNanos\n"
      "Fix,gps,37.5,-122.25,-19.5,0.5,4.0,1471902356999,6000\n");
  ASSERT_EQ(r.samples.size(), 2u) << (r.stats.issues.empty() ? "" : r.stats.issues[0].to_string());
  const auto& a = std::get<AccelSample>(r.samples[0]);
  EXPECT_EQ(a.t_ns, 5000);
  EXPECT_EQ(a.utc_ms, 1234);
  EXPECT_EQ(a.acc_mps2, Eigen::Vector3d(1, 2, 3));
  const auto& f = std::get<FixSample>(r.samples[1]);
  EXPECT_EQ(f.lat_deg, 37.5);
  EXPECT_EQ(f.lon_deg, -122.25);
  EXPECT_EQ(f.alt_m, -19.5);
  EXPECT_EQ(f.speed_mps, 0.5);
  EXPECT_EQ(f.accuracy_m, 4.0);
  EXPECT_EQ(f.utc_ms, 1471902356999);
  EXPECT_EQ(f.t_ns, 6000);
}

TEST(Header, InfoLinesBecomeKeyValuePairs) {
  io::LogReader reader(std::make_unique<std::istringstream>(
                           "# Header Description:\n#\n# Version: v3.0.6.4 Platform: 14 Manufacturer: Google Model: Pixel 7\n"
                           "# Device: Pixel 7 Pro\nAccel,1,5000,1,2,3\n"),
                       "mem");
  Sample s;
  while (reader.next(s)) {
  }
  const auto& h = reader.header_info();
  EXPECT_EQ(h.at("Version"), "v3.0.6.4");
  EXPECT_EQ(h.at("Platform"), "14");
  EXPECT_EQ(h.at("Model"), "Pixel 7");
  EXPECT_EQ(h.at("Device"), "Pixel 7 Pro");
  EXPECT_EQ(h.count("Description"), 0u);
}

TEST(Header, BinaryGarbageNeverCrashes) {
  std::string junk;
  std::uint64_t x = 88172645463325252ull;  // xorshift64, fixed seed
  for (int i = 0; i < 200000; ++i) {
    x ^= x << 13; x ^= x >> 7; x ^= x << 17;
    const char pool[] = "Raw,Fix,Nav,Accel,Meta,#%\n\r0123456789.e-+ NaN";
    junk.push_back((x >> 60) < 12 ? pool[x % (sizeof pool - 1)] : static_cast<char>(x & 0xFF));
  }
  const auto r = read_text(junk);
  EXPECT_GT(r.stats.lines, 0);
  EXPECT_EQ(r.stats.samples + r.stats.skipped_total() <= r.stats.lines, true);
}

}  // namespace
}  // namespace pdnav
