// `pdnav inspect LOG`: what a session log / GnssLogger log contains and what the reader skipped.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "pdnav/io/log_format.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/io/sample_source.h"
#include "pdnav/pdr/pdr.h"
#include "support/replay_support.h"
#include "support/sources.h"

namespace pdnav::cli {
namespace {

struct TypeSummary {
  std::int64_t count = 0;
  std::int64_t distinct_t = 0;  // samples with a new time (Raw: epochs)
  TimeNs first_t = 0, last_t = 0;
};

struct InspectArgs {
  std::string path;
  std::string format = "auto";
  bool strict = false;
  std::size_t issues = 5;
};

std::string fmt(const char* f, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, a);
  return buf;
}

/// Prints "\rinspect: NN%" on stderr for big files, once per percent.
class Progress {
 public:
  explicit Progress(bool enabled) : enabled_(enabled) {}
  void update(double fraction) {
    const int pct = static_cast<int>(fraction * 100.0);
    if (!enabled_ || pct == last_) return;
    last_ = pct;
    std::cerr << "\rinspect: " << pct << "%" << std::flush;
  }
  void done() {
    if (enabled_ && last_ >= 0) std::cerr << "\rinspect: done\n";
  }

 private:
  bool enabled_;
  int last_ = -1;
};

/// Distinct timestamps per second over the type's span; NaN with fewer than two.
double rate_hz(const TypeSummary& s) {
  const double span_s = static_cast<double>(s.last_t - s.first_t) * 1e-9;
  return s.distinct_t > 1 && span_s > 0 ? static_cast<double>(s.distinct_t - 1) / span_s : kNaN;
}

void print_types(const std::map<std::string, TypeSummary>& types) {
  std::printf("%-16s %9s %10s %16s %16s %10s %9s\n", "type", "count", "distinct_t", "first_t_s",
              "last_t_s", "span_s", "rate_hz");
  for (const auto& [name, s] : types) {
    const double span_s = static_cast<double>(s.last_t - s.first_t) * 1e-9;
    const std::string rate = std::isfinite(rate_hz(s)) ? fmt("%.3f", rate_hz(s)) : std::string("-");
    std::printf("%-16s %9lld %10lld %16.6f %16.6f %10.3f %9s\n", name.c_str(),
                static_cast<long long>(s.count), static_cast<long long>(s.distinct_t),
                static_cast<double>(s.first_t) * 1e-9, static_cast<double>(s.last_t) * 1e-9, span_s,
                rate.c_str());
  }
}

void print_skips(const io::ReadStats& st, std::size_t max_issues) {
  if (st.skipped_by_reason.empty()) return;
  std::printf("skipped by reason:\n");
  for (const auto& [reason, n] : st.skipped_by_reason)
    std::printf("  %s: %lld\n", reason.c_str(), static_cast<long long>(n));
  std::printf("first issues:\n");
  for (std::size_t i = 0; i < st.issues.size() && i < max_issues; ++i)
    std::printf("  %s\n", st.issues[i].to_string().c_str());
}

void run_inspect(const InspectArgs& a) {
  io::SourceOptions opt;
  opt.log.strict = a.strict;
  const std::unique_ptr<io::SampleSource> source = open_source(a.path, a.format, opt);
  io::SampleSource& reader = *source;
  std::error_code ec;
  const bool folder = std::filesystem::is_directory(a.path, ec);
  const auto size = folder ? 0 : std::filesystem::file_size(a.path, ec);
  Progress progress(!ec && size > (32u << 20));
  std::map<std::string, TypeSummary> types;
  bool any = false;
  TimeNs t_min = 0, t_max = 0;
  Sample s;
  std::int64_t n = 0;
  while (reader.next(s)) {
    const TimeNs t = sample_time_ns(s);
    TypeSummary& ts = types[std::string(io::line_type_name(s))];
    if (ts.count == 0) ts.first_t = t;
    if (ts.count == 0 || t != ts.last_t) ++ts.distinct_t;
    ++ts.count;
    ts.last_t = t;
    t_min = any ? std::min(t_min, t) : t;
    t_max = any ? std::max(t_max, t) : t;
    any = true;
    if ((++n & 0xFF) == 0) progress.update(reader.progress());
  }
  progress.done();
  const io::ReadStats& st = reader.stats();
  if (folder) std::printf("folder: %s (%s)\n", a.path.c_str(), std::string(io::format_name(reader.format())).c_str());
  else if (reader.format() == io::Format::kSession || reader.format() == io::Format::kGnssLogger)
    std::printf("file: %s (%llu bytes)\n", a.path.c_str(), ec ? 0ull : static_cast<unsigned long long>(size));
  else
    std::printf("file: %s (%llu bytes, %s)\n", a.path.c_str(), ec ? 0ull : static_cast<unsigned long long>(size),
                std::string(io::format_name(reader.format())).c_str());
  std::printf("header:");
  for (const auto& [k, v] : reader.header_info()) std::printf(" %s=%s;", k.c_str(), v.c_str());
  std::printf("\nlines: %lld\n", static_cast<long long>(st.lines));
  print_types(types);
  for (const char* accel : {"Accel", "UncalAccel"}) {  // the step detector needs its rate
    const auto it = types.find(accel);
    if (it != types.end() && rate_hz(it->second) < pdr::Pdr::kMinAccelRateHz)  // false for NaN
      std::printf("warning: %s\n", accel_rate_warning(rate_hz(it->second)).c_str());
  }
  if (any)
    std::printf("time span: %.6f s .. %.6f s (%.3f s)\n", static_cast<double>(t_min) * 1e-9,
                static_cast<double>(t_max) * 1e-9, static_cast<double>(t_max - t_min) * 1e-9);
  print_skips(st, a.issues);
  for (const auto& [what, why] : st.not_used) std::printf("not used: %s: %s\n", what.c_str(), why.c_str());
  if (st.reordered > 0)
    std::printf("reordered: %lld motion-sensor samples read in time order, not file order (batched; the latest %.3f s late)\n",
                static_cast<long long>(st.reordered), st.reorder_window_s);
  std::printf("samples: %lld skipped: %lld\n", static_cast<long long>(st.samples),
              static_cast<long long>(st.skipped_total()));
}

}  // namespace

void register_inspect(CLI::App& app) {
  auto args = std::make_shared<InspectArgs>();
  CLI::App* sub = app.add_subcommand(
      "inspect", "Summarise a recording (session log, GnssLogger, Sensor Logger, phyphox, GetSensorData): header, samples per line type, "
                 "time span, rates, skipped lines by reason");
  sub->add_option("log", args->path,
                  "log file (pdnav session log or GnssLogger .txt), Sensor Logger / phyphox export (folder or zip), "
                  "GetSensorData log")->required();
  add_format_option(sub, args->format);
  sub->add_flag("--strict", args->strict, "stop with an error at the first malformed line");
  sub->add_option("--issues", args->issues, "how many skipped lines to list (default 5)");
  sub->callback([args] { run_inspect(*args); });
}

}  // namespace pdnav::cli
