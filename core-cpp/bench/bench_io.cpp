// Session log throughput: lines/s read (LogReader) and written (LogWriter, format_line).
// A phone-like mix: Accel, Gyro, Mag at 100 Hz, Pressure at 25 Hz, 30 Raw lines per second.
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "pdnav/io/log_reader.h"
#include "pdnav/io/log_writer.h"
#include "pdnav/io/sample_source.h"

namespace {
using namespace pdnav;

GnssRawSample raw_line(int i, TimeNs t) {
  GnssRawSample r;
  r.t_ns = t;
  r.utc_ms = 1'699'400'594'000 + t / kNsPerMs;
  r.time_nanos = 61'090'000'000 + t;
  r.full_bias_nanos = -1383435750910273353;
  r.bias_nanos = 0.0;
  r.bias_uncertainty_nanos = 6.979524800095384;
  r.svid = i % 32 + 1;
  r.state = 16431;
  r.received_sv_time_nanos = 258211922049091 + i;
  r.received_sv_time_uncertainty_nanos = 40;
  r.cn0_dbhz = 28.924739837646484;
  r.pseudorange_rate_mps = 673.7922380838304;
  r.pseudorange_rate_uncertainty_mps = 0.8101946432987757;
  r.accumulated_delta_range_state = 16;
  r.accumulated_delta_range_m = 40099.90686538701;
  r.accumulated_delta_range_uncertainty_m = 3.4028234663852886e38;
  r.carrier_frequency_hz = 1575420030;
  r.constellation_type = 1;
  r.baseband_cn0_dbhz = 25.324739456176758;
  r.code_type = "C";
  r.chipset_elapsed_realtime_nanos = t;
  return r;
}

/// One second of phone recording per step: 100 x (Accel, Gyro, Mag), 25 Pressure, 30 Raw.
std::vector<Sample> phone_samples(int seconds) {
  std::vector<Sample> out;
  for (int s = 0; s < seconds; ++s) {
    for (int k = 0; k < 100; ++k) {
      const TimeNs t = s * kNsPerS + k * 10'000'000;
      const std::int64_t utc = 1'699'400'594'000 + t / kNsPerMs;
      out.push_back(AccelSample{t, utc, Eigen::Vector3d(0.15553348 + k * 1e-3, 1.1874382, 9.695319)});
      out.push_back(GyroSample{t, utc, Eigen::Vector3d(0.36483926, -0.033750303, 0.05467244 * k)});
      out.push_back(MagSample{t, utc, Eigen::Vector3d(-68.1492, -103.2242, -155.2694)});
      if (k % 4 == 0) out.push_back(PressureSample{t, utc, 101213.4375 + k});
      if (k == 50)
        for (int i = 0; i < 30; ++i) out.push_back(raw_line(i, t));
    }
  }
  return out;
}

std::string phone_log(int seconds) {
  std::string text = io::log_header("bench");
  for (const Sample& s : phone_samples(seconds)) text += io::format_line(s) + "\n";
  return text;
}

void BM_ReadPhoneLog(benchmark::State& state) {
  const std::string text = phone_log(60);
  std::int64_t lines = 0;
  for (auto _ : state) {
    io::LogReader reader(std::make_unique<std::istringstream>(text), "bench");
    Sample s;
    std::int64_t n = 0;
    while (reader.next(s)) ++n;
    benchmark::DoNotOptimize(n);
    lines += n;
  }
  state.SetItemsProcessed(lines);  // items/s = lines/s
  state.SetBytesProcessed(static_cast<std::int64_t>(text.size()) * state.iterations());
}
BENCHMARK(BM_ReadPhoneLog)->Unit(benchmark::kMillisecond);

// The same log through open_memory_source, i.e. through the time-ordering of motion samples that
// every replay reads (a log in time order passes straight through it).
void BM_ReadPhoneLogInTimeOrder(benchmark::State& state) {
  const std::string text = phone_log(60);
  std::int64_t lines = 0;
  for (auto _ : state) {
    auto src = io::open_memory_source({{"bench.txt", text}}, "bench", io::Format::kSession);
    Sample s;
    std::int64_t n = 0;
    while (src->next(s)) ++n;
    benchmark::DoNotOptimize(n);
    lines += n;
  }
  state.SetItemsProcessed(lines);
  state.SetBytesProcessed(static_cast<std::int64_t>(text.size()) * state.iterations());
}
BENCHMARK(BM_ReadPhoneLogInTimeOrder)->Unit(benchmark::kMillisecond);

void BM_WritePhoneLog(benchmark::State& state) {
  const std::vector<Sample> samples = phone_samples(60);
  for (auto _ : state) {
    io::LogWriter w("/dev/null");  // real write(2) calls, 1 s flush interval
    for (const Sample& s : samples) w.write(s);
    w.close();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(samples.size()) * state.iterations());
}
BENCHMARK(BM_WritePhoneLog)->Unit(benchmark::kMillisecond);

void BM_FormatAccelLine(benchmark::State& state) {
  const Sample s = AccelSample{16175331060713, 1699400633245, Eigen::Vector3d(0.15553348, 1.1874382, 10.695319)};
  for (auto _ : state) benchmark::DoNotOptimize(io::format_line(s));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FormatAccelLine);

void BM_FormatRawLine(benchmark::State& state) {
  const Sample s = raw_line(3, 16136559319000);
  for (auto _ : state) benchmark::DoNotOptimize(io::format_line(s));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FormatRawLine);

}  // namespace
