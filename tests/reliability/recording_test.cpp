// SIGKILL recording test (issue 9): a child process records a session through io::LogWriter
// (record_child.cpp) and is killed with SIGKILL at seeded random moments. After each kill the
// log must parse with zero malformed lines (no torn last line either), every line must be
// exactly the sample the child wrote (each stream a gap-free prefix), and the data must reach
// to within the 1 s flush interval (+ 50 ms slack) of the last sample the child reported as
// written before it died.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/io/log_format.h"
#include "pdnav/io/log_reader.h"
#include "record_streams.h"
#include "test_data.h"

extern char** environ;

namespace pdnav::reliability {
namespace {

constexpr TimeNs kFlushInterval_ns = kNsPerS;  // the child's LogWriterOptions::flush_interval_ns
constexpr TimeNs kSlack_ns = 50 * kNsPerMs;    // scheduling slack on top of the flush interval

/// What the child reported through its pipe before it died.
struct ChildReport {
  bool have_t0 = false;
  TimeNs t0_ns = 0;
  bool have_written = false;
  TimeNs last_written_ns = 0;  // every sample with t <= this was handed to LogWriter::write
  int wait_status = 0;
};

TimeNs monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

void parse_reports(const std::string& text, ChildReport& r) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (in.eof()) break;  // an incomplete last line (cut by the kill) is not a report
    if (line.rfind("T0 ", 0) == 0) {
      r.have_t0 = true;
      r.t0_ns = std::stoll(line.substr(3));
    } else if (line.rfind("W ", 0) == 0) {
      r.have_written = true;
      r.last_written_ns = std::stoll(line.substr(2));
    }
  }
}

/// Starts the recorder on `log_path`, reads its pipe for `run_ms`, then SIGKILLs it
/// (kill_it = false: lets it run to its own end after max_s seconds).
ChildReport run_child(const std::string& log_path, int run_ms, bool kill_it, double max_s = 30.0) {
  int fds[2];
  EXPECT_EQ(pipe(fds), 0);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_addclose(&actions, fds[1]);
  const std::string exe = PDNAV_RECORD_CHILD;
  const std::string max_arg = std::to_string(max_s);
  std::vector<char*> argv = {const_cast<char*>(exe.c_str()), const_cast<char*>(log_path.c_str()),
                             const_cast<char*>(max_arg.c_str()), nullptr};
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  EXPECT_EQ(rc, 0) << "cannot start " << exe;
  std::string text;
  char buf[4096];
  const TimeNs deadline = monotonic_ns() + static_cast<TimeNs>(run_ms) * kNsPerMs;
  for (;;) {
    const TimeNs left_ns = deadline - monotonic_ns();
    if (kill_it && left_ns <= 0) break;
    pollfd p{fds[0], POLLIN, 0};
    const int timeout_ms = kill_it ? static_cast<int>(left_ns / kNsPerMs) + 1 : 1000;
    if (poll(&p, 1, timeout_ms) > 0) {
      const ssize_t n = read(fds[0], buf, sizeof buf);
      if (n <= 0) break;  // child closed its end (exited)
      text.append(buf, static_cast<std::size_t>(n));
    }
  }
  ChildReport r;
  if (kill_it) kill(pid, SIGKILL);
  waitpid(pid, &r.wait_status, 0);
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
  close(fds[0]);
  parse_reports(text, r);
  return r;
}

int stream_of(const Sample& s) {
  switch (s.index()) {
    case 0: return static_cast<int>(Stream::kAccel);
    case 1: return static_cast<int>(Stream::kGyro);
    case 2: return static_cast<int>(Stream::kMag);
    case 7: return static_cast<int>(Stream::kPressure);
    case 8: return static_cast<int>(Stream::kRotationVector);
    case 11: return static_cast<int>(Stream::kGnssRaw);
    case 12: return static_cast<int>(Stream::kFix);
    default: return -1;
  }
}

std::string file_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// Parses the log the killed child left and checks it against what the child reported.
/// Returns the number of samples found.
std::int64_t check_log(const std::string& path, const ChildReport& r) {
  const std::string bytes = file_bytes(path);
  if (!bytes.empty()) {
    EXPECT_EQ(bytes.back(), '\n') << path << ": torn last line";
  }
  if (bytes.empty()) {
    EXPECT_FALSE(r.have_written) << path << ": empty although samples were reported written";
    return 0;
  }
  io::LogReader reader(path);
  std::array<std::int64_t, kStreamCount> count{};
  TimeNs last_t_ns = 0;
  std::int64_t n = 0;
  for (Sample s; reader.next(s); ++n) {
    const int st = stream_of(s);
    if (st < 0) {
      ADD_FAILURE() << path << ": unexpected line type " << io::line_type_name(s);
      continue;
    }
    EXPECT_TRUE(r.have_t0) << path << ": samples but no T0 report";
    const auto stream = static_cast<Stream>(st);
    const std::int64_t i = count[static_cast<std::size_t>(st)]++;
    const bool raw = stream == Stream::kGnssRaw;
    const std::int64_t k = raw ? i / kRawPerEpoch : i;
    const int sat = raw ? static_cast<int>(i % kRawPerEpoch) : 0;
    const Sample want = stream_sample(stream, k, r.t0_ns + k * stream_period_ns(stream), sat);
    if (!io::same_sample(s, want)) {
      ADD_FAILURE() << path << ": " << stream_name(stream) << " line #" << i << " at t=" << sample_time_ns(s)
                    << " is not the sample written (want t=" << sample_time_ns(want) << ")";
      break;
    }
    last_t_ns = std::max(last_t_ns, sample_time_ns(s));
  }
  const io::ReadStats& st = reader.stats();
  EXPECT_EQ(st.skipped_total(), 0) << path << ": malformed lines, first: "
                                   << (st.issues.empty() ? std::string("-") : st.issues.front().to_string());
  if (r.have_written && r.last_written_ns - kFlushInterval_ns - kSlack_ns >= r.t0_ns) {
    EXPECT_GE(last_t_ns, r.last_written_ns - kFlushInterval_ns - kSlack_ns)
        << path << ": lost " << ns_to_s(r.last_written_ns - last_t_ns) << " s of data (allowed: 1 s + slack)";
  }
  return n;
}

class SigkillRecording : public ::testing::TestWithParam<int> {};

// 4 batches x 6 kills = 24 kills at seeded random moments between 5 ms and 1.7 s after the
// start (so before the first flush, around it and after it). Batches run as separate ctest
// entries, in parallel under ctest -j2.
TEST_P(SigkillRecording, KilledRecorderLeavesAParsableLogLosingAtMostOneSecond) {
  const int batch = GetParam();
  std::mt19937_64 rng(0x5151'0000u + static_cast<unsigned>(batch));
  std::uniform_int_distribution<int> kill_ms(5, 1700);
  const auto dir = test::scratch_dir("reliability_sigkill_" + std::to_string(batch));
  std::int64_t total = 0;
  for (int i = 0; i < 6; ++i) {
    const std::string path = (dir / ("kill_" + std::to_string(i) + ".log")).string();
    const int ms = kill_ms(rng);
    const ChildReport r = run_child(path, ms, true);
    ASSERT_TRUE(WIFSIGNALED(r.wait_status) && WTERMSIG(r.wait_status) == SIGKILL)
        << "child did not die by SIGKILL after " << ms << " ms (status " << r.wait_status << ")";
    SCOPED_TRACE("kill after " + std::to_string(ms) + " ms");
    total += check_log(path, r);
  }
  EXPECT_GT(total, 0) << "no kill left any sample: the test did not exercise the writer";
}

INSTANTIATE_TEST_SUITE_P(Batches, SigkillRecording, ::testing::Values(0, 1, 2, 3));

// A recorder that ends by itself closes the log: everything it reported is there.
TEST(Recording, CleanExitKeepsEverySample) {
  const auto dir = test::scratch_dir("reliability_clean_exit");
  const std::string path = (dir / "clean.log").string();
  const ChildReport r = run_child(path, 0, false, 1.3);
  ASSERT_TRUE(WIFEXITED(r.wait_status) && WEXITSTATUS(r.wait_status) == 0) << "status " << r.wait_status;
  ASSERT_TRUE(r.have_written);
  const std::int64_t n = check_log(path, r);
  // 1.3 s at 200+200+50+50+25 Hz + GNSS: well over 600 lines, and the very last one present
  EXPECT_GT(n, 600);
  io::LogReader reader(path);
  TimeNs last = 0;
  for (Sample s; reader.next(s);) last = std::max(last, sample_time_ns(s));
  EXPECT_EQ(last, r.last_written_ns);
}

}  // namespace
}  // namespace pdnav::reliability
