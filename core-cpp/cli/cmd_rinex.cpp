// `pdnav rinex LOG -o OUT.obs`: a GnssLogger or pdnav session log as a RINEX 3.04
// observation file (code, phase, Doppler, C/N0 per signal; LLI on slips, resets and
// hardware clock discontinuities), for RTKLIB and other tools. Conventions: docs/gnss.md.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "pdnav/gnss/rinex_obs.h"
#include "pdnav/io/sample_source.h"
#include "support/sources.h"

namespace pdnav::cli {
namespace {

struct RinexArgs {
  std::string log;
  std::string format = "auto";
  std::string out;
};

void run_rinex(const RinexArgs& a) {
  const std::unique_ptr<io::SampleSource> source = open_source(a.log, a.format);
  io::SampleSource& reader = *source;
  gnss::RinexObsWriter writer("pdnav rinex");
  std::map<std::string, std::int64_t> skipped;
  std::int64_t raw = 0, written = 0;
  Sample s;
  while (reader.next(s)) {
    if (const auto* r = std::get_if<GnssRawSample>(&s)) {
      ++raw;
      std::string why;
      if (writer.add(*r, &why)) ++written;
      else ++skipped[why];
    }
  }
  if (raw == 0) throw std::runtime_error(a.log + ": no Raw GNSS measurement rows (nothing to write)");
  std::ofstream f(a.out);
  if (!f) throw std::runtime_error(a.out + ":0: cannot create");
  const std::int64_t epochs = writer.finish(f);
  f.close();
  if (!f) throw std::runtime_error(a.out + ":0: write failed");
  std::printf("%s: %lld Raw rows, %lld written as signals in %lld epochs\n", a.out.c_str(),
              static_cast<long long>(raw), static_cast<long long>(written), static_cast<long long>(epochs));
  for (const auto& [why, n] : skipped) std::printf("  skipped %lld: %s\n", static_cast<long long>(n), why.c_str());
  if (epochs == 0) throw std::runtime_error(a.log + ": no Raw row could be written (reasons above)");
}

}  // namespace

void register_rinex(CLI::App& app) {
  auto args = std::make_shared<RinexArgs>();
  CLI::App* cmd = app.add_subcommand("rinex", "write a GnssLogger / session log's Raw rows as RINEX 3.04 observations");
  cmd->add_option("log", args->log, "GnssLogger or pdnav session log (or any recording with Raw rows)")->required()->check(CLI::ExistingPath);
  add_format_option(cmd, args->format);
  cmd->add_option("-o,--out", args->out, "output RINEX observation file")->required();
  cmd->callback([args]() { run_rinex(*args); });
}

}  // namespace pdnav::cli
