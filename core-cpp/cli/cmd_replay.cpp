// pdnav replay LOG --out DIR: stream a session log through fusion::Navigator and write the
// estimated track (CSV + GeoJSON with error ellipses), a JSON summary and, when the log
// carries a reference (Truth lines, else the phone's GPS Fix lines), error statistics.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "pdnav/fusion/navigator.h"
#include "pdnav/io/sample_source.h"
#include "pdnav/pdr/pdr.h"
#include "pdnav/terrain/terrain_engine.h"
#include "support/eval_support.h"
#include "support/replay_support.h"
#include "support/sources.h"

namespace pdnav::cli {
namespace {

struct ReplayArgs {
  std::string log;
  std::string format = "auto";
  std::string out_dir;
  std::string engine = "auto";
  std::string dem;
  std::string graph;
  std::vector<std::string> nav;
  std::string start;
  int particles = 500;
  std::string preset = "srtm-tuned";
  std::uint64_t seed = 1;
  double height_m = std::numeric_limits<double>::quiet_NaN();  // NaN: the log's, else 1.75 m
  std::string mount = "auto";
  bool quiet = false;
};

fusion::NavigatorConfig make_config(const ReplayArgs& a) {
  fusion::NavigatorConfig c;
  c.mode = fusion::engine_mode_from_string(a.engine);
  c.dem_path = a.dem;
  c.graph_path = a.graph;
  c.nav_paths = a.nav;
  c.particles = a.particles;
  c.terrain_preset = a.preset;
  c.user_height_m = a.height_m;
  c.mount = pdr::mount_from_string(a.mount);
  if (!a.start.empty()) {
    const std::vector<double> v = parse_number_list(a.start, "--start");
    if (v.size() < 2 || v.size() > 3) throw std::invalid_argument("--start wants LAT,LON[,SIGMA_M]");
    c.start_lat_deg = v[0];
    c.start_lon_deg = v[1];
    if (v.size() == 3) c.start_sigma_m = v[2];
  }
  return c;
}

/// The fused estimate's hand-overs, for the track CSV.
std::vector<std::pair<TimeNs, std::string>> mode_change_notes(const fusion::Navigator& nav) {
  std::vector<std::pair<TimeNs, std::string>> out;
  for (const fusion::ModeChange& c : nav.mode_changes())
    out.emplace_back(c.t_ns, std::string(fusion::to_string(c.from)) + " -> " + fusion::to_string(c.to) + ": " + c.reason);
  return out;
}

/// summary.json "fusion": mode changes with reasons, counters, the PDR calibration in use.
nlohmann::json fusion_summary(const fusion::Navigator& nav) {
  nlohmann::json changes = nlohmann::json::array();
  for (const fusion::ModeChange& c : nav.mode_changes())
    changes.push_back({{"t_ns", c.t_ns}, {"from", fusion::to_string(c.from)}, {"to", fusion::to_string(c.to)}, {"reason", c.reason}});
  nlohmann::json counts = nlohmann::json::object();
  for (const auto& [k, v] : nav.fusion_counts()) counts[k] = v;
  const fusion::NavigatorOutput o = nav.output(0);
  const fusion::PdrCalibration& cal = o.calibration;
  return {{"mode", fusion::to_string(o.mode)},
          {"mode_change_count", o.mode_change_count},
          {"mode_changes", changes},
          {"counts", counts},
          {"pdr_calibration", pdr_calibration_json(cal)}};
}

/// Why a replay produced no position at all (an empty track is an error, not a success).
std::string no_estimate_reason(const fusion::Navigator& nav, const io::ReadStats& stats) {
  const fusion::NavigatorOutput o = nav.output(0);
  const auto count = [&stats](const char* type) {
    const auto it = stats.samples_by_type.find(type);
    return it == stats.samples_by_type.end() ? std::int64_t{0} : it->second;
  };
  if (o.mode == fusion::FusionMode::kNotStarted)
    return "no position estimated: the log gives no start position (no Meta StartLatitudeDegrees / "
           "StartLongitudeDegrees, no GNSS Fix row, no Raw measurements with navigation data: --nav or Nav rows); "
           "give one with --start LAT,LON[,SIGMA_M] (" + std::to_string(o.steps) + " steps detected, " +
           std::to_string(count("Fix")) + " Fix rows, " + std::to_string(count("Raw")) + " Raw rows)";
  return "no position estimated: the Navigator started but gave no valid estimate (" + std::to_string(o.steps) +
         " steps detected)";
}

int run_replay(const ReplayArgs& a) {
  const auto t0 = std::chrono::steady_clock::now();
  std::filesystem::create_directories(a.out_dir);
  const std::unique_ptr<io::SampleSource> source = open_source(a.log, a.format);
  io::SampleSource& reader = *source;
  const fusion::NavigatorConfig config = make_config(a);
  fusion::Navigator nav(config, a.seed);
  TimeNs t0_ns = -1;
  ReplayRecorder rec;
  ProgressBar progress(a.quiet ? nullptr : &std::cerr, "replay");
  Sample s;
  while (reader.next(s)) {
    rec.observe_reference(s);
    nav.feed(s);
    std::visit(
        [&](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, AccelSample> || std::is_same_v<T, GyroSample> || std::is_same_v<T, MagSample> ||
                        std::is_same_v<T, RotationVectorSample> || std::is_same_v<T, StepDetectorSample> ||
                        std::is_same_v<T, UncalAccelSample> || std::is_same_v<T, UncalGyroSample> ||
                        std::is_same_v<T, UncalMagSample>) {
            if (t0_ns < 0) t0_ns = x.t_ns;  // the summary's times count from the first motion sample
          }
        },
        s);
    for (const Estimate& e : nav.take_step_estimates()) rec.observe_estimate(e);  // a row per step
    const Estimate shown = nav.estimate();
    rec.observe_estimate(shown);
    if (shown.valid() && rec.engines_due(shown.t_ns)) rec.observe_engines(shown.t_ns, nav.output(0).engines);
    progress.update(reader.progress());
  }
  nav.finish();  // a walk shorter than the bout gate is still reported
  for (const Estimate& e : nav.take_step_estimates()) rec.observe_estimate(e);
  rec.observe_estimate(nav.estimate());
  progress.done();
  rec.finish();
  rec.set_mode_changes(mode_change_notes(nav));
  const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const std::filesystem::path out(a.out_dir);
  rec.write_track_csv((out / "track.csv").string());
  rec.write_geojson((out / "track.geojson").string());
  rec.write_engines_csv((out / "engines.csv").string());
  nlohmann::json summary;
  summary["log"] = a.log;
  summary["format"] = std::string(io::format_name(reader.format()));
  summary["engine_mode"] = a.engine;
  summary["seed"] = a.seed;
  summary["run_time_s"] = run_s;
  summary["lines"] = reader.stats().lines;
  summary["samples"] = reader.stats().samples;
  summary["samples_by_type"] = reader.stats().samples_by_type;
  summary["skipped_lines_by_reason"] = reader.stats().skipped_by_reason;
  summary["samples_reordered"] = {{"samples", reader.stats().reordered}, {"window_s", reader.stats().reorder_window_s}};
  summary["not_used"] = reader.stats().not_used;
  nlohmann::json issues = nlohmann::json::array();
  for (const auto& i : reader.stats().issues) issues.push_back(i.to_string());
  summary["first_issues"] = issues;
  nlohmann::json ignored = nlohmann::json::object();
  for (const auto& [k, v] : nav.ignored()) ignored[k] = v;
  summary["navigator_ignored_by_reason"] = ignored;
  summary["epochs"] = rec.epochs().size();
  summary["epochs_by_engine"] = rec.epochs_by_engine();
  const ErrorStats st = rec.error_stats();
  if (st.n > 0) summary["errors"] = st.to_json();
  summary["reference"] = rec.reference_kind();
  summary["fusion"] = fusion_summary(nav);
  if (const terrain::TerrainOptions* to = nav.terrain_options())  // the terrain engine as configured
    summary["terrain"] = {{"preset", a.preset},
                          {"particles", to->particles},
                          {"walker_scale_sigma", to->step_scale_sigma},
                          {"walk_grade_sigma", to->stride_walk_grade_sigma}};
  summary["pdr"] = pdr_summary_json(nav.pdr(), nav.output(0).steps, std::max<TimeNs>(0, t0_ns));
  const fusion::NavigatorOutput o = nav.output(0);  // the PDR declination: model and any warning (#19.2)
  summary["declination"] = {{"known", o.declination_known}, {"deg", rad_to_deg(o.declination.declination_rad)},
                            {"model", o.declination.model}, {"warning", o.declination.warning}};
  std::ofstream(out / "summary.json") << summary.dump(2) << "\n";

  std::cout << "log:      " << a.log << " (" << io::format_name(reader.format()) << ")\n"
            << "samples:  " << reader.stats().samples << " (skipped lines: " << reader.stats().skipped_total() << ")\n";
  for (const auto& [type, n] : reader.stats().samples_by_type) std::cout << "  " << type << ": " << n << "\n";
  for (const auto& [why, n] : reader.stats().skipped_by_reason) std::cout << "  skipped " << n << ": " << why << "\n";
  print_not_used(std::cout, reader.stats());
  if (reader.stats().reordered > 0)
    std::cout << "  reordered " << reader.stats().reordered << ": motion-sensor samples read in time order, not file order (batched; the latest "
              << reader.stats().reorder_window_s << " s late)\n";
  {
    // the PDR in one line: what it counted and refused, and whether it thought it rode a vehicle
    const nlohmann::json& p = summary["pdr"];
    const auto f1 = [](double v) {
      char b[32];
      std::snprintf(b, sizeof b, "%.1f", v);
      return std::string(b);
    };
    std::cout << "pdr:      " << p["steps"].get<std::int64_t>() << " steps, " << f1(p["distance_m"].get<double>()) << " m ("
              << p["sensor_set"].get<std::string>() << ", heading: " << p["heading_reference"].get<std::string>()
              << "); refused: handling " << p["steps_refused_handling"].get<std::int64_t>() << ", vehicle "
              << p["steps_refused_vehicle"].get<std::int64_t>() << "; vehicle spans: ";
    if (p["vehicle_spans"].empty()) std::cout << "none";
    for (std::size_t i = 0; i < p["vehicle_spans"].size(); ++i)
      std::cout << (i ? ", " : "") << f1(p["vehicle_spans"][i]["start_s"].get<double>()) << "-"
                << f1(p["vehicle_spans"][i]["end_s"].get<double>()) << " s";
    double handled_s = 0.0;
    for (const auto& h : p["handling_spans"]) handled_s += h["end_s"].get<double>() - h["start_s"].get<double>();
    std::cout << "; handling spans: " << p["handling_spans"].size() << " (" << f1(handled_s) << " s)";
    std::cout << "; longest step delay " << f1(p["max_step_delay_s"].get<double>()) << " s\n";
    if (!p["accel_rate_warning"].get<std::string>().empty())
      std::cout << "warning:  " << p["accel_rate_warning"].get<std::string>() << "\n";
  }
  std::cout << "epochs:   " << rec.epochs().size() << "\n";
  std::cout << "mode changes: " << nav.output(0).mode_change_count << " (summary.json fusion.mode_changes)\n";
  for (const auto& [eng, n] : rec.epochs_by_engine()) std::cout << "  " << eng << ": " << n << "\n";
  std::cout << "run time: " << run_s << " s\n"
            << "wrote:    " << (out / "track.csv").string() << ", track.geojson, engines.csv, summary.json\n";
  if (st.n > 0) {
    std::cout << "reference: " << rec.reference_kind() << " (" << st.n << " epochs)\n";
    std::cout << "drms_m: " << st.drms_m << " rms_e_m: " << st.rms_e_m << " rms_n_m: " << st.rms_n_m
              << " p50_h_m: " << st.p50_h_m << " p95_h_m: " << st.p95_h_m
              << " coverage_1sigma: " << st.coverage_1sigma << " coverage_68: " << st.coverage_68 << "\n";
    std::cout << "median_error_percentile: " << fixed_or(st.median_percentile, 1, "nan")
              << " (where the median epoch's error falls in its stated distribution; 50 = calibrated)\n";
  } else if (!rec.epochs().empty()) {
    std::cout << "reference: none (no Truth or GPS Fix lines): no error statistics\n";
  }
  if (rec.epochs().empty()) throw std::runtime_error(a.log + ": " + no_estimate_reason(nav, reader.stats()));
  return 0;
}

}  // namespace

void register_replay(CLI::App& app) {
  auto a = std::make_shared<ReplayArgs>();
  CLI::App* c = app.add_subcommand("replay", "Replay a session log through the core; write track, GeoJSON, summary");
  c->add_option("log", a->log, "session log (pdnav or GnssLogger), Sensor Logger / phyphox export (folder or zip), GetSensorData log")->required()->check(CLI::ExistingPath);
  add_format_option(c, a->format);
  c->add_option("--out", a->out_dir, "output directory")->required();
  c->add_option("--engine", a->engine, "auto | dr | terrain | route | gnss")->capture_default_str();
  c->add_option("--dem", a->dem, "DEM tile (.pdem from dem-tools) for the terrain engine")->check(CLI::ExistingFile);
  c->add_option("--graph", a->graph, "walkway graph (from dem-tools) for the route engine")->check(CLI::ExistingFile);
  c->add_option("--nav", a->nav, "RINEX navigation file(s) for the GNSS engine")->check(CLI::ExistingFile);
  c->add_option("--start", a->start, "start position LAT,LON[,SIGMA_M] (default: from the log)");
  c->add_option("--particles", a->particles, "terrain particle count")->capture_default_str();
  c->add_option("--terrain-preset", a->preset, "paper | srtm | srtm-tuned")->capture_default_str();
  c->add_option("--height", a->height_m,
                 "user height in metres for the step length (default: the log's Meta UserHeightMeters, else 1.75)");
  c->add_option("--mount", a->mount, "phone placement: auto (estimated from the motion) | chest | hand | ...")
      ->capture_default_str();
  c->add_option("--seed", a->seed, "random seed")->capture_default_str();
  c->add_flag("--quiet", a->quiet, "no progress bar");
  c->callback([a]() {
    const int rc = run_replay(*a);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace pdnav::cli
