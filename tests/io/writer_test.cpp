// LogWriter: crash safety (SIGKILL loses at most flush_interval of sample time, never tears a
// line), flush cadence, errors surfaced as IoError.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "io_test_util.h"
#include "pdnav/io/log_format.h"
#include "pdnav/io/log_writer.h"
#include "test_data.h"

namespace pdnav {
namespace {

Sample accel_at(int i) {
  AccelSample a;
  a.t_ns = 1'000'000'000 + TimeNs{i} * 10'000'000;  // 100 Hz
  a.utc_ms = 1'700'000'000'000 + i * 10;
  a.acc_mps2 = Eigen::Vector3d(0.001 * i, -0.5, 9.80665 + 1e-9 * i);
  return a;
}

std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::int64_t sample_lines_on_disk(const std::string& path) {
  const std::string t = file_text(path);
  std::int64_t n = 0;
  std::size_t start = 0;
  while (start < t.size()) {
    const std::size_t nl = t.find('\n', start);
    if (nl == std::string::npos) break;
    if (t[start] != '#') ++n;
    start = nl + 1;
  }
  return n;
}

TEST(LogWriter, HandsLinesToTheOsAtLeastEveryFlushIntervalOfSampleTime) {
  const std::string path = (test::scratch_dir("io_writer_flush") / "log.txt").string();
  io::LogWriterOptions opt;
  opt.flush_interval_ns = kNsPerS;
  io::LogWriter w(path, opt);
  EXPECT_EQ(file_text(path), io::log_header());  // the header is on disk at once
  for (int i = 0; i < 500; ++i) {
    w.write(accel_at(i));
    // every sample at least one interval older than the newest is on disk, as whole lines
    const std::int64_t must = std::max(0, i - 100 + 1);
    const std::int64_t on_disk = sample_lines_on_disk(path);
    ASSERT_GE(on_disk, must) << "after sample " << i;
    ASSERT_LE(on_disk, i + 1);
    ASSERT_EQ(file_text(path).back(), '\n');
  }
  w.close();
  EXPECT_EQ(sample_lines_on_disk(path), 500);
}

TEST(LogWriter, SigkillLosesAtMostTheLastSecondAndNeverTearsALine) {
  const std::string path = (test::scratch_dir("io_writer_kill") / "log.txt").string();
  constexpr int kSamples = 1000;  // 10 s at 100 Hz
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    io::LogWriter w(path);
    for (int i = 0; i < kSamples; ++i) w.write(accel_at(i));
    raise(SIGKILL);  // no close, no destructor, no atexit
    _exit(3);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGKILL);
  const test::ReadResult r = test::read_text(file_text(path));
  EXPECT_EQ(r.stats.skipped_total(), 0);
  EXPECT_GE(static_cast<int>(r.samples.size()), kSamples - 100);
  for (std::size_t i = 0; i < r.samples.size(); ++i)
    ASSERT_TRUE(io::same_sample(r.samples[i], accel_at(static_cast<int>(i)))) << i;
}

TEST(LogWriter, DestructorFlushesEverything) {
  const std::string path = (test::scratch_dir("io_writer_dtor") / "log.txt").string();
  {
    io::LogWriterOptions opt;
    opt.fsync_on_flush = true;
    opt.device = "Pixel 7\nsecond line";
    io::LogWriter w(path, opt);
    for (int i = 0; i < 50; ++i) w.write(accel_at(i));
  }
  io::LogReader reader(path);
  Sample s;
  int n = 0;
  while (reader.next(s)) ++n;
  EXPECT_EQ(n, 50);
  EXPECT_EQ(reader.header_info().at("Device"), "Pixel 7 second line");
  EXPECT_EQ(reader.header_info().at("Version"), "pdnav-log 1");
}

TEST(LogWriter, DiskFullIsAnIoErrorNeverSilent) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "/dev/full not available";
  try {
    io::LogWriter w("/dev/full");
    FAIL() << "no IoError";
  } catch (const io::IoError& e) {
    EXPECT_EQ(e.file(), "/dev/full");
    EXPECT_NE(e.reason().find("write failed"), std::string::npos) << e.what();
  }
}

TEST(LogWriter, UncreatableFileAndWriteAfterCloseAreIoErrors) {
  EXPECT_THROW(io::LogWriter("/nonexistent/dir/log.txt"), io::IoError);
  const std::string path = (test::scratch_dir("io_writer_closed") / "log.txt").string();
  io::LogWriter w(path);
  w.write(accel_at(0));
  w.close();
  w.close();  // idempotent
  EXPECT_THROW(w.write(accel_at(1)), io::IoError);
}

TEST(LogWriter, StreamWriterWritesHeaderThenFormatLineOfEachSample) {
  auto out = std::make_unique<std::ostringstream>();
  std::ostringstream* raw = out.get();
  io::LogWriter w(std::move(out), "mem");
  w.write(accel_at(0));
  MetaSample m;
  m.t_ns = 5;
  m.key = "UserHeightMeters";
  m.value = "1.80";
  w.write(m);
  w.flush();
  EXPECT_EQ(raw->str(), io::log_header() + io::format_line(accel_at(0)) + "\n" + "Meta,5,UserHeightMeters,1.80\n");
  // moving keeps the writer usable
  io::LogWriter moved = std::move(w);
  moved.write(m);
  moved.close();
  EXPECT_EQ(moved.lines_written(), 3);
}

}  // namespace
}  // namespace pdnav
