// `pdnav import IN -o OUT.log [--format F]`: any recording pdnav reads (Sensor Logger or
// phyphox folder/zip, GetSensorData file, GnssLogger log) written as a pdnav session log
// through io::LogWriter. `pdnav replay OUT.log` gives the same result as `pdnav replay IN`
// (the writer and reader are lossless; docs/log-format.md).
#include <cstdio>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "pdnav/io/log_format.h"
#include "pdnav/io/log_writer.h"
#include "pdnav/io/sample_source.h"
#include "support/output_file.h"
#include "support/sources.h"

namespace pdnav::cli {
namespace {

struct ImportArgs {
  std::string in;
  std::string out;
  std::string format = "auto";
  bool strict = false;
};

void run_import(const ImportArgs& a) {
  io::SourceOptions opt;
  opt.log.strict = a.strict;
  const std::unique_ptr<io::SampleSource> src = open_source(a.in, a.format, opt);
  io::LogWriterOptions wopt;
  const auto& info = src->header_info();
  for (const char* k : {"device name", "deviceModel", "Model"})
    if (auto it = info.find(k); it != info.end() && wopt.device.empty()) wopt.device = it->second;
  OutputFile out(a.out, {a.in});
  io::LogWriter writer(out.partial_path(), wopt);
  Sample s;
  while (src->next(s)) writer.write(s);
  writer.close();
  out.commit();
  const io::ReadStats& st = src->stats();
  std::printf("%s (%s) -> %s: %lld samples, %lld lines written\n", a.in.c_str(),
              std::string(io::format_name(src->format())).c_str(), a.out.c_str(), static_cast<long long>(st.samples),
              static_cast<long long>(writer.lines_written()));
  for (const auto& [type, n] : st.samples_by_type) std::printf("  %s: %lld\n", type.c_str(), static_cast<long long>(n));
  for (const auto& [why, n] : st.skipped_by_reason) std::printf("  skipped %lld: %s\n", static_cast<long long>(n), why.c_str());
  for (std::size_t i = 0; i < st.issues.size() && i < 5; ++i) std::printf("    %s\n", st.issues[i].to_string().c_str());
  print_not_used(std::cout, st);
  std::printf("skipped: %lld\n", static_cast<long long>(st.skipped_total()));
}

}  // namespace

void register_import(CLI::App& app) {
  auto a = std::make_shared<ImportArgs>();
  CLI::App* c = app.add_subcommand(
      "import", "Write a recording (Sensor Logger / phyphox folder or zip, GetSensorData, GnssLogger) as a pdnav session log");
  c->add_option("in", a->in, "the recording (file, folder or zip)")->required()->check(CLI::ExistingPath);
  c->add_option("-o,--out", a->out, "session log to write")->required();
  add_format_option(c, a->format);
  c->add_flag("--strict", a->strict, "stop with an error at the first malformed line");
  c->callback([a] { run_import(*a); });
}

}  // namespace pdnav::cli
