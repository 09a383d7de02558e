// Epochs per second through SPP + TDCP + robust KF with 30 satellites (synthetic sky,
// GPS + Galileo + BeiDou, 1 m code noise, 3 mm carrier noise, seeded). Run: build/<dir>/bench/bench_gnss
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "pdnav/gnss/kalman.h"
#include "pdnav/gnss/solver_synthetic.h"
#include "pdnav/gnss/spp.h"
#include "pdnav/gnss/tdcp.h"

namespace pdnav::gnss {
namespace {

struct Epoch {
  std::vector<SppObservation> code;
  std::vector<CarrierObservation> carrier;
};

/// Pre-generated epochs so the benchmark times only the solver.
std::vector<Epoch> make_epochs(int n_epochs, int n_sats) {
  const geo::Ecef rx = geo::to_ecef(geo::Geodetic::from_deg(48.1, 11.6, 520.0));
  std::mt19937_64 rng(2019);
  std::normal_distribution<double> code(0.0, 1.0), phase(0.0, 0.003);
  auto sky = synthetic_sky(rx, n_sats, 7, {Constellation::kGps, Constellation::kGalileo, Constellation::kBeidou});
  std::vector<Epoch> out;
  for (int k = 0; k < n_epochs; ++k) {
    Epoch e;
    for (const auto& s : sky) {
      const double range = sagnac_range_m(s.state.pos.p_m, rx.p_m) - kSpeedOfLight_mps * s.state.clock_bias_s;
      SppObservation o{s.sat, range + kSpeedOfLight_mps * s.state.group_delay_s + code(rng), 40.0, 1575.42e6, s.state};
      e.code.push_back(o);
      CarrierObservation c;
      c.sat = s.sat;
      c.state = s.state;
      c.cn0_dbhz = 40.0;
      c.adr_m = range + phase(rng);
      c.pr_rate_mps = range_rate_mps(s.state, rx.p_m, Eigen::Vector3d::Zero()) - kSpeedOfLight_mps * s.state.clock_drift_sps;
      e.carrier.push_back(c);
    }
    out.push_back(e);
    sky = propagate_sky(sky, 1.0);
  }
  return out;
}

void BM_SppTdcpKalman30Sats(benchmark::State& state) {
  const auto epochs = make_epochs(64, 30);
  SppOptions spp_opt;
  spp_opt.ionosphere = false;  // no Klobuchar parameters in a synthetic sky
  RobustKalman kf;
  geo::Ecef guess;
  std::size_t k = 0;
  for (auto _ : state) {
    const Epoch& e = epochs[k % epochs.size()];
    const SppSolution s = solve_spp(e.code, guess, 0.0, nullptr, spp_opt);
    if (k % epochs.size() != 0) {
      const DisplacementSolution d = solve_tdcp(epochs[(k - 1) % epochs.size()].carrier, e.carrier, 1.0, s.pos, TdcpOptions{});
      if (d.ok) kf.predict(d.disp_ecef_m, d.cov_ecef_m2, d.clock_change_m, d.clock_change_var_m2);
    }
    if (s.ok) {
      kf.update(s.pos, s.pos_cov_ecef, s.clock_m, s.clock_var_m2);
      guess = s.pos;
    }
    benchmark::DoNotOptimize(kf.state());
    ++k;
  }
  state.counters["epochs_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SppTdcpKalman30Sats)->Unit(benchmark::kMicrosecond);

void BM_Spp30Sats(benchmark::State& state) {
  const auto epochs = make_epochs(8, 30);
  SppOptions spp_opt;
  spp_opt.ionosphere = false;
  std::size_t k = 0;
  for (auto _ : state) benchmark::DoNotOptimize(solve_spp(epochs[k++ % epochs.size()].code, geo::Ecef(), 0.0, nullptr, spp_opt));
  state.counters["epochs_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Spp30Sats)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace pdnav::gnss
