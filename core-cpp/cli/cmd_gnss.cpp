// `pdnav gnss LOG --nav FILE... [--truth LAT,LON,H] [--out CSV]`: the GNSS engine on a
// GnssLogger / session log: per-epoch CSV, summary table (epochs, satellites used per
// constellation, exclusions by reason), error statistics against a static truth.
// The last line is always
//   spp_p50_h_m: A spp_p95_h_m: B kf_rms_h_m: C tdcp_rms_cm: D
// (nan where there is no truth or no data; D = worst axis RMS of the 1 s TDCP displacement's
// error: the displacement itself against a static --truth, the displacement less the truth
// track's own over the same second with --truth-csv).
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/gnss_engine.h"
#include "pdnav/gnss/rinex_obs.h"
#include "pdnav/gnss/solver_metrics.h"
#include "pdnav/gnss/sp3.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/io/sample_source.h"
#include "support/eval_support.h"
#include "support/sources.h"

namespace pdnav::cli {
namespace {

struct GnssArgs {
  std::string log;
  std::string format = "auto";
  std::vector<std::string> nav;
  std::vector<std::string> sp3;
  std::vector<std::string> clk;
  std::string truth;
  std::string truth_csv;
  std::string out;
  std::string residuals_out;
  bool strip_adr = false;
  double smoothing_window_s = gnss::SmoothingOptions{}.window_s;
  bool smoothed_white_noise = gnss::GnssOptions{}.smoothed_code_white_noise;
  double fix_bias_sigma_h_m = gnss::GnssOptions{}.fix_bias_sigma_h_m;
  std::uint64_t seed = 1;
  int keep_every = 1;  // robustness check: keep every N-th epoch (duty cycling)
  bool clock_steps = false;  // robustness check: a 1 ms code-only clock step every epoch
  bool hw_discontinuities = false;  // robustness check: HardwareClockDiscontinuityCount changes every epoch
  double iono_window_s = gnss::SmoothingOptions{}.iono_window_s;
  int dual_min_sats = gnss::MeasurementOptions{}.dual_min_sats;
  double dual_min_fraction = gnss::MeasurementOptions{}.dual_min_fraction;
  bool dual_keep_single = gnss::MeasurementOptions{}.dual_keep_single;
  std::string freq = gnss::frequency_mode_name(gnss::MeasurementOptions{}.frequency);
  double kf_displacement_q_m2 = gnss::KalmanOptions{}.displacement_q_m2;
  double kf_fix_scale = gnss::KalmanOptions{}.fix_variance_scale;
  std::string dynamics = gnss::kf_dynamics_name(gnss::KalmanOptions{}.dynamics);
  double kf_accel_psd = kNaN;  // NaN = the dynamics' value
  std::string spp_fde = "subsets";
  bool spp_igg3 = gnss::SppOptions{}.robust_igg3;
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

enum class InputFormat { kLog, kRinexObs };

/// GnssLogger / pdnav session log or RINEX 3 observations, decided from the content; any
/// other file is an error with the reason.
InputFormat detect_format(const std::string& path) {
  if (std::filesystem::is_directory(path)) return InputFormat::kLog;  // a Sensor Logger / phyphox folder
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ":0: cannot open");
  std::string l;
  int n = 0;
  while (std::getline(f, l) && n < 50) {
    ++n;
    if (!l.empty() && l.back() == '\r') l.pop_back();
    if (l.find_first_not_of(" \t") == std::string::npos) continue;
    if (gnss::looks_like_rinex_obs(l)) return InputFormat::kRinexObs;
    if (l.size() >= 80 && l.substr(60, 20).find("RINEX VERSION / TYPE") == 0)
      throw std::runtime_error(path + ":" + std::to_string(n) + ": a RINEX file but not observation data ('" +
                               l.substr(20, 20) + "'); give navigation files with --nav");
    if (l[0] == '#') return InputFormat::kLog;
    const auto comma = l.find(',');
    const std::string type = comma == std::string::npos ? std::string() : l.substr(0, comma);
    static const char* kTypes[] = {"Raw", "Fix", "Nav", "Status", "Accel", "Gyro", "Mag", "UncalAccel", "UncalGyro",
                                   "UncalMag", "OrientationDeg", "Agc", "Pressure", "Truth", "Step", "GameRot"};
    for (const char* t : kTypes) if (type == t) return InputFormat::kLog;
    try {
      (void)io::detect_format(path);  // another recording format (its reader reports what it lacks)
      return InputFormat::kLog;
    } catch (const io::IoError&) {
    }
    throw std::runtime_error(path + ":" + std::to_string(n) +
                             ": neither a GnssLogger/session log (no '#' header or known line type) nor a RINEX "
                             "observation file (no RINEX VERSION / TYPE line)");
  }
  throw std::runtime_error(path + ":0: empty file (neither a GnssLogger/session log nor RINEX observations)");
}

void strip(GnssRawSample& raw) {
  raw.accumulated_delta_range_state = 0;
  raw.accumulated_delta_range_m = kNaN;
}

/// Runs the whole input through the engine; returns every epoch solution.
std::vector<gnss::EpochSolution> run(const GnssArgs& a, gnss::GnssEngine& engine, std::int64_t& raw_rows,
                                     std::int64_t& nav_rows) {
  std::vector<gnss::EpochSolution> sols;
  auto collect = [&]() {
    auto part = engine.take_solutions();
    sols.insert(sols.end(), part.begin(), part.end());
  };
  if (a.format == "auto" && detect_format(a.log) == InputFormat::kRinexObs) {
    std::ifstream f(a.log);
    gnss::RinexObsReader reader(f, a.log);
    gnss::RinexObsEpoch ep;
    std::map<std::string, std::int64_t> skipped;
    std::int64_t index = 0;
    while (reader.next(ep)) {
      if (index++ % a.keep_every != 0) continue;
      auto rows = gnss::rinex_epoch_to_raw(ep, reader.header(), skipped);
      if (a.clock_steps)
        for (auto& r : rows) r.full_bias_nanos -= (index % 2) * 1'000'000;
      if (a.hw_discontinuities)
        for (auto& r : rows) r.hardware_clock_discontinuity_count = index;
      for (auto& r : rows) {
        if (a.strip_adr) strip(r);
        engine.feed(r);
      }
      raw_rows += static_cast<std::int64_t>(rows.size());
      engine.flush();  // a RINEX epoch is complete when its record ends
      collect();
    }
    const auto& rep = reader.report();
    std::cout << "rinex obs " << a.log << ": version " << reader.header().version << ", " << rep.epochs << " epochs, "
              << rep.satellite_records << " satellite records, " << rep.signals << " signals\n";
    for (const auto& [why, n] : rep.skipped_by_reason) std::cout << "  skipped " << n << ": " << why << "\n";
    for (const auto& [why, n] : skipped) std::cout << "  skipped " << n << ": " << why << "\n";
    if (rep.epochs == 0) throw std::runtime_error(a.log + ": RINEX observation file without any epoch");
    return sols;
  }
  const std::unique_ptr<io::SampleSource> source = open_source(a.log, a.format);
  io::SampleSource& reader = *source;
  Sample s;
  std::int64_t index = -1, last_time_nanos = kMissingInt;
  while (reader.next(s)) {
    if (auto* raw = std::get_if<GnssRawSample>(&s)) {
      if (raw->time_nanos != last_time_nanos) { ++index; last_time_nanos = raw->time_nanos; }
      if (index % a.keep_every != 0) continue;
      if (a.clock_steps && raw->full_bias_nanos != kMissingInt) raw->full_bias_nanos -= (index % 2) * 1'000'000;
      if (a.hw_discontinuities) raw->hardware_clock_discontinuity_count = index;
      ++raw_rows;
      if (a.strip_adr) strip(*raw);
      engine.feed(*raw);
    } else if (const auto* nav = std::get_if<NavMessageSample>(&s)) {
      ++nav_rows;
      engine.feed(*nav);
    }
    collect();
  }
  engine.flush();
  collect();
  if (reader.stats().skipped_total() > 0) {
    std::cout << "log: skipped " << reader.stats().skipped_total() << " lines\n";
    for (const auto& [why, n] : reader.stats().skipped_by_reason) std::cout << "  " << n << ": " << why << "\n";
  }
  if (raw_rows == 0)
    throw std::runtime_error(a.log + ": no Raw GNSS measurement rows in this log (" +
                             std::to_string(reader.stats().skipped_total()) + " lines skipped)");
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
  f << ",spp_sigma_e_m,spp_sigma_n_m,spp_chi2_per_dof\n";
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
    if (s.spp_ok) f << "," << num(std::sqrt(s.spp_cov_enu(0, 0)), "%.3f") << "," << num(std::sqrt(s.spp_cov_enu(1, 1)), "%.3f")
                    << "," << num(s.spp_variance_factor, "%.3f");
    else f << ",,,";
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
  std::printf("%-22s %8s %8s %8s %8s %8s\n", "vs truth", "p50_h_m", "p95_h_m", "rms_h_m", "rms_v_m", "cov68");
  std::printf("%-22s %8.2f %8.2f %8.2f %8.2f %8s   (%d epochs)\n", "SPP", a.spp_p50_h_m, a.spp_p95_h_m, a.spp_rms_h_m, a.spp_rms_v_m, "-", a.spp_epochs);
  std::printf("%-22s %8.2f %8.2f %8.2f %8.2f %8.3f   (%d epochs)\n", "KF", a.kf_p50_h_m, a.kf_p95_h_m, a.kf_rms_h_m, a.kf_rms_v_m, a.kf_coverage68, a.kf_epochs);
  std::printf("1 s displacement RMS (static truth 0), cm: TDCP e/n/u %.2f %.2f %.2f (%d), Doppler e/n/u %.2f %.2f %.2f (%d)\n",
              a.tdcp_rms_enu_m.x() * 100, a.tdcp_rms_enu_m.y() * 100, a.tdcp_rms_enu_m.z() * 100, a.tdcp_epochs,
              a.doppler_rms_enu_m.x() * 100, a.doppler_rms_enu_m.y() * 100, a.doppler_rms_enu_m.z() * 100, a.doppler_epochs);
}

/// Code residuals at the truth (static or track) of every epoch, raw and smoothed code, one
/// row per satellite: the input of tools/gnss-noise-fit (docs/gnss.md "Code noise model").
void write_residuals(const std::string& path, const std::vector<gnss::EpochSolution>& sols, const GnssArgs& a,
                     const gnss::EphemerisStore& store, const gnss::SppOptions& spp) {
  const bool have_static = !a.truth.empty();
  if (!have_static && a.truth_csv.empty()) throw std::runtime_error("--residuals-out needs --truth or --truth-csv");
  const geo::Geodetic fixed = have_static ? parse_truth(a.truth) : geo::Geodetic();
  const gnss::TruthTrack track = have_static ? gnss::TruthTrack() : gnss::read_truth_csv_file(a.truth_csv);
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot write");
  f << "gps_ns,sys,svid,band,cn0_dbhz,el_deg,raw_m,smoothed_m,group_size,iono_free,az_deg,white_ratio\n";
  std::int64_t rows = 0, epochs = 0;
  for (const gnss::EpochSolution& s : sols) {
    if (s.code_obs.empty()) continue;
    geo::Geodetic g = fixed;
    if (!have_static && !gnss::truth_at(track, s.gps_ns, g)) continue;
    const geo::Ecef truth = geo::to_ecef(g);
    const double tow = geo::gps_ns_to_week_tow(s.gps_ns).tow_s;
    std::vector<gnss::SppObservation> raw = s.code_obs;
    for (std::size_t i = 0; i < raw.size() && i < s.code_raw_m.size(); ++i) raw[i].pseudorange_m = s.code_raw_m[i];
    // a truth track's height is estimated (GSDC 2021 heights are tens of metres off the
    // phone's: docs/gnss.md); a static survey point's is used
    gnss::TruthResidualOptions ro;
    ro.estimate_height = !have_static;
    const auto r_raw = gnss::residuals_at_truth(raw, truth, tow, store.klobuchar(), spp, ro);
    const auto r_sm = gnss::residuals_at_truth(s.code_obs, truth, tow, store.klobuchar(), spp, ro);
    std::map<gnss::SatId, double> smoothed;
    for (const auto& r : r_sm) smoothed[r.sat] = r.residual_m;
    std::map<gnss::SatId, bool> iono_free;
    std::map<gnss::SatId, double> white_ratio;
    for (const auto& o : s.code_obs) {
      iono_free[o.sat] = o.iono_free;
      white_ratio[o.sat] = o.white_var_ratio;
    }
    for (const auto& r : r_raw) {
      const auto it = smoothed.find(r.sat);
      char line[256];
      std::snprintf(line, sizeof line, "%lld,%c,%d,%s,%.2f,%.3f,%.4f,%.4f,%d,%d,%.3f,%.5f\n", static_cast<long long>(s.gps_ns),
                    gnss::rinex_letter(r.sat.sys), r.sat.prn, gnss::to_string(gnss::signal_band(r.carrier_hz)),
                    r.cn0_dbhz, r.el_rad * 180.0 / kPi, r.residual_m, it == smoothed.end() ? kNaN : it->second,
                    r.group_size, iono_free[r.sat] ? 1 : 0, r.az_rad * 180.0 / kPi, white_ratio[r.sat]);
      f << line;
      ++rows;
    }
    ++epochs;
  }
  if (!f) throw std::runtime_error(path + ": write failed");
  std::cout << "residuals: " << path << " (" << rows << " code residuals at the truth, " << epochs << " epochs)\n";
}

void run_gnss(const GnssArgs& a) {
  const auto store = load_nav(a.nav);
  for (const std::string& f : a.sp3) {
    const gnss::Sp3File sp3 = gnss::read_sp3_file(f);
    const int n = store->add_precise(sp3);
    std::printf("sp3 %s: %zu epochs, %d satellites with precise orbits and clocks, %d lines skipped\n", f.c_str(),
                sp3.epochs.size(), n, sp3.skipped_lines);
  }
  if (!a.clk.empty() && a.sp3.empty()) throw std::runtime_error("--clk needs --sp3 (the clock file has no orbits)");
  for (const std::string& f : a.clk) {
    const gnss::ClockFile clk = gnss::read_rinex_clock_file(f);
    const int n = store->add_precise_clocks(clk);
    std::printf("clk %s: version %.2f, %s time, %lld satellite clock records, %d satellites, %lld records skipped\n",
                f.c_str(), clk.version, clk.time_system.c_str(), static_cast<long long>(clk.records), n,
                static_cast<long long>(clk.skipped_total()));
    for (const auto& [why, k] : clk.skipped) std::printf("  skipped %lld: %s\n", static_cast<long long>(k), why.c_str());
  }
  gnss::GnssOptions options;
  options.smoothing.window_s = a.smoothing_window_s;
  options.smoothed_code_white_noise = a.smoothed_white_noise;
  options.fix_bias_sigma_h_m = a.fix_bias_sigma_h_m;
  options.smoothing.iono_window_s = a.iono_window_s;
  options.measurements.dual_min_sats = a.dual_min_sats;
  options.measurements.dual_min_fraction = a.dual_min_fraction;
  options.measurements.dual_keep_single = a.dual_keep_single;
  options.measurements.frequency = a.freq == "dual" ? gnss::FrequencyMode::kDual
                                   : a.freq == "l5"   ? gnss::FrequencyMode::kL5
                                   : a.freq == "best" ? gnss::FrequencyMode::kBest
                                                      : gnss::FrequencyMode::kSingle;
  options.kalman.displacement_q_m2 = a.kf_displacement_q_m2;
  options.kalman.fix_variance_scale = a.kf_fix_scale;
  gnss::parse_kf_dynamics(a.dynamics, options.kalman.dynamics);  // validated by CLI11
  options.kalman.accel_psd_h_m2ps3 = a.kf_accel_psd;
  options.spp.fde = a.spp_fde == "largest" ? gnss::SppFde::kLargestResidual : gnss::SppFde::kSubsets;
  options.spp.robust_igg3 = a.spp_igg3;
  options.record_code_observations = !a.residuals_out.empty();
  gnss::GnssEngine engine(options, store, a.seed);
  std::int64_t raw_rows = 0, nav_rows = 0;
  const std::vector<gnss::EpochSolution> sols = run(a, engine, raw_rows, nav_rows);
  if (a.nav.empty() && a.sp3.empty() && nav_rows == 0 &&
      std::none_of(sols.begin(), sols.end(), [](const gnss::EpochSolution& s) { return s.spp_ok; }))
    throw std::runtime_error(a.log + ": " + std::to_string(raw_rows) +
                             " Raw rows but no satellite orbits: pass the broadcast ephemeris with --nav FILE "
                             "(RINEX navigation) or use a log that records Nav rows");
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
  if (!a.residuals_out.empty()) write_residuals(a.residuals_out, sols, a, *store, options.spp);
  const gnss::StaticAccuracy acc = gnss::evaluate_static(sols, truth);
  if (have_truth) print_accuracy(acc);
  double tdcp_rms_m = have_truth ? acc.tdcp_rms_max_axis_m() : kNaN;  // static: the displacement is its error
  if (!a.truth_csv.empty()) {
    const gnss::TruthTrack track = gnss::read_truth_csv_file(a.truth_csv);
    const gnss::TrackAccuracy t = gnss::evaluate_track(sols, track);
    tdcp_rms_m = t.tdcp_err_rms_max_axis_m();
    std::printf("truth track %s: %zu points, %lld rows skipped\n", a.truth_csv.c_str(), track.points.size(),
                static_cast<long long>(track.skipped_rows));
    std::printf("%-6s %8s %8s %8s %8s %8s %8s\n", "track", "p50_h_m", "p95_h_m", "rms_h_m", "score_m", "avail", "cov68");
    for (const auto& [name, st] : {std::pair<const char*, const gnss::TrackStats&>{"SPP", t.spp}, {"KF", t.kf}})
      std::printf("%-6s %8.2f %8.2f %8.2f %8.2f %8.3f %8.3f   (%d of %d epochs)\n", name, st.p50_h_m, st.p95_h_m,
                  st.rms_h_m, st.score_m, st.availability, st.coverage68, st.solved, st.epochs);
    std::printf("track_spp_score_m: %.2f track_spp_avail: %.3f track_kf_score_m: %.2f track_kf_avail: %.3f "
                "track_kf_cov68: %.3f\n", t.spp.score_m, t.spp.availability, t.kf.score_m, t.kf.availability,
                t.kf.coverage68);
    const auto cm = [](const Eigen::Vector3d& v) { return Eigen::Vector3d(100.0 * v); };
    const Eigen::Vector3d te = cm(t.tdcp_err_rms_enu_m), de = cm(t.doppler_err_rms_enu_m);
    std::printf("1 s displacement vs the truth's: TDCP rms e/n/u %.1f / %.1f / %.1f cm (%d epochs), "
                "Doppler %.1f / %.1f / %.1f cm (%d epochs)\n",
                te.x(), te.y(), te.z(), t.tdcp_epochs, de.x(), de.y(), de.z(), t.doppler_epochs);
  }
  // the static figures need --truth (a surveyed point); n/a, not NaN, where there is none
  const auto fig = [have_truth](double v, int digits) { return fixed_or(have_truth ? v : kNaN, digits, "n/a"); };
  std::printf("spp_p50_h_m: %s spp_p95_h_m: %s kf_rms_h_m: %s tdcp_rms_cm: %s kf_cov68: %s\n",
              fig(acc.spp_p50_h_m, 2).c_str(), fig(acc.spp_p95_h_m, 2).c_str(), fig(acc.kf_rms_h_m, 2).c_str(),
              fixed_or(tdcp_rms_m * 100.0, 2, "n/a").c_str(), fig(acc.kf_coverage68, 3).c_str());
}

}  // namespace

void register_gnss(CLI::App& app) {
  auto args = std::make_shared<GnssArgs>();
  CLI::App* cmd = app.add_subcommand("gnss", "GNSS engine (SPP, TDCP, robust KF; Walker 2019) on a log's Raw rows");
  cmd->add_option("log", args->log, "GnssLogger / session log or RINEX 3.0x observation file (detected from the content)")->required()->check(CLI::ExistingPath);
  add_format_option(cmd, args->format);
  cmd->add_option("--nav", args->nav, "RINEX navigation files (2 or 3)")->check(CLI::ExistingFile);
  cmd->add_option("--sp3", args->sp3, "precise orbits and clocks (SP3-c/d); used instead of broadcast where they cover")
      ->check(CLI::ExistingFile);
  cmd->add_option("--clk", args->clk,
                  "precise satellite clocks (RINEX clock 3.0x, AS records) replacing the SP3 clocks; needs --sp3")
      ->check(CLI::ExistingFile);
  cmd->add_option("--truth", args->truth, "static truth LAT,LON,H (deg, deg, m ellipsoidal)");
  cmd->add_option("--truth-csv", args->truth_csv,
                  "per-epoch truth track, GSDC columns millisSinceGpsEpoch,latDeg,lngDeg,heightAboveWgs84EllipsoidM")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "per-epoch CSV (tools/plot.py gnss CSV)");
  cmd->add_option("--residuals-out", args->residuals_out,
                  "per-satellite code residuals at the truth (raw and smoothed; needs --truth or --truth-csv), "
                  "input of tools/gnss-noise-fit");
  cmd->add_flag("--strip-adr", args->strip_adr, "drop carrier phase (tests the Doppler fallback)");
  cmd->add_option("--smoothing-window", args->smoothing_window_s,
                  "carrier smoothing window of the code, s (RTCA DO-229: 100; 0 = raw code)")->check(CLI::Range(0.0, 3600.0));
  cmd->add_option("--fix-bias-sigma", args->fix_bias_sigma_h_m,
                  "the fixes' common bias per horizontal axis, m, added to the KF's reported covariance "
                  "(a consider variance: the estimate is unchanged; 0 = off)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  cmd->add_option("--smoothed-white-noise", args->smoothed_white_noise,
                  "weight a smoothed code by what smoothing left of its C/N0 noise (true, default) or as raw code (false)");
  cmd->add_option("--kf-displacement-q", args->kf_displacement_q_m2,
                  "KF process noise added to each displacement, m^2 per epoch")->check(CLI::Range(0.0, 1e6));
  cmd->add_option("--kf-fix-scale", args->kf_fix_scale, "KF: multiplies the SPP covariance used as R, for fixes 1 s apart (AR(1) over longer gaps)")
      ->check(CLI::Range(1e-3, 1e6));
  cmd->add_option("--dynamics", args->dynamics,
                  "KF process noise: pedestrian (1 m^2/s^3) or vehicle (10 m^2/s^3), Groves 2013 Sec. 9.4.2.2")
      ->check(CLI::IsMember({"pedestrian", "vehicle"}));
  cmd->add_option("--kf-accel-psd", args->kf_accel_psd, "KF horizontal acceleration PSD, m^2/s^3 (overrides --dynamics)")
      ->check(CLI::Range(1e-6, 1e6));
  cmd->add_flag("--hw-discontinuities", args->hw_discontinuities,
                "robustness check: HardwareClockDiscontinuityCount changes on every epoch (no TDCP, KF clock reset)");
  cmd->add_option("--spp-fde", args->spp_fde, "SPP FDE: subsets (leave-one/two-out, default) or largest (residual)")
      ->check(CLI::IsMember({"subsets", "largest"}));
  cmd->add_option("--spp-igg3", args->spp_igg3, "SPP IGG-III robust weights after the FDE (true/false)");
  cmd->add_option("--keep-every", args->keep_every, "robustness check: keep every N-th epoch (duty cycling)")
      ->check(CLI::Range(1, 3600));
  cmd->add_option("--freq", args->freq,
                  "single: L1/E1/B1 + Klobuchar; dual: L1/L5 (E1/E5a) ionosphere-free code per clock group "
                  "where enough satellites track both bands (docs/gnss.md); l5: L5/E5a/B2a alone; best: per "
                  "satellite L5/E5a where tracked, else L1 (a receiver clock per band)")
      ->check(CLI::IsMember({"single", "dual", "l5", "best"}));
  cmd->add_option("--iono-window", args->iono_window_s,
                  "dual: averaging window of the IF ionosphere correction, s (0 = raw IF code)")
      ->check(CLI::Range(0.0, 1e5));
  cmd->add_option("--dual-min-sats", args->dual_min_sats, "dual: fewest L1+L5 satellites for a clock group to use IF")
      ->check(CLI::Range(2, 64));
  cmd->add_option("--dual-min-fraction", args->dual_min_fraction,
                  "dual: smallest share of a clock group's satellites tracking L5 for IF")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("--dual-keep-single", args->dual_keep_single,
                "dual: keep the L1 code of L1-only satellites in an IF clock group (mixed; bias not modelled)");
  cmd->add_flag("--clock-steps", args->clock_steps,
                "robustness check: step FullBiasNanos by 1 ms on every other epoch (code moves, carrier does not)");
  cmd->add_option("--seed", args->seed, "engine seed (the engine is deterministic)");
  cmd->callback([args]() { run_gnss(*args); });
}

}  // namespace pdnav::cli
