// pdnav eval-terrain: simulated walks on a DEM tile, dead reckoning vs the terrain particle
// filter. Prints a table and, as the last line, "median_ratio: X coverage: Y".
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pdnav/terrain/dem.h"
#include "pdnav/terrain/simulator.h"
#include "pdnav/terrain/terrain_engine.h"

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
};

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

int run_eval(const EvalArgs& a) {
  if (a.walks < 1) throw std::invalid_argument("--walks must be >= 1");
  auto dem = std::make_shared<const terrain::Dem>(terrain::Dem::load(a.dem));
  terrain::TerrainOptions opt = terrain::TerrainOptions::preset(a.preset);
  opt.particles = a.particles;
  opt.resampling = terrain::resampling_from_string(a.resampling);
  opt.residual_monitor = !a.no_monitor;
  terrain::WalkSimOptions sim;
  sim.min_length_m = a.min_length_m;
  sim.max_length_m = a.max_length_m;
  std::printf("# eval-terrain: dem %s, %d walks, seed %llu, %d particles, preset %s, resampling %s\n",
              a.dem.c_str(), a.walks, static_cast<unsigned long long>(a.seed), a.particles, a.preset.c_str(),
              a.resampling.c_str());
  std::printf("# coverage = fraction of steps with the truth inside the 1-sigma ellipse (68.27 %% content,\n"
              "# Mahalanobis^2 <= 2.296); cov_unit = inside the unit-covariance ellipse (39.35 %% content)\n");
  std::printf("%4s %9s %10s %10s %7s %9s %9s %9s %9s %6s\n", "walk", "length_m", "dr_drms_m", "pf_drms_m", "ratio",
              "coverage", "cov_unit", "final_dr", "final_pf", "recov");
  std::vector<double> ratios;
  std::size_t inside = 0, inside_unit = 0, epochs = 0;
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
    const terrain::WalkEvaluation ev = terrain::evaluate_walk(walk, dem, opt, ws ^ 0xA5A5A5A5ULL);
    const double ratio = ev.pf_drms_m / ev.dr_drms_m;
    ratios.push_back(ratio);
    inside += ev.inside_1sigma;
    inside_unit += ev.inside_unit;
    epochs += ev.epochs;
    finite = finite && ev.all_finite && std::isfinite(ratio);
    std::printf("%4d %9.0f %10.1f %10.1f %7.3f %9.3f %9.3f %9.1f %9.1f %6lld\n", k, ev.length_m, ev.dr_drms_m,
                ev.pf_drms_m, ratio, ev.coverage_1sigma, ev.coverage_unit, ev.final_dr_error_m, ev.final_pf_error_m,
                static_cast<long long>(ev.stats.recoveries));
    std::fflush(stdout);
  }
  const double coverage = epochs ? static_cast<double>(inside) / static_cast<double>(epochs) : 0.0;
  std::printf("# all estimates finite: %s; pooled over %zu steps: coverage %.3f, cov_unit %.3f\n",
              finite ? "yes" : "NO", epochs, coverage,
              epochs ? static_cast<double>(inside_unit) / static_cast<double>(epochs) : 0.0);
  std::printf("median_ratio: %.3f coverage: %.3f\n", median(ratios), coverage);
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
  cmd->add_flag("--no-monitor", a->no_monitor, "disable residual monitoring (ablation)");
  cmd->callback([a]() {
    const int rc = run_eval(*a);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace pdnav::cli
