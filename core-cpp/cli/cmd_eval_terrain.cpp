// pdnav eval-terrain: simulated walks on a DEM tile, dead reckoning vs the terrain particle
// filter. Prints a table and, as the last line, "median_ratio: X coverage: Y".
// --path app (default): each walk is written as a session log (io::LogWriter), read back
// (io::LogReader) and replayed through fusion::Navigator -- PDR from the Android step events and
// rotation vector, APT step length -- exactly as `pdnav replay` does, once with the terrain
// engine and once with dead reckoning, scored by the replay's own statistics (ReplayRecorder).
// --path direct: the simulator's measured steps are fed to a TerrainEngine in memory.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include <unistd.h>

#include "pdnav/fusion/navigator.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/io/log_writer.h"
#include "pdnav/terrain/dem.h"
#include "pdnav/terrain/simulator.h"
#include "pdnav/terrain/terrain_engine.h"
#include "support/eval_support.h"
#include "support/replay_support.h"
#include "support/walk_log.h"

namespace pdnav::cli {
namespace {

struct EvalArgs {
  std::string dem;
  int walks = 20;
  std::uint64_t seed = 1;
  int particles = 500;
  std::string preset = "srtm-tuned";
  std::string resampling = "multinomial";
  double min_length_m = 1000.0;
  double max_length_m = 5000.0;
  bool no_monitor = false;
  bool no_anchor = false;         // ablations of the issue-17 additions (direct path)
  bool no_uninformative = false;
  std::string path = "app";
  double user_height_m = 1.75;
  std::string tmp_dir;  // empty: the system temp directory
};

/// One walk replayed through the app's path (log writer -> reader -> Navigator).
struct AppWalkResult {
  terrain::WalkEvaluation ev;
  std::int64_t ambiguous_epochs = 0;      // terrain estimate status kAmbiguous
  std::int64_t uninformative_epochs = 0;  // status kDegraded, reason "terrain uninformative"
};

/// Replays the log at `log` through a Navigator in `mode`, as `pdnav replay` does.
ReplayRecorder replay_log(const std::string& log, const EvalArgs& a, std::shared_ptr<const terrain::Dem> dem,
                          fusion::EngineMode mode, std::uint64_t seed) {
  fusion::NavigatorConfig c;
  c.mode = mode;
  c.dem = std::move(dem);
  c.particles = a.particles;
  c.terrain_preset = a.preset;
  io::LogReader reader(log);
  fusion::Navigator nav(c, seed);
  ReplayRecorder rec;
  Sample s;
  while (reader.next(s)) {
    rec.observe_reference(s);
    nav.feed(s);
    rec.observe_estimate(nav.estimate());
  }
  rec.finish();
  if (reader.stats().skipped_total() != 0)
    throw std::runtime_error(log + ": the reader skipped " + std::to_string(reader.stats().skipped_total()) +
                             " lines the writer wrote");
  return rec;
}

AppWalkResult evaluate_app_path(const terrain::SimulatedWalk& walk, const EvalArgs& a,
                                std::shared_ptr<const terrain::Dem> dem, std::uint64_t seed, int k) {
  const std::filesystem::path dir =
      a.tmp_dir.empty() ? std::filesystem::temp_directory_path() : std::filesystem::path(a.tmp_dir);
  const std::string log = (dir / ("pdnav-eval-terrain-" + std::to_string(::getpid()) + "-" + std::to_string(k) +
                                  ".log")).string();
  {
    io::LogWriterOptions wo;
    wo.device = "pdnav eval-terrain";
    io::LogWriter writer(log, wo);
    for (const Sample& s : walk_to_samples(walk, *dem, a.user_height_m, a.dem, walk.seed)) writer.write(s);
    writer.close();
  }
  AppWalkResult out;
  terrain::WalkEvaluation& ev = out.ev;
  ev.length_m = walk.length_m;
  try {
    const ReplayRecorder pf = replay_log(log, a, dem, fusion::EngineMode::kTerrain, seed);
    const ReplayRecorder dr = replay_log(log, a, dem, fusion::EngineMode::kDeadReckoning, seed);
    std::filesystem::remove(log);
    const ErrorStats spf = pf.error_stats(), sdr = dr.error_stats();
    ev.epochs = static_cast<std::size_t>(spf.n);
    ev.pf_drms_m = spf.drms_m;
    ev.dr_drms_m = sdr.drms_m;
    ev.coverage_1sigma = spf.coverage_68;  // the 68.27 % ellipse (eval-terrain's "coverage")
    ev.coverage_unit = spf.coverage_1sigma;  // the unit ellipse (39.35 %)
    ev.inside_1sigma = static_cast<std::size_t>(std::lround(spf.coverage_68 * static_cast<double>(spf.n)));
    ev.inside_unit = static_cast<std::size_t>(std::lround(spf.coverage_1sigma * static_cast<double>(spf.n)));
    ev.median_percentile = spf.median_percentile;
    for (const Epoch& e : pf.epochs()) {
      if (!e.est.en_m.allFinite() || !e.est.cov_en_m2.allFinite()) ev.all_finite = false;
      if (e.est.status == EstimateStatus::kAmbiguous) ++out.ambiguous_epochs;
      if (e.est.reason.find("terrain uninformative") != std::string::npos) ++out.uninformative_epochs;
      if (e.has_ref) ev.final_pf_error_m = std::hypot(e.err_e_m, e.err_n_m);
    }
    for (const Epoch& e : dr.epochs())
      if (e.has_ref) ev.final_dr_error_m = std::hypot(e.err_e_m, e.err_n_m);
    ev.all_finite = ev.all_finite && spf.n > 0 && sdr.n > 0 && std::isfinite(spf.drms_m) && std::isfinite(sdr.drms_m);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(log, ec);
    throw;
  }
  return out;
}

int run_eval(const EvalArgs& a) {
  if (a.walks < 1) throw std::invalid_argument("--walks must be >= 1");
  if (a.path != "app" && a.path != "direct") throw std::invalid_argument("--path must be app or direct");
  const bool app = a.path == "app";
  auto dem = std::make_shared<const terrain::Dem>(terrain::Dem::load(a.dem));
  terrain::TerrainOptions opt = terrain::TerrainOptions::preset(a.preset);
  opt.particles = a.particles;
  opt.resampling = terrain::resampling_from_string(a.resampling);
  opt.residual_monitor = !a.no_monitor;
  if (a.no_anchor) opt.anchor_start_bias = false;
  if (a.no_uninformative) opt.uninformative_relief_sigmas = 0.0;
  terrain::WalkSimOptions sim;
  sim.min_length_m = a.min_length_m;
  sim.max_length_m = a.max_length_m;
  // On the app path the walker's mean step follows the APT height model the Navigator's PDR
  // uses (l = 0.415 h, Zhu et al. Sec. V-A), as `pdnav simulate` does; each walk still deviates.
  if (app) sim.step_length_mean_m = 0.415 * a.user_height_m;
  std::printf("# eval-terrain: dem %s, %d walks, seed %llu, %d particles, preset %s, resampling %s, path %s\n",
              a.dem.c_str(), a.walks, static_cast<unsigned long long>(a.seed), a.particles, a.preset.c_str(),
              a.resampling.c_str(), a.path.c_str());
  if (app && (a.resampling != "multinomial" || a.no_monitor || a.no_anchor || a.no_uninformative))
    throw std::invalid_argument(
        "--resampling / --no-monitor / --no-anchor / --no-uninformative are ablations of --path direct (the Navigator "
        "uses the preset)");
  std::printf("# coverage = fraction of steps with the truth inside the 1-sigma ellipse (68.27 %% content,\n"
              "# Mahalanobis^2 <= 2.296); cov_unit = inside the unit-covariance ellipse (39.35 %% content)\n");
  std::printf("%4s %9s %10s %10s %7s %9s %9s %9s %9s %6s\n", "walk", "length_m", "dr_drms_m", "pf_drms_m", "ratio",
              "coverage", "cov_unit", "final_dr", "final_pf", app ? "ambig" : "recov");
  std::vector<double> ratios, percentiles;
  std::size_t inside = 0, inside_unit = 0, epochs = 0;
  std::int64_t ambiguous = 0, uninformative = 0;
  bool finite = true;
  // Walk k uses seed index k; a seed index whose route does not fit the tile (too steep, too
  // many voids) is reported and replaced by the next unused index, up to 3 x walks indices.
  int next_index = 0, done = 0;
  while (done < a.walks) {
    const int k = next_index++;
    if (k >= 3 * a.walks)
      throw std::runtime_error("eval-terrain: only " + std::to_string(done) + " of " + std::to_string(a.walks) +
                               " walks fit the tile after " + std::to_string(k) + " seeds");
    const std::uint64_t ws = terrain::walk_seed(a.seed, static_cast<std::uint64_t>(k));
    terrain::SimulatedWalk walk;
    try {
      walk = terrain::simulate_walk(*dem, sim, ws);
    } catch (const std::runtime_error& e) {
      std::printf("# walk seed index %d skipped: %s\n", k, e.what());
      continue;
    }
    ++done;
    AppWalkResult res;
    if (app) res = evaluate_app_path(walk, a, dem, ws ^ 0xA5A5A5A5ULL, k);
    else res.ev = terrain::evaluate_walk(walk, dem, opt, ws ^ 0xA5A5A5A5ULL);
    const terrain::WalkEvaluation& ev = res.ev;
    ambiguous += res.ambiguous_epochs;
    uninformative += res.uninformative_epochs;
    const double ratio = ev.pf_drms_m / ev.dr_drms_m;
    ratios.push_back(ratio);
    percentiles.push_back(ev.median_percentile);
    inside += ev.inside_1sigma;
    inside_unit += ev.inside_unit;
    epochs += ev.epochs;
    finite = finite && ev.all_finite && std::isfinite(ratio);
    std::printf("%4d %9.0f %10.1f %10.1f %7.3f %9.3f %9.3f %9.1f %9.1f %6lld\n", k, ev.length_m, ev.dr_drms_m,
                ev.pf_drms_m, ratio, ev.coverage_1sigma, ev.coverage_unit, ev.final_dr_error_m, ev.final_pf_error_m,
                static_cast<long long>(app ? res.ambiguous_epochs : ev.stats.recoveries));
    std::fflush(stdout);
  }
  const double coverage = epochs ? static_cast<double>(inside) / static_cast<double>(epochs) : 0.0;
  std::printf("# all estimates finite: %s; pooled over %zu steps: coverage %.3f, cov_unit %.3f\n",
              finite ? "yes" : "NO", epochs, coverage,
              epochs ? static_cast<double>(inside_unit) / static_cast<double>(epochs) : 0.0);
  std::printf("# terrain status over the epochs: %lld ambiguous, %lld uninformative\n",
              static_cast<long long>(ambiguous), static_cast<long long>(uninformative));
  std::printf("# median over the walks of the median step's error percentile in its stated distribution: %s "
              "(50 = calibrated; a walk's coverage is a few draws)\n",
              fixed_or(median_of_finite(percentiles), 1, "-").c_str());
  // a walk whose ratio is not finite has already made the run fail (exit 3, "finite: NO"); the
  // median is of the finite ones (sorting a NaN is undefined)
  std::printf("median_ratio: %.3f coverage: %.3f\n", median_of_finite(ratios), coverage);
  return finite ? 0 : 3;
}

}  // namespace

void register_eval_terrain(CLI::App& app) {
  auto a = std::make_shared<EvalArgs>();
  CLI::App* cmd = app.add_subcommand(
      "eval-terrain", "Simulated walks on a DEM tile: dead reckoning vs terrain particle filter (DRMS, coverage)");
  cmd->add_option("--dem", a->dem, "DEM tile (.pdem, dem-tools/pdnav_dem.py tile)")->required();
  cmd->add_option("--walks", a->walks, "number of simulated walks")->capture_default_str();
  cmd->add_option("--seed", a->seed, "base seed (walk k uses a seed derived from it)")->capture_default_str();
  cmd->add_option("--particles", a->particles, "particles")->capture_default_str();
  cmd->add_option("--preset", a->preset, "terrain options: srtm-tuned, srtm (paper SRTM tuning) or paper")->capture_default_str();
  cmd->add_option("--resampling", a->resampling, "multinomial, systematic or stratified")->capture_default_str();
  cmd->add_option("--min-length", a->min_length_m, "shortest route, m")->capture_default_str();
  cmd->add_option("--max-length", a->max_length_m, "longest route, m")->capture_default_str();
  cmd->add_option("--path", a->path,
                  "app: each walk through the session log writer, reader, PDR and Navigator as `pdnav replay` "
                  "does (the number users get); direct: the simulator's steps into the filter in memory")
      ->capture_default_str();
  cmd->add_option("--user-height", a->user_height_m, "user height for the app path's APT step length, m")
      ->capture_default_str();
  cmd->add_option("--tmp-dir", a->tmp_dir, "where the app path writes each walk's log (removed after)");
  cmd->add_flag("--no-monitor", a->no_monitor, "disable residual monitoring (ablation)");
  cmd->add_flag("--no-anchor", a->no_anchor, "every particle's baro bias starts at 0, the paper's (ablation)");
  cmd->add_flag("--no-uninformative", a->no_uninformative, "never skip updates on featureless terrain (ablation)");
  cmd->callback([a]() {
    const int rc = run_eval(*a);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace pdnav::cli
