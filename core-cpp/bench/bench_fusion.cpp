// Replay speed of the fused Navigator (issue 14 bar: >= 1000x real time for a 1 h session with
// 500 particles on one core). One iteration replays a synthetic 1 h walk through a fresh
// Navigator (kAuto: PDR, terrain engine with 500 particles on a 12 x 12 km DEM, the fused
// filter): accelerometer and gyro at 50 Hz, rotation vector and Android step events per step,
// pressure at 5 Hz, a chipset Fix every second with a 10 minute outage. (No Raw rows: the GNSS
// engine's own cost is in bench_gnss; no walkway graph.) Counter: realtime_factor.
//   build/release/bench/bench_fusion --benchmark_counters_tabular=true
#include <cmath>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>

#include "pdnav/fusion/navigator.h"
#include "pdnav/geo/baro.h"
#include "pdnav/terrain/dem.h"
#include "walk_fixtures.h"

namespace {

using namespace pdnav;

std::vector<Sample> session(const terrain::Dem& dem, double duration_s) {
  std::vector<Sample> out;
  MetaSample m;
  m.t_ns = kNsPerS / 2;
  m.key = "StartLatitudeDegrees";
  m.value = "42.5";
  out.push_back(m);
  m.key = "StartLongitudeDegrees";
  m.value = "1.5";
  out.push_back(m);
  const geo::LocalFrame frame(geo::Geodetic::from_deg(42.5, 1.5, 0.0));
  double e = 0, n = 0, heading = 0.3;
  TimeNs next_step = kNsPerS, next_fix = kNsPerS, next_baro = kNsPerS;
  for (TimeNs t = kNsPerS; t < static_cast<TimeNs>(duration_s * 1e9); t += 20 * kNsPerMs) {
    const double ts = static_cast<double>(t) * 1e-9;
    AccelSample a;
    a.t_ns = t;
    a.acc_mps2 = Eigen::Vector3d(0.3 * std::sin(11.3 * ts), 9.81 + 1.5 * std::sin(11.3 * ts), 0.2);
    out.push_back(a);
    GyroSample g;
    g.t_ns = t;
    g.rate_radps = Eigen::Vector3d(0.01, 0.002, -0.003);
    out.push_back(g);
    if (t >= next_step) {
      next_step += 550 * kNsPerMs;
      heading += 0.002;
      e += 0.7 * std::sin(heading);
      n += 0.7 * std::cos(heading);
      for (const Sample& s : test::step_events(t, t, test::chest_facing(heading))) out.push_back(s);
    }
    if (t >= next_baro) {
      next_baro += 200 * kNsPerMs;
      PressureSample p;
      p.t_ns = t;
      p.pressure_pa = geo::baro_pressure_pa(dem.at_local(e, n).elevation_m, 101325.0, 0.0);
      out.push_back(p);
    }
    if (t >= next_fix) {
      next_fix += kNsPerS;
      if (ts < 1200.0 || ts > 1800.0) {  // a 10 minute outage
        const geo::Geodetic gd = frame.to_geodetic(geo::Enu(e + 2.0 * std::sin(ts / 40.0), n + 2.0 * std::cos(ts / 55.0), 0.0));
        out.push_back(test::gps_fix(t, gd, 1500.0, 4.0));
      }
    }
  }
  return out;
}

void BM_FusedReplayOneHour500Particles(benchmark::State& state) {
  const auto dem = test::bench_hills_dem();
  const double duration_s = 3600.0;
  const std::vector<Sample> samples = session(*dem, duration_s);
  fusion::NavigatorConfig cfg;
  cfg.dem = dem;
  cfg.particles = 500;
  std::size_t valid = 0;
  for (auto _ : state) {
    fusion::Navigator nav(cfg, 1);
    for (const Sample& s : samples) {
      nav.feed(s);
      valid += nav.estimate().valid() ? 1 : 0;  // replay asks for the estimate after every sample
    }
    benchmark::DoNotOptimize(valid);
  }
  state.counters["realtime_factor"] =
      benchmark::Counter(duration_s * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["samples"] = static_cast<double>(samples.size());
}

BENCHMARK(BM_FusedReplayOneHour500Particles)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
