// GNSS engine benchmarks. Run: build/<dir>/bench/bench_gnss (tools/bench runs it from the repo root).
// - BM_WholeEpochGsdcRinex: the WHOLE receiver epoch through GnssEngine::feed_epoch on the real
//   GSDC Pixel 5 drive (RINEX 3 -> Android Raw rows, parsed before timing): measurement building
//   from the Raw rows, satellite states (SP3 precise orbits + broadcast), carrier smoothing,
//   SPP with subset FDE and IGG-III, TDCP or Doppler velocity, the kinematic KF. Data from
//   $PDNAV_SHARED_DATA_DIR, else ../shared/data (the benchmark is skipped with a reason if absent).
// - BM_SolverOnlySppTdcpKalman30Sats / BM_SolverOnlySpp30Sats: the solvers alone on a synthetic
//   sky (30 satellites, GPS + Galileo + BeiDou, 1 m code noise, 3 mm carrier noise, seeded).
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "pdnav/gnss/gnss_engine.h"
#include "pdnav/gnss/kalman.h"
#include "pdnav/gnss/rinex_obs.h"
#include "pdnav/gnss/sp3.h"
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

void BM_SolverOnlySppTdcpKalman30Sats(benchmark::State& state) {
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
BENCHMARK(BM_SolverOnlySppTdcpKalman30Sats)->Unit(benchmark::kMicrosecond);

void BM_SolverOnlySpp30Sats(benchmark::State& state) {
  const auto epochs = make_epochs(8, 30);
  SppOptions spp_opt;
  spp_opt.ionosphere = false;
  std::size_t k = 0;
  for (auto _ : state) benchmark::DoNotOptimize(solve_spp(epochs[k++ % epochs.size()].code, geo::Ecef(), 0.0, nullptr, spp_opt));
  state.counters["epochs_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SolverOnlySpp30Sats)->Unit(benchmark::kMicrosecond);

struct GsdcData {
  std::string error;  // why the data could not be loaded
  std::shared_ptr<EphemerisStore> eph;
  std::vector<std::vector<GnssRawSample>> epochs;
  std::size_t rows = 0;
};

bool exists(const std::string& p) { return std::ifstream(p).good(); }

GsdcData load_gsdc() {
  GsdcData d;
  std::vector<std::string> roots;
  if (const char* env = std::getenv("PDNAV_SHARED_DATA_DIR")) roots.emplace_back(env);
  roots.insert(roots.end(), {"../shared/data", "../../shared/data", "../../../shared/data"});
  std::string dir;
  for (const auto& r : roots)
    if (exists(r + "/gnss-gsdc2021-pixel5/Pixel5_first_half.21o")) { dir = r + "/gnss-gsdc2021-pixel5"; break; }
  if (dir.empty()) { d.error = "GSDC data not found (set PDNAV_SHARED_DATA_DIR)"; return d; }
  d.eph = std::make_shared<EphemerisStore>();
  d.eph->load_rinex_nav(dir + "/hour1180.21n");
  d.eph->add_precise(read_sp3_file(dir + "/COD0MGXFIN_20211180000_01D_05M_ORB.SP3"));
  std::ifstream in(dir + "/Pixel5_first_half.21o");
  RinexObsReader reader(in, "Pixel5_first_half.21o");
  RinexObsEpoch ep;
  std::map<std::string, std::int64_t> skipped;
  while (reader.next(ep)) {
    d.epochs.push_back(rinex_epoch_to_raw(ep, reader.header(), skipped));
    d.rows += d.epochs.back().size();
  }
  if (d.epochs.empty()) d.error = "GSDC RINEX file without epochs";
  return d;
}

void BM_WholeEpochGsdcRinex(benchmark::State& state) {
  static const GsdcData data = load_gsdc();
  if (!data.error.empty()) {
    state.SkipWithError(data.error.c_str());
    return;
  }
  GnssEngine engine(GnssOptions{}, data.eph, 1);
  std::size_t k = 0;
  std::int64_t rows = 0;
  for (auto _ : state) {
    if (k == data.epochs.size()) {  // wrap: restart the filter (time would go backwards)
      k = 0;
      engine.reset();
    }
    engine.feed_epoch(data.epochs[k]);
    rows += static_cast<std::int64_t>(data.epochs[k].size());
    benchmark::DoNotOptimize(engine.estimate());
    engine.take_solutions();
    ++k;
  }
  state.counters["epochs_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["raw_rows_per_epoch"] = static_cast<double>(rows) / static_cast<double>(std::max<std::int64_t>(state.iterations(), 1));
}
BENCHMARK(BM_WholeEpochGsdcRinex)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace pdnav::gnss
