// Throughput of the pdr pipeline on one core: accelerometer + gyro samples per second through
// the step detector, the bout gate, the gyro re-orientation / turn tracker and step output.
// Run: build/<dir>/bench/bench_pdr  (a synthetic 100 Hz walk with turns, tests/pdr/synthetic_imu.h)
#include <benchmark/benchmark.h>

#include "../../tests/pdr/synthetic_imu.h"
#include "pdnav/pdr/pdr.h"
#include "pdnav/pdr/step_detector.h"

namespace {

const pdnav::test::SyntheticWalk& walk() {
  static const pdnav::test::SyntheticWalk w = [] {
    pdnav::test::WalkSpec spec;
    spec.tilt_deg = 30.0;
    spec.final_straight_s = 30.0;
    return pdnav::test::make_walk(spec, {{20, 90}, {20, -45}, {20, 180}});
  }();
  return w;
}

/// Full engine: accel + gyro + rotation vector, steps and turns drained as fusion does.
void BM_PdrEngine(benchmark::State& state) {
  const auto& w = walk();
  for (auto _ : state) {
    pdnav::pdr::Pdr engine;
    std::size_t steps = 0;
    for (std::size_t i = 0; i < w.accel.size(); ++i) {
      engine.feed(w.accel[i]);
      engine.feed(w.gyro[i]);
      engine.feed(w.rotation[i]);
      steps += engine.take_steps().size();
      benchmark::DoNotOptimize(engine.take_turns());
    }
    benchmark::DoNotOptimize(steps);
  }
  // one "sample" = one accel + one gyro + one rotation-vector reading
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(w.accel.size()));
  state.counters["sensor_samples_per_s"] = benchmark::Counter(
      3.0 * static_cast<double>(state.iterations()) * static_cast<double>(w.accel.size()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PdrEngine)->Unit(benchmark::kMillisecond);

/// Step detector alone (APT level crossing + gates).
void BM_StepDetector(benchmark::State& state) {
  const auto& w = walk();
  for (auto _ : state) {
    benchmark::DoNotOptimize(pdnav::pdr::detect_steps(w.accel, pdnav::pdr::StepDetectorOptions{}));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(w.accel.size()));
}
BENCHMARK(BM_StepDetector)->Unit(benchmark::kMillisecond);

/// Gyro re-orientation / turn tracker alone.
void BM_TurnTracker(benchmark::State& state) {
  const auto& w = walk();
  for (auto _ : state) {
    pdnav::pdr::GyroTurnTracker tracker;
    for (std::size_t i = 0; i < w.accel.size(); ++i) {
      tracker.feed(w.accel[i]);
      tracker.feed(w.gyro[i]);
    }
    benchmark::DoNotOptimize(tracker.take_turns());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(w.accel.size()));
}
BENCHMARK(BM_TurnTracker)->Unit(benchmark::kMillisecond);

}  // namespace
