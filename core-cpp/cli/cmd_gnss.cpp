// `pdnav gnss LOG --nav FILE... [--truth LAT,LON,H] [--out CSV]`: the GNSS engine on a
// GnssLogger / session log: per-epoch CSV, summary table (epochs, satellites used per
// constellation, exclusions by reason), error statistics against a static truth.
// The last line is always
//   spp_p50_h_m: A spp_p95_h_m: B kf_rms_h_m: C tdcp_rms_cm: D
// (nan where there is no truth or no data; D = worst axis RMS of the 1 s TDCP displacement).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pdnav/gnss/gnss_engine.h"
#include "pdnav/gnss/solver_metrics.h"
#include "pdnav/io/log_reader.h"

namespace pdnav::cli {
namespace {

struct GnssArgs {
  std::string log;
  std::vector<std::string> nav;
  std::string truth;
  std::string out;
  bool strip_adr = false;
  double smoothing_window_s = gnss::SmoothingOptions{}.window_s;
  std::uint64_t seed = 1;
};

geo::Geodetic parse_truth(const std::string& s) {
  double lat = 0, lon = 0, h = 0;
  char c1 = 0, c2 = 0;
  std::istringstream in(s);
  if (!(in >> lat >> c1 >> lon >> c2 >> h) || c1 != ',' || c2 != ',' || !std::isfinite(lat) || !std::isfinite(lon) ||
      std::fabs(lat) > 90.0 || std::fabs(lon) > 180.0)
    throw std::runtime_error("--truth: expected LAT,LON,H in degrees and metres, got '" + s + "'");
  return geo::Geodetic::from_deg(lat, lon, h);
}

std::shared_ptr<gnss::EphemerisStore> load_nav(const std::vector<std::string>& files) {
  auto store = std::make_shared<gnss::EphemerisStore>();
  for (const std::string& f : files) {
    const gnss::EphemerisLoadReport r = store->load_rinex_nav(f);
    std::cout << "nav " << f << ": " << r.records_total() << " records";
    for (const auto& [sys, n] : r.records_by_system) std::cout << " " << sys << "=" << n;
    if (r.skipped_total() > 0) std::cout << ", skipped " << r.skipped_total();
    std::cout << "\n";
    for (const auto& [why, n] : r.skipped_by_reason) std::cout << "  skipped " << n << ": " << why << "\n";
  }
  return store;
}

/// Runs the whole log through the engine; returns every epoch solution.
std::vector<gnss::EpochSolution> run(const GnssArgs& a, gnss::GnssEngine& engine, std::int64_t& raw_rows) {
  io::LogReader reader(a.log);
  Sample s;
  std::vector<gnss::EpochSolution> sols;
  while (reader.next(s)) {
    if (auto* raw = std::get_if<GnssRawSample>(&s)) {
      ++raw_rows;
      if (a.strip_adr) {
        raw->accumulated_delta_range_state = 0;
        raw->accumulated_delta_range_m = kNaN;
      }
      engine.feed(*raw);
    } else if (const auto* nav = std::get_if<NavMessageSample>(&s)) {
      engine.feed(*nav);
    }
    auto part = engine.take_solutions();
    sols.insert(sols.end(), part.begin(), part.end());
  }
  engine.flush();
  auto part = engine.take_solutions();
  sols.insert(sols.end(), part.begin(), part.end());
  if (reader.stats().skipped_total() > 0) {
    std::cout << "log: skipped " << reader.stats().skipped_total() << " lines\n";
    for (const auto& [why, n] : reader.stats().skipped_by_reason) std::cout << "  " << n << ": " << why << "\n";
  }
  return sols;
}

const gnss::Constellation kSystems[] = {gnss::Constellation::kGps, gnss::Constellation::kGlonass,
                                        gnss::Constellation::kGalileo, gnss::Constellation::kBeidou,
                                        gnss::Constellation::kQzss};

void write_csv(const std::string& path, const std::vector<gnss::EpochSolution>& sols, const geo::LocalFrame& frame) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot create");
  f << "t_ns,gps_ns,spp_ok,spp_lat_deg,spp_lon_deg,spp_h_m,spp_e_m,spp_n_m,spp_u_m,hdop,"
       "kf_ok,kf_lat_deg,kf_lon_deg,kf_h_m,kf_e_m,kf_n_m,kf_u_m,kf_sigma_e_m,kf_sigma_n_m,kf_sigma_u_m,kf_accepted,"
       "disp_source,disp_dt_s,disp_e_m,disp_n_m,disp_u_m,tdcp_sats,sats_tracked,sats_used";
  for (auto c : kSystems) f << ",sats_" << gnss::to_string(c);
  f << "\n";
  char buf[64];
  auto num = [&](double v, const char* fmt) { std::snprintf(buf, sizeof buf, fmt, v); return std::string(std::isfinite(v) ? buf : ""); };
  for (const auto& s : sols) {
    f << s.t_ns << "," << s.gps_ns << "," << (s.spp_ok ? 1 : 0);
    const geo::Geodetic gs = geo::to_geodetic(s.spp);
    const geo::Enu es = frame.to_enu(s.spp);
    if (s.spp_ok) f << "," << num(gs.lat_deg(), "%.8f") << "," << num(gs.lon_deg(), "%.8f") << "," << num(gs.h_m, "%.3f")
                    << "," << num(es.e_m(), "%.3f") << "," << num(es.n_m(), "%.3f") << "," << num(es.u_m(), "%.3f");
    else f << ",,,,,,";
    f << "," << num(s.hdop, "%.3f") << "," << (s.kf_ok ? 1 : 0);
    const geo::Geodetic gk = geo::to_geodetic(s.kf);
    const geo::Enu ek = frame.to_enu(s.kf);
    if (s.kf_ok) f << "," << num(gk.lat_deg(), "%.8f") << "," << num(gk.lon_deg(), "%.8f") << "," << num(gk.h_m, "%.3f")
                   << "," << num(ek.e_m(), "%.3f") << "," << num(ek.n_m(), "%.3f") << "," << num(ek.u_m(), "%.3f")
                   << "," << num(std::sqrt(s.kf_cov_enu(0, 0)), "%.3f") << "," << num(std::sqrt(s.kf_cov_enu(1, 1)), "%.3f")
                   << "," << num(std::sqrt(s.kf_cov_enu(2, 2)), "%.3f");
    else f << ",,,,,,,,,";
    f << "," << (s.kf_update_accepted ? 1 : 0) << "," << s.disp_source << "," << num(s.disp_dt_s, "%.3f");
    if (!s.disp_source.empty()) f << "," << num(s.tdcp_disp_m.x(), "%.4f") << "," << num(s.tdcp_disp_m.y(), "%.4f") << "," << num(s.tdcp_disp_m.z(), "%.4f");
    else f << ",,,";
    f << "," << s.tdcp_sats << "," << s.sats_tracked << "," << s.sats_used;
    for (auto c : kSystems) { auto it = s.used_by_sys.find(c); f << "," << (it == s.used_by_sys.end() ? 0 : it->second); }
    f << "\n";
  }
}

void print_summary(const std::vector<gnss::EpochSolution>& sols, const gnss::GnssEngine& engine, std::int64_t raw_rows) {
  int spp = 0, kf = 0, tdcp = 0, dop = 0;
  std::map<gnss::Constellation, double> used_sum;
  for (const auto& s : sols) {
    spp += s.spp_ok; kf += s.kf_ok; tdcp += s.disp_source == "tdcp"; dop += s.disp_source == "doppler";
    for (const auto& [c, n] : s.used_by_sys) used_sum[c] += n;
  }
  std::printf("raw rows: %lld  epochs: %zu  spp fixes: %d  kf epochs: %d  tdcp: %d  doppler fallback: %d\n",
              static_cast<long long>(raw_rows), sols.size(), spp, kf, tdcp, dop);
  std::printf("%-10s %s\n", "system", "mean satellites used per SPP fix");
  for (auto c : kSystems)
    std::printf("%-10s %.2f\n", gnss::to_string(c), spp > 0 ? used_sum[c] / spp : 0.0);
  std::printf("%-72s %s\n", "exclusion / skip reason", "count");
  for (const auto& [why, n] : engine.exclusions()) std::printf("%-72s %lld\n", why.c_str(), static_cast<long long>(n));
}

void print_accuracy(const gnss::StaticAccuracy& a) {
  std::printf("%-22s %8s %8s %8s %8s\n", "vs truth", "p50_h_m", "p95_h_m", "rms_h_m", "rms_v_m");
  std::printf("%-22s %8.2f %8.2f %8.2f %8.2f   (%d epochs)\n", "SPP", a.spp_p50_h_m, a.spp_p95_h_m, a.spp_rms_h_m, a.spp_rms_v_m, a.spp_epochs);
  std::printf("%-22s %8.2f %8.2f %8.2f %8.2f   (%d epochs)\n", "KF", a.kf_p50_h_m, a.kf_p95_h_m, a.kf_rms_h_m, a.kf_rms_v_m, a.kf_epochs);
  std::printf("1 s displacement RMS (static truth 0), cm: TDCP e/n/u %.2f %.2f %.2f (%d), Doppler e/n/u %.2f %.2f %.2f (%d)\n",
              a.tdcp_rms_enu_m.x() * 100, a.tdcp_rms_enu_m.y() * 100, a.tdcp_rms_enu_m.z() * 100, a.tdcp_epochs,
              a.doppler_rms_enu_m.x() * 100, a.doppler_rms_enu_m.y() * 100, a.doppler_rms_enu_m.z() * 100, a.doppler_epochs);
}

void run_gnss(const GnssArgs& a) {
  const auto store = load_nav(a.nav);
  gnss::GnssOptions options;
  options.smoothing.window_s = a.smoothing_window_s;
  gnss::GnssEngine engine(options, store, a.seed);
  std::int64_t raw_rows = 0;
  const std::vector<gnss::EpochSolution> sols = run(a, engine, raw_rows);
  print_summary(sols, engine, raw_rows);
  const bool have_truth = !a.truth.empty();
  geo::Geodetic truth;
  if (have_truth) truth = parse_truth(a.truth);
  else {
    for (const auto& s : sols) if (s.kf_ok) { truth = geo::to_geodetic(s.kf); break; }
  }
  if (!a.out.empty()) {
    write_csv(a.out, sols, geo::LocalFrame(truth));
    std::cout << "csv: " << a.out << " (" << sols.size() << " epochs; e/n/u relative to "
              << (have_truth ? "the truth" : "the first KF fix") << ")\n";
  }
  const gnss::StaticAccuracy acc = gnss::evaluate_static(sols, truth);
  if (have_truth) print_accuracy(acc);
  const double nan = kNaN;
  std::printf("spp_p50_h_m: %.2f spp_p95_h_m: %.2f kf_rms_h_m: %.2f tdcp_rms_cm: %.2f\n",
              have_truth ? acc.spp_p50_h_m : nan, have_truth ? acc.spp_p95_h_m : nan,
              have_truth ? acc.kf_rms_h_m : nan, acc.tdcp_rms_max_axis_m() * 100.0);
}

}  // namespace

void register_gnss(CLI::App& app) {
  auto args = std::make_shared<GnssArgs>();
  CLI::App* cmd = app.add_subcommand("gnss", "GNSS engine (SPP, TDCP, robust KF; Walker 2019) on a log's Raw rows");
  cmd->add_option("log", args->log, "GnssLogger or session log")->required()->check(CLI::ExistingFile);
  cmd->add_option("--nav", args->nav, "RINEX navigation files (2 or 3)")->check(CLI::ExistingFile);
  cmd->add_option("--truth", args->truth, "static truth LAT,LON,H (deg, deg, m ellipsoidal)");
  cmd->add_option("--out", args->out, "per-epoch CSV (tools/plot.py gnss CSV)");
  cmd->add_flag("--strip-adr", args->strip_adr, "drop carrier phase (tests the Doppler fallback)");
  cmd->add_option("--smoothing-window", args->smoothing_window_s,
                  "carrier smoothing window of the code, s (RTCA DO-229: 100; 0 = raw code)")->check(CLI::Range(0.0, 3600.0));
  cmd->add_option("--seed", args->seed, "engine seed (the engine is deterministic)");
  cmd->callback([args]() { run_gnss(*args); });
}

}  // namespace pdnav::cli
