// pdnav simulate: a realistic walk on a real DEM tile, written as a session log (io::LogWriter)
// plus the ground-truth track as CSV. Seeded and reproducible (docs/terrain.md "Simulator").
// With --session: a whole phone session (IMU, rotation vector, barometer, step events, GNSS
// Raw rows from real broadcast ephemeris, chipset Fix rows, Truth) walking the walkway graph,
// with a scripted GNSS outage and degraded segments (docs/simulator.md).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pdnav/gnss/ephemeris.h"
#include "pdnav/io/log_writer.h"
#include "pdnav/phonesim/phone_session.h"
#include "pdnav/route/walk_graph.h"
#include "pdnav/terrain/dem.h"
#include "pdnav/terrain/simulator.h"
#include "support/walk_log.h"

namespace pdnav::cli {
namespace {

struct SimulateArgs {
  std::string dem;
  std::string log;
  std::string truth_csv;
  std::uint64_t seed = 1;
  double min_length_m = 1000.0;
  double max_length_m = 5000.0;
  double user_height_m = 1.75;
  // --session
  bool session = false;
  std::string graph;
  std::vector<std::string> nav;
  double outage_min_min = 2.0;
  double outage_max_min = 20.0;
  double lead_s = 360.0;
  double tail_s = 180.0;
  bool declare_start = false;
};

MetaSample meta(const std::string& key, const std::string& value) { return {0, key, value}; }

void write_truth_csv(const std::string& path, const terrain::SimulatedWalk& w) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot create the truth CSV");
  f << "t_ns,lat_deg,lon_deg,h_m,heading_deg,east_m,north_m,measured_length_m,measured_heading_deg\n";
  f << std::setprecision(12);
  for (std::size_t k = 0; k < w.truth.size(); ++k) {
    const TruthSample& t = w.truth[k];
    f << t.t_ns << ',' << t.lat_deg << ',' << t.lon_deg << ',' << std::setprecision(6) << t.h_m << ','
      << t.heading_deg << ',' << w.truth_en[k].x() << ',' << w.truth_en[k].y() << ',' << w.steps[k].length_m << ','
      << rad_to_deg(w.steps[k].heading_rad) << std::setprecision(12) << '\n';
  }
  if (!f) throw std::runtime_error(path + ": write error");
}

int run_session(const SimulateArgs& a) {
  if (a.graph.empty()) throw std::invalid_argument("--session needs --graph (walkway graph from dem-tools)");
  if (a.nav.empty()) throw std::invalid_argument("--session needs --nav (RINEX broadcast navigation file)");
  const terrain::Dem dem = terrain::Dem::load(a.dem);
  const route::WalkGraph graph = route::WalkGraph::load(a.graph);
  gnss::EphemerisStore eph;
  for (const std::string& n : a.nav) eph.load_rinex_nav(n);
  phonesim::SessionOptions opt;
  opt.outage_min_s = 60.0 * a.outage_min_min;
  opt.outage_max_s = 60.0 * a.outage_max_min;
  opt.lead_s = a.lead_s;
  opt.tail_s = a.tail_s;
  opt.user_height_m = a.user_height_m;
  opt.declare_start = a.declare_start;
  const phonesim::PhoneSession ses = phonesim::simulate_session(dem, graph, eph, opt, a.seed);
  {
    io::LogWriterOptions wo;
    wo.device = "pdnav simulate --session";
    io::LogWriter writer(a.log, wo);
    writer.write(meta("DemFile", a.dem));
    writer.write(meta("GraphFile", a.graph));
    for (const Sample& s : ses.samples) writer.write(s);
    writer.close();
  }
  const std::string truth = a.truth_csv.empty() ? a.log + ".truth.csv" : a.truth_csv;
  {
    std::ofstream f(truth);
    if (!f) throw std::runtime_error(truth + ": cannot create the truth CSV");
    f << "t_ns,lat_deg,lon_deg,east_m,north_m,h_m,heading_deg,outage,degraded\n" << std::setprecision(12);
    for (const auto& t : ses.truth) {
      const geo::Geodetic g = dem.to_geodetic(t.en_m.x(), t.en_m.y());
      f << t.t_ns << ',' << g.lat_deg() << ',' << g.lon_deg() << ',' << t.en_m.x() << ',' << t.en_m.y() << ',' << t.h_m
        << ',' << rad_to_deg(t.heading_rad) << ',' << (t.outage ? 1 : 0) << ',' << (t.degraded ? 1 : 0) << '\n';
    }
    if (!f) throw std::runtime_error(truth + ": write error");
  }
  const auto& st = ses.stats;
  std::printf("simulated session: %.0f m, %.0f s, %lld steps, outage %.0f-%.0f s, %zu degraded segments; "
              "%lld GNSS epochs (%.1f satellites tracked, %lld masked by terrain, %lld NLOS rows, %lld cycle slips), "
              "%lld Fix rows; stride scale %.3f, heading bias at outage %.1f deg; log %s, truth %s\n",
              st.length_m, st.duration_s, static_cast<long long>(st.steps), ns_to_s(ses.outage_start_ns) - 10.0,
              ns_to_s(ses.outage_end_ns) - 10.0, ses.degraded.size(), static_cast<long long>(st.gnss_epochs),
              st.mean_sats_tracked, static_cast<long long>(st.masked_by_terrain), static_cast<long long>(st.nlos_rows),
              static_cast<long long>(st.cycle_slips), static_cast<long long>(st.fix_rows), st.walker_stride_scale,
              st.heading_bias_at_outage_deg, a.log.c_str(), truth.c_str());
  return 0;
}

int run_simulate(const SimulateArgs& a) {
  if (a.session) return run_session(a);
  const terrain::Dem dem = terrain::Dem::load(a.dem);
  terrain::WalkSimOptions opt;
  opt.min_length_m = a.min_length_m;
  opt.max_length_m = a.max_length_m;
  // The walker's mean step follows the APT height model the replay's PDR uses (l = 0.415 h,
  // Zhu et al. Sec. V-A); each walk still deviates from it by step_length_walk_sd_m.
  opt.step_length_mean_m = 0.415 * a.user_height_m;
  if (!(opt.min_length_m > 0 && opt.max_length_m >= opt.min_length_m))
    throw std::invalid_argument("need 0 < --min-length <= --max-length");
  const terrain::SimulatedWalk w = terrain::simulate_walk(dem, opt, a.seed);
  {
    io::LogWriterOptions wo;
    wo.device = "pdnav simulate";
    io::LogWriter writer(a.log, wo);
    for (const Sample& s : walk_to_samples(w, dem, a.user_height_m, a.dem, a.seed, "pdnav simulate")) writer.write(s);
    writer.close();
  }
  const std::string truth = a.truth_csv.empty() ? a.log + ".truth.csv" : a.truth_csv;
  write_truth_csv(truth, w);
  std::printf("simulated %.0f m, %zu steps, %zu pressure samples, %.0f s; log %s, truth %s\n", w.length_m,
              w.steps.size(), w.pressure.size(), w.steps.empty() ? 0.0 : ns_to_s(w.steps.back().t_ns - w.t0_ns),
              a.log.c_str(), truth.c_str());
  return 0;
}

}  // namespace

void register_simulate(CLI::App& app) {
  auto a = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand("simulate", "Simulate a walk on a DEM tile: session log + truth CSV");
  cmd->add_option("--dem", a->dem, "DEM tile (.pdem)")->required();
  cmd->add_option("-o,--log", a->log, "session log to write")->required();
  cmd->add_option("--truth", a->truth_csv, "truth CSV (default: <log>.truth.csv)");
  cmd->add_option("--seed", a->seed, "random seed")->capture_default_str();
  cmd->add_option("--min-length", a->min_length_m, "shortest route, m")->capture_default_str();
  cmd->add_option("--max-length", a->max_length_m, "longest route, m")->capture_default_str();
  cmd->add_option("--user-height", a->user_height_m, "user height written to Meta, m")->capture_default_str();
  cmd->add_flag("--session", a->session,
                "write a whole phone session (IMU, rotation vector, barometer, steps, GNSS Raw + Fix, Truth) "
                "walking the walkway graph, with a GNSS outage (needs --graph and --nav)");
  cmd->add_option("--graph", a->graph, "walkway graph (dem-tools) for --session")->check(CLI::ExistingFile);
  cmd->add_option("--nav", a->nav, "RINEX broadcast navigation file(s) for --session")->check(CLI::ExistingFile);
  cmd->add_option("--outage-min", a->outage_min_min, "--session: shortest GNSS outage, minutes")->capture_default_str();
  cmd->add_option("--outage-max", a->outage_max_min, "--session: longest GNSS outage, minutes")->capture_default_str();
  cmd->add_option("--lead", a->lead_s, "--session: open-sky GNSS before the outage, s")->capture_default_str();
  cmd->add_option("--tail", a->tail_s, "--session: walking after the outage, s")->capture_default_str();
  cmd->add_flag("--declare-start", a->declare_start, "--session: write the start position as Meta lines");
  cmd->callback([a]() { run_simulate(*a); });
}

}  // namespace pdnav::cli
