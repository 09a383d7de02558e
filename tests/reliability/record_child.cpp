// Test-only recorder for the SIGKILL test (recording_test.cpp): records a session through
// io::LogWriter like the app does, with sample times tied to the wall clock (CLOCK_MONOTONIC,
// like Android's elapsedRealtimeNanos), until it is killed.
//
//   reliability_record_child <log path> <max seconds>
//
// Progress goes to stdout (the parent's pipe), one line per written batch, with write(2) so
// nothing sits in a stdio buffer when SIGKILL arrives:
//   "T0 <t0_ns>"    once, before the first sample (stream k of each type is due at t0 + k*period)
//   "W <t_ns>"      after LogWriter::write() returned for every sample with time <= t_ns
// Exits 0 after <max seconds> (a safety net; the test always kills it before).
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "pdnav/io/log_writer.h"
#include "record_streams.h"

namespace {

using pdnav::TimeNs;
using pdnav::reliability::Stream;

TimeNs monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * pdnav::kNsPerS + ts.tv_nsec;
}

void report(const std::string& line) {
  const std::string s = line + "\n";
  std::size_t done = 0;
  while (done < s.size()) {
    const ssize_t n = ::write(STDOUT_FILENO, s.data() + done, s.size() - done);
    if (n <= 0) std::exit(3);  // parent gone
    done += static_cast<std::size_t>(n);
  }
}

struct Due {
  TimeNs t_ns;
  int stream;
  std::int64_t k;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <log path> <max seconds>\n", argv[0]);
    return 2;
  }
  const TimeNs max_ns = static_cast<TimeNs>(std::atof(argv[2]) * 1e9);
  pdnav::io::LogWriterOptions opt;
  opt.flush_interval_ns = pdnav::kNsPerS;
  opt.device = "reliability_record_child";
  pdnav::io::LogWriter writer(argv[1], opt);

  const TimeNs t0 = monotonic_ns() / pdnav::kNsPerMs * pdnav::kNsPerMs;
  report("T0 " + std::to_string(t0));
  std::array<std::int64_t, pdnav::reliability::kStreamCount> next_k{};
  std::vector<Due> due;
  for (;;) {
    const TimeNs now = monotonic_ns();
    if (now - t0 > max_ns) break;
    due.clear();
    for (int s = 0; s < pdnav::reliability::kStreamCount; ++s) {
      const TimeNs period = pdnav::reliability::stream_period_ns(static_cast<Stream>(s));
      for (; t0 + next_k[s] * period <= now; ++next_k[s]) due.push_back({t0 + next_k[s] * period, s, next_k[s]});
    }
    // one time-ordered stream, as the app's sensor thread hands it to the writer
    std::sort(due.begin(), due.end(), [](const Due& a, const Due& b) {
      return a.t_ns != b.t_ns ? a.t_ns < b.t_ns : a.stream < b.stream;
    });
    for (const Due& d : due) {
      const auto stream = static_cast<Stream>(d.stream);
      const int n = stream == Stream::kGnssRaw ? pdnav::reliability::kRawPerEpoch : 1;
      for (int sat = 0; sat < n; ++sat) writer.write(pdnav::reliability::stream_sample(stream, d.k, d.t_ns, sat));
    }
    if (!due.empty()) report("W " + std::to_string(due.back().t_ns));
    timespec nap{0, 2'000'000};
    nanosleep(&nap, nullptr);
  }
  writer.close();
  return 0;
}
