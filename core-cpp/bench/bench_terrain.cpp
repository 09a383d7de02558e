// Terrain particle filter throughput: nanoseconds per particle per step (propagate + DEM
// lookup + weight + resample when Neff < N/2) at 500 .. 1M particles, per resampling scheme.
// Reported counters: ns_per_particle_step, bytes_per_particle. Run in a Release build:
//   build/release/bench/bench_terrain --benchmark_counters_tabular=true
// Instructions per particle-step (load-independent), docs/terrain.md "Speed":
//   valgrind --tool=callgrind --toggle-collect='pdnav::terrain::TerrainEngine::feed(pdnav::PdrStep const&)'
//     build/release/bench/bench_terrain --benchmark_filter='^BM_TerrainStep_Multinomial/1000$'
//   then Ir (PROGRAM TOTALS) / (calls of feed x particles).
#include <cmath>
#include <memory>

#include <benchmark/benchmark.h>

#include "pdnav/geo/baro.h"
#include "pdnav/terrain/terrain_engine.h"
#include "walk_fixtures.h"

namespace {

using namespace pdnav;
using namespace pdnav::terrain;

std::shared_ptr<const Dem> bench_dem() {
  static const auto dem = test::bench_hills_dem();
  return dem;
}

void run(benchmark::State& state, Resampling scheme, bool with_estimate = false) {
  TerrainOptions o = TerrainOptions::srtm_tuned();
  o.particles = static_cast<int>(state.range(0));
  o.resampling = scheme;
  o.update_distance_m = 0.0;  // measurement update on every step: the worst case
  TerrainEngine pf(o, bench_dem(), 1);
  pf.initialize(bench_dem()->to_geodetic(0, 0), 5.0, 0);
  TimeNs t = 0;
  double e = 0, n = 0, heading = 0.3;
  for (auto _ : state) {
    t += 550 * kNsPerMs;
    heading += 0.002;
    e += 0.7 * std::sin(heading);
    n += 0.7 * std::cos(heading);
    PressureSample p;
    p.t_ns = t - kNsPerMs;
    p.pressure_pa = geo::baro_pressure_pa(bench_dem()->at_local(e, n).elevation_m, 101325.0, 0.0);
    pf.feed(p);
    PdrStep s;
    s.t_ns = t;
    s.length_m = 0.7;
    s.heading_rad = heading;
    pf.feed(s);
    if (with_estimate) benchmark::DoNotOptimize(pf.estimate());  // the Navigator asks after every sample
  }
  const double particle_steps = static_cast<double>(state.iterations()) * static_cast<double>(o.particles);
  state.counters["ns_per_particle_step"] =
      benchmark::Counter(particle_steps, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["bytes_per_particle"] = static_cast<double>(TerrainEngine::bytes_per_particle());
  state.counters["resample_fraction"] =
      static_cast<double>(pf.stats().resamples) / static_cast<double>(std::max<std::int64_t>(1, pf.stats().steps));
}

void BM_TerrainStep_Multinomial(benchmark::State& s) { run(s, Resampling::kMultinomial); }
void BM_TerrainStep_Systematic(benchmark::State& s) { run(s, Resampling::kSystematic); }
void BM_TerrainStep_Stratified(benchmark::State& s) { run(s, Resampling::kStratified); }
// The app's cost: a step plus the estimate (mean, covariance, the mode search and the
// status), at the Navigator's 500 particles and beyond.
void BM_TerrainStepAndEstimate(benchmark::State& s) { run(s, Resampling::kMultinomial, true); }

// 500: the Navigator's default count (docs/terrain.md).
BENCHMARK(BM_TerrainStep_Multinomial)->Arg(500)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TerrainStep_Systematic)->Arg(500)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TerrainStepAndEstimate)->Arg(500)->Arg(2000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TerrainStep_Stratified)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMicrosecond);

}  // namespace
