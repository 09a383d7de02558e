// `pdnav steps FILE...`: steps, cadence and turns found by the pdr engine.
//   --format log     a session log (io::LogReader), all IMU lines through pdr::Pdr
//   --format oxford  an accelerometer CSV of the Oxford Step Counter data set
//   --table          one row per file (file, truth, detected, error) and the mean error
// The last line is always `steps: N` (the total over all files).
#include <algorithm>
#include <cmath>
#include <memory>
#include <type_traits>
#include <utility>
#include <variant>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pdnav/geo/wmm.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/io/sample_source.h"
#include "pdnav/pdr/pdr.h"
#include "support/pdr_oxford.h"
#include "support/replay_support.h"

namespace pdnav::cli {
namespace {

struct StepsArgs {
  std::vector<std::string> files;
  std::string format = "log";
  bool table = false;
  bool list = false;
  bool paper = false;
  bool female = false;
  std::string mount = "chest-camera-out";
  std::string source = "accel";
  double check_mean_pct = -1.0;   // fail (exit 1) when the table's mean |error| exceeds this
  double check_worst_pct = -1.0;  // fail when any file's |error| exceeds this
  pdr::PdrOptions options;
};

struct FileResult {
  std::string file;
  std::int64_t detected = 0;
  std::int64_t truth = -1;  // -1 = unknown
  double duration_s = 0.0;
  pdr::SampleCounters counters;
  std::int64_t android_events = 0;
  pdr::StepConsistency consistency;
  std::vector<PdrTurn> turns;
  std::vector<PdrStep> steps;
  std::string heading_frame;  // how the headings are referenced (true north via WMM, or magnetic)
  std::string rate_warning;   // the accelerometer's rate is below what the detector is measured at
  double max_delay_s = 0.0, max_delay_at_s = 0.0;  // longest step-to-emission latency, that step's time
};

void note_delay(FileResult& r, const pdr::PdrCounters& c, TimeNs t0_ns) {
  r.max_delay_s = c.max_step_delay_s;
  r.max_delay_at_s = c.max_step_delay_s > 0.0 ? ns_to_s(c.max_step_delay_at_ns - t0_ns) : 0.0;
}

/// Issue 19.4: the log's Meta start (StartLatitudeDegrees/StartLongitudeDegrees) and its first
/// UTC time give the WMM declination; without a start the headings stay magnetic, and say so.
struct MetaStart {
  double lat_deg = kNaN, lon_deg = kNaN;
  std::int64_t utc_ms = kMissingInt;
  bool applied = false;
  std::int64_t applied_utc_ms = kMissingInt;

  void note(const Sample& s) {
    if (const auto* m = std::get_if<MetaSample>(&s)) {
      try {
        if (m->key == "StartLatitudeDegrees") lat_deg = std::stod(m->value);
        if (m->key == "StartLongitudeDegrees") lon_deg = std::stod(m->value);
      } catch (const std::exception&) {
        std::cerr << "Meta " << m->key << ": not a number ('" << m->value << "'), ignored\n";
      }
    }
    if (utc_ms == kMissingInt) {
      std::visit(
          [&](const auto& x) {
            if constexpr (has_utc<std::decay_t<decltype(x)>>::value)
              if (x.utc_ms != kMissingInt && x.utc_ms > 0) utc_ms = x.utc_ms;
          },
          s);
    }
  }
  bool valid() const {
    return std::isfinite(lat_deg) && std::isfinite(lon_deg) && std::abs(lat_deg) <= 90.0 && std::abs(lon_deg) <= 180.0;
  }
  /// Tells the engine (again when the UTC time arrives after the start).
  void apply(pdr::Pdr& engine) {
    if (!valid() || (applied && applied_utc_ms == utc_ms)) return;
    engine.set_location(geo::Geodetic::from_deg(lat_deg, lon_deg, 0.0), utc_ms);
    applied = true;
    applied_utc_ms = utc_ms;
  }
};

std::string describe_frame(const pdr::Pdr& engine, const MetaStart& start) {
  if (!engine.has_location()) {
    return "headings are MAGNETIC (no declination applied: the log has no Meta StartLatitudeDegrees/"
           "StartLongitudeDegrees)";
  }
  const geo::Declination& d = engine.declination();
  char buf[256];
  std::snprintf(buf, sizeof buf, "headings are true north: declination %+.2f deg (%s, %.2f) at the log's Meta start %.5f, %.5f",
                rad_to_deg(d.declination_rad), d.model.c_str(), d.decimal_year, start.lat_deg, start.lon_deg);
  std::string out = buf;
  if (!d.warning.empty()) out += "; warning: " + d.warning;
  return out;
}

std::string base_name(const std::string& path) {
  const auto pos = path.find_last_of('/');
  return pos == std::string::npos ? path : path.substr(pos + 1);
}

/// Feeds any sample the engine understands; other line types are ignored.
void feed_sample(pdr::Pdr& engine, const Sample& s) {
  std::visit(
      [&](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, AccelSample> || std::is_same_v<T, GyroSample> ||
                      std::is_same_v<T, MagSample> || std::is_same_v<T, RotationVectorSample> ||
                      std::is_same_v<T, StepDetectorSample> || std::is_same_v<T, UncalAccelSample> ||
                      std::is_same_v<T, UncalGyroSample> || std::is_same_v<T, UncalMagSample>) {
          engine.feed(x);
        }
      },
      s);
}

FileResult run_log(const std::string& path, const pdr::PdrOptions& options) {
  // any recording pdnav reads (session, GnssLogger, Sensor Logger, phyphox, GetSensorData)
  const std::unique_ptr<io::SampleSource> source = io::open_sample_source(path);
  io::SampleSource& reader = *source;
  pdr::Pdr engine(options);
  FileResult r;
  r.file = path;
  Sample s;
  TimeNs t0 = 0, t1 = 0;
  bool first = true;
  MetaStart start;
  while (reader.next(s)) {
    const TimeNs t = sample_time_ns(s);
    if (first) t0 = t;
    first = false;
    t1 = std::max(t1, t);
    start.note(s);
    start.apply(engine);
    feed_sample(engine, s);
    for (auto& st : engine.take_steps()) r.steps.push_back(st);
    for (auto& tu : engine.take_turns()) r.turns.push_back(tu);
  }
  engine.finish();  // a walk too short for the bout gate still counts (issue 19.6)
  for (auto& st : engine.take_steps()) r.steps.push_back(st);
  r.heading_frame = describe_frame(engine, start);
  if (const double hz = engine.accel_rate_hz(); std::isfinite(hz) && hz < pdr::Pdr::kMinAccelRateHz)
    r.rate_warning = accel_rate_warning(hz);
  r.detected = engine.step_count();
  r.duration_s = first ? 0.0 : ns_to_s(t1 - t0);
  r.counters = engine.counters().accel;
  note_delay(r, engine.counters(), t0);
  r.android_events = engine.counters().step_detector.accepted;
  r.consistency = engine.consistency();
  if (reader.stats().skipped_total() > 0) {
    std::cerr << path << ": " << reader.stats().skipped_total() << " lines skipped by the reader";
    if (!reader.stats().issues.empty()) std::cerr << " (first: " << reader.stats().issues.front().to_string() << ")";
    std::cerr << "\n";
  }
  const pdr::PdrSensorSet& set = engine.sensor_set();
  if (set.accel + set.uncal_accel + set.step_detector == 0) {
    std::string types;
    for (const auto& [type, n] : reader.stats().samples_by_type)
      types += (types.empty() ? "" : ", ") + type + " " + std::to_string(n);
    throw std::runtime_error(path + ": no accelerometer or step-detector samples, no steps to detect (the recording holds " +
                             (types.empty() ? std::string("no samples") : types) + ")");
  }
  return r;
}

FileResult run_oxford(const std::string& path, const pdr::PdrOptions& options) {
  const OxfordRecording rec = read_oxford_csv(path);
  if (rec.skipped_lines > 0) {
    std::cerr << rec.first_issue << " (" << rec.skipped_lines << " malformed lines skipped)\n";
  }
  pdr::Pdr engine(options);
  FileResult r;
  r.file = path;
  r.truth = rec.truth_steps;
  for (const auto& s : rec.samples) {
    engine.feed(s);
    for (auto& st : engine.take_steps()) r.steps.push_back(st);
  }
  engine.finish();
  for (auto& st : engine.take_steps()) r.steps.push_back(st);
  r.detected = engine.step_count();
  r.counters = engine.counters().accel;
  note_delay(r, engine.counters(), rec.samples.empty() ? 0 : rec.samples.front().t_ns);
  if (rec.samples.size() >= 2) r.duration_s = ns_to_s(rec.samples.back().t_ns - rec.samples.front().t_ns);
  return r;
}

/// Median cadence (steps/s) from step intervals inside walking bouts.
double median_cadence_hz(const std::vector<PdrStep>& steps) {
  std::vector<double> intervals;
  for (std::size_t i = 1; i < steps.size(); ++i) {
    const double dt = ns_to_s(steps[i].t_ns - steps[i - 1].t_ns);
    if (dt > 0.0 && dt < 2.0) intervals.push_back(dt);
  }
  if (intervals.empty()) return 0.0;
  std::nth_element(intervals.begin(), intervals.begin() + static_cast<long>(intervals.size() / 2), intervals.end());
  return 1.0 / intervals[intervals.size() / 2];
}

void print_file(const FileResult& r, bool list) {
  std::printf("%s: %lld steps in %.1f s, cadence %.2f steps/s (median)", r.file.c_str(),
              static_cast<long long>(r.detected), r.duration_s, median_cadence_hz(r.steps));
  if (r.truth >= 0) std::printf(", truth %lld", static_cast<long long>(r.truth));
  std::printf("\n");
  if (!r.heading_frame.empty()) std::printf("  %s\n", r.heading_frame.c_str());
  if (!r.rate_warning.empty()) std::printf("  warning: %s\n", r.rate_warning.c_str());
  if (r.detected > 0) std::printf("  step latency: max %.2f s (the step at %.1f s)\n", r.max_delay_s, r.max_delay_at_s);
  const auto& c = r.counters;
  if (c.skipped() > 0 || c.gaps > 0) {
    std::printf("  accel samples skipped: %lld non-finite, %lld duplicate time, %lld backwards time; %lld gaps (detector reset)\n",
                static_cast<long long>(c.non_finite), static_cast<long long>(c.duplicate_time),
                static_cast<long long>(c.backwards_time), static_cast<long long>(c.gaps));
  }
  if (r.android_events > 0) {
    std::printf("  android step events: %lld; last 30 s: detector %lld vs android %lld (%s, %.0f %% apart)\n",
                static_cast<long long>(r.android_events), static_cast<long long>(r.consistency.accel_steps),
                static_cast<long long>(r.consistency.android_steps),
                r.consistency.consistent ? "consistent" : "INCONSISTENT", 100.0 * r.consistency.relative_difference);
  }
  if (list) {
    for (const auto& s : r.steps) {
      std::printf("  step t=%.3f s length=%.2f m heading=%.1f deg\n", ns_to_s(s.t_ns), s.length_m,
                  rad_to_deg(s.heading_rad));
    }
  }
  for (const auto& t : r.turns) {
    std::printf("  turn at %.2f s (%.2f-%.2f s), %.0f deg, %s\n", ns_to_s(t.t_ns), ns_to_s(t.start_ns),
                ns_to_s(t.t_ns), std::abs(rad_to_deg(t.angle_rad)), t.angle_rad > 0 ? "left" : "right");
  }
}

struct TableSummary {
  double mean_pct = 0.0;
  double worst_pct = 0.0;
  int files = 0;
};

TableSummary print_table(const std::vector<FileResult>& results) {
  std::printf("%-40s %7s %9s %8s\n", "file", "truth", "detected", "error");
  double sum = 0.0, worst = 0.0;
  int n = 0;
  for (const auto& r : results) {
    if (r.truth <= 0) {
      std::printf("%-40s %7s %9lld %8s\n", base_name(r.file).c_str(), "-", static_cast<long long>(r.detected), "-");
      continue;
    }
    const double err = 100.0 * static_cast<double>(r.detected - r.truth) / static_cast<double>(r.truth);
    std::printf("%-40s %7lld %9lld %+7.2f%%\n", base_name(r.file).c_str(), static_cast<long long>(r.truth),
                static_cast<long long>(r.detected), err);
    sum += std::abs(err);
    worst = std::max(worst, std::abs(err));
    ++n;
  }
  if (n > 0) std::printf("mean |error| %.2f %%, worst %.2f %% over %d files\n", sum / n, worst, n);
  return {n > 0 ? sum / n : 0.0, worst, n};
}

void run(const StepsArgs& args) {
  pdr::PdrOptions options = args.options;
  if (args.paper) {  // gates off, keep --window/--k
    const pdr::StepDetectorOptions paper = pdr::StepDetectorOptions::paper();
    const double window_s = options.detector.window_s, k = options.detector.k_sigma;
    options.detector = paper;
    options.detector.window_s = window_s;
    options.detector.k_sigma = k;
  }
  if (args.female) options.length.c1 = pdr::StepLengthModel::apt_female(options.length.height_m).c1;
  options.heading.mount = args.mount == "handheld"           ? pdr::Mount::kHandheld
                          : args.mount == "chest-screen-out" ? pdr::Mount::kChestScreenOut
                                                             : pdr::Mount::kChestCameraOut;
  options.source = args.source == "android" ? pdr::StepSource::kAndroid
                   : args.source == "auto"  ? pdr::StepSource::kAuto
                                            : pdr::StepSource::kAccelerometer;
  std::vector<FileResult> results;
  for (const auto& f : args.files) {
    if (args.format == "oxford") {
      results.push_back(run_oxford(f, options));
    } else if (args.format == "log") {
      results.push_back(run_log(f, options));
    } else {
      throw std::invalid_argument("unknown --format '" + args.format + "' (log or oxford)");
    }
  }
  std::int64_t total = 0;
  for (const auto& r : results) {
    total += r.detected;
    if (!args.table) print_file(r, args.list);
  }
  TableSummary summary;
  if (args.table) summary = print_table(results);
  std::printf("steps: %lld\n", static_cast<long long>(total));
  std::fflush(stdout);
  if (args.check_mean_pct >= 0.0 || args.check_worst_pct >= 0.0) {
    if (summary.files == 0) throw std::runtime_error("--check-* needs --table and files with a step truth");
    if (args.check_mean_pct >= 0.0 && summary.mean_pct > args.check_mean_pct) {
      throw std::runtime_error("mean |error| " + std::to_string(summary.mean_pct) + " % exceeds --check-mean");
    }
    if (args.check_worst_pct >= 0.0 && summary.worst_pct > args.check_worst_pct) {
      throw std::runtime_error("worst |error| " + std::to_string(summary.worst_pct) + " % exceeds --check-worst");
    }
  }
}

}  // namespace

void register_steps(CLI::App& app) {
  auto args = std::make_shared<StepsArgs>();
  CLI::App* cmd = app.add_subcommand("steps", "Detect steps, cadence and turns (pdr engine)");
  cmd->add_option("files", args->files, "session log(s), or Oxford CSV file(s) with --format oxford")->required();
  cmd->add_option("--format", args->format, "log (session log) or oxford (Oxford step-counter CSV)")
      ->check(CLI::IsMember({"log", "oxford"}));
  cmd->add_flag("--table", args->table, "print a results table (file, truth, detected, error)");
  cmd->add_flag("--list", args->list, "print every step");
  cmd->add_flag("--paper", args->paper, "use APT's detector as published (no gates)");
  cmd->add_option("--check-mean", args->check_mean_pct, "with --table: exit 1 if mean |error| > this, %");
  cmd->add_option("--check-worst", args->check_worst_pct, "with --table: exit 1 if any |error| > this, %");
  auto& d = args->options.detector;
  cmd->add_option("--window", d.window_s, "running-statistics window, s")->capture_default_str();
  cmd->add_option("--k", d.k_sigma, "symbol threshold mu +- k*sigma")->capture_default_str();
  cmd->add_option("--lowpass", d.lowpass_hz, "low-pass cut-off, Hz (0 = off)")->capture_default_str();
  cmd->add_option("--min-interval", d.min_step_interval_s, "refractory time after a step, s")->capture_default_str();
  cmd->add_option("--min-sigma", d.min_sigma_mps2, "walking gate on sigma, m/s^2")->capture_default_str();
  cmd->add_option("--min-swing", d.min_swing_mps2, "minimum peak-to-trough per step, m/s^2")->capture_default_str();
  cmd->add_option("--bout", d.bout_min_steps, "steps needed to confirm a walking bout")->capture_default_str();
  cmd->add_option("--max-interval", d.max_step_interval_s, "longest step interval inside a bout, s")->capture_default_str();
  cmd->add_option("--height", args->options.length.height_m, "user height for the step length, m")->capture_default_str();
  cmd->add_flag("--female", args->female, "APT step-length constant for women (c1 = 0.413)");
  cmd->add_option("--mount", args->mount, "phone mount: chest-camera-out (-Z forward), chest-screen-out (+Z), handheld (+Y)")
      ->check(CLI::IsMember({"chest-camera-out", "chest-screen-out", "handheld"}))
      ->capture_default_str();
  cmd->add_option("--source", args->source, "step source: accel, android (step-detector events), auto")
      ->check(CLI::IsMember({"accel", "android", "auto"}))
      ->capture_default_str();
  cmd->callback([args] { run(*args); });
}

}  // namespace pdnav::cli
