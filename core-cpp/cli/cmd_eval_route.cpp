// pdnav eval-route: simulated walks on a walkway graph through the route engine (issue 6).
// The graph comes from --graph FILE, or from --osm FILE through dem-tools/pdnav_graph.py
// (cached by file identity). Prints a table per walk, the overall errors, and last:
//   median_turn_error_m: X p95_turn_error_m: Y gnss_median_error_m: Z
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "pdnav/route/route_engine.h"
#include "pdnav/route/walk_graph.h"
#include "pdnav/route/walk_sim.h"
#include "support/route_graph_cache.h"

namespace pdnav::cli {
namespace {

struct EvalRouteArgs {
  std::string osm_path;
  std::string graph_path;
  std::string cache_dir;
  std::string graph_tool = default_graph_tool();
  std::string python = "/usr/bin/python3";
  int walks = 50;
  std::uint64_t seed = 1;
  route::WalkSimOptions sim;
};

std::string fmt(double v, int prec = 2) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(prec) << v;
  return s.str();
}

int run_eval_route(const EvalRouteArgs& a) {
  std::string graph_path = a.graph_path;
  if (graph_path.empty()) {
    if (a.osm_path.empty()) throw std::runtime_error("eval-route: give --osm FILE or --graph FILE");
    graph_path = build_graph_cached(a.osm_path, a.cache_dir, a.graph_tool, a.python);
  }
  auto graph = std::make_shared<const route::WalkGraph>(route::WalkGraph::load(graph_path));
  std::cout << "graph: " << graph_path << "  vertices " << graph->vertex_count() << "  edges "
            << graph->edge_count() << "  length " << fmt(graph->total_length_m() / 1000.0, 1) << " km\n";
  const route::RouteOptions options;
  std::mt19937_64 seeds(a.seed);
  std::vector<double> turn_err, step_err, gnss_err;
  std::size_t lost = 0, steps = 0, restarts = 0, local_restarts = 0, fix_requests = 0, ambiguous = 0;
  std::cout << "walk  length_m turns missed fixes turn_med_m turn_p95_m step_med_m lost_% amb_% restarts max_routes\n";
  for (int i = 0; i < a.walks; ++i) {
    const route::SimWalk w = route::simulate_walk(*graph, a.sim, seeds());
    const route::WalkScore s = route::score_walk(graph, options, w);
    std::cout << std::setw(4) << i << std::setw(10) << fmt(w.length_m, 0) << std::setw(6) << w.turns
              << std::setw(7) << w.bends_missed << std::setw(6) << s.gnss_errors_m.size()
              << std::setw(11) << fmt(route::quantile(s.turn_errors_m, 0.5))
              << std::setw(11) << fmt(route::quantile(s.turn_errors_m, 0.95))
              << std::setw(11) << fmt(route::quantile(s.step_errors_m, 0.5))
              << std::setw(7) << fmt(100.0 * static_cast<double>(s.lost_steps) / static_cast<double>(std::max<std::size_t>(1, s.step_errors_m.size())), 1)
              << std::setw(6) << fmt(100.0 * static_cast<double>(s.ambiguous_steps) / static_cast<double>(std::max<std::size_t>(1, s.step_errors_m.size())), 1)
              << std::setw(5) << s.restarts << "+" << std::setw(3) << s.local_restarts << std::setw(11) << s.max_routes << "\n";
    turn_err.insert(turn_err.end(), s.turn_errors_m.begin(), s.turn_errors_m.end());
    step_err.insert(step_err.end(), s.step_errors_m.begin(), s.step_errors_m.end());
    gnss_err.insert(gnss_err.end(), s.gnss_errors_m.begin(), s.gnss_errors_m.end());
    lost += s.lost_steps;
    ambiguous += s.ambiguous_steps;
    fix_requests += s.fix_request_steps;
    steps += s.step_errors_m.size();
    restarts += s.restarts;
    local_restarts += s.local_restarts;
  }
  const double steps_d = static_cast<double>(std::max<std::size_t>(1, steps));
  std::cout << "walks: " << a.walks << "  turn points: " << turn_err.size() << "  steps: " << steps
            << "  gnss fixes: " << gnss_err.size() << "  restarts (fix + local): " << restarts << " + " << local_restarts << "\n";
  std::cout << "lost_steps_pct: " << fmt(100.0 * static_cast<double>(lost) / steps_d)
            << "  ambiguous_steps_pct: " << fmt(100.0 * static_cast<double>(ambiguous) / steps_d)
            << "  fix_request_steps_pct: " << fmt(100.0 * static_cast<double>(fix_requests) / steps_d) << "\n";
  std::cout << "overall_median_error_m: " << fmt(route::quantile(step_err, 0.5))
            << " overall_p95_error_m: " << fmt(route::quantile(step_err, 0.95)) << "\n";
  std::cout << "median_turn_error_m: " << fmt(route::quantile(turn_err, 0.5))
            << " p95_turn_error_m: " << fmt(route::quantile(turn_err, 0.95))
            << " gnss_median_error_m: " << fmt(route::quantile(gnss_err, 0.5)) << std::endl;
  return 0;
}

}  // namespace

void register_eval_route(CLI::App& app) {
  auto args = std::make_shared<EvalRouteArgs>();
  CLI::App* cmd = app.add_subcommand(
      "eval-route", "Simulated walks on an OSM walkway graph through the route engine (APT matcher)");
  cmd->add_option("--osm", args->osm_path, "OpenStreetMap extract (.osm.pbf/.osm); graph built with dem-tools")
      ->check(CLI::ExistingFile);
  cmd->add_option("--graph", args->graph_path, "pdnav walkway graph file (instead of --osm)")->check(CLI::ExistingFile);
  cmd->add_option("--walks", args->walks, "number of simulated walks")->check(CLI::Range(1, 100000))->capture_default_str();
  cmd->add_option("--seed", args->seed, "random seed of the walks")->capture_default_str();
  cmd->add_option("--cache-dir", args->cache_dir, "where graphs built from --osm are kept (default: system temp)");
  cmd->add_option("--graph-tool", args->graph_tool, "dem-tools/pdnav_graph.py")->capture_default_str();
  cmd->add_option("--python", args->python, "python with GDAL for the graph tool")->capture_default_str();
  cmd->add_option("--min-turns", args->sim.min_turns, "reported turns per walk")->capture_default_str();
  cmd->add_option("--gnss-error", args->sim.gnss_error_m, "RMS horizontal GNSS fix error, m")->capture_default_str();
  cmd->add_option("--step-scale-error", args->sim.step_scale_error, "PDR step length scale error bound")->capture_default_str();
  cmd->callback([args]() {
    const int rc = run_eval_route(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace pdnav::cli
