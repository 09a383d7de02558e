// `pdnav orbits`: load broadcast navigation files, report what was read and, with --sp3,
// compare broadcast satellite positions with precise SP3 orbits at every SP3 epoch.
#include <cstdio>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/orbit_compare.h"
#include "pdnav/gnss/sp3.h"

namespace pdnav::cli {
namespace {

struct OrbitsArgs {
  std::vector<std::string> nav;
  std::string sp3;
};

void print_load_report(const gnss::EphemerisLoadReport& r) {
  std::cout << "nav " << r.file << ": " << r.records_total() << " records";
  for (const auto& [sys, n] : r.records_by_system) std::cout << "  " << sys << "=" << n;
  std::cout << "\n";
  for (const auto& [reason, n] : r.skipped_by_reason) std::cout << "  skipped " << n << ": " << reason << "\n";
  for (std::size_t i = 0; i < r.issues.size() && i < 10; ++i) std::cout << "  " << r.issues[i] << "\n";
}

void print_comparison(const std::vector<gnss::OrbitComparisonRow>& rows) {
  std::printf("%-4s %6s %8s %10s %10s %12s %12s  %s\n", "sat", "epochs", "missing", "max_3d_m", "rms_3d_m",
              "max_radial_m", "max_clock_m", "reason");
  std::map<std::string, double> worst;
  std::map<std::string, int> count;
  for (const auto& r : rows) {
    std::printf("%-4s %6d %8d %10.3f %10.3f %12.3f %12.3f  %s\n", r.sat.to_string().c_str(), r.epochs, r.missing,
                r.max_3d_m, r.rms_3d_m, r.max_radial_m, r.max_clock_m, r.last_reason.c_str());
    const std::string sys = gnss::to_string(r.sat.sys);
    if (r.epochs > 0) {
      worst[sys] = std::max(worst[sys], r.max_3d_m);
      ++count[sys];
    }
  }
  std::cout << "max_3d_m by system:";
  for (const auto& [sys, w] : worst) std::printf(" %s=%.3f(%d sats)", sys.c_str(), w, count[sys]);
  std::cout << "\n";
}

void run_orbits(const OrbitsArgs& a) {
  gnss::EphemerisStore store;
  for (const auto& f : a.nav) print_load_report(store.load_rinex_nav(f));
  std::cout << "satellites with ephemeris: " << store.satellites().size() << "\n";
  if (a.sp3.empty()) return;
  const gnss::Sp3File sp3 = gnss::read_sp3_file(a.sp3);
  std::cout << "sp3 " << a.sp3 << ": " << sp3.epochs.size() << " epochs, time system " << sp3.time_system
            << ", skipped lines " << sp3.skipped_lines << "\n";
  print_comparison(gnss::compare_broadcast_to_sp3(store, sp3));
}

}  // namespace

void register_orbits(CLI::App& app) {
  auto args = std::make_shared<OrbitsArgs>();
  CLI::App* cmd = app.add_subcommand("orbits", "Read broadcast ephemerides; compare with SP3 precise orbits");
  cmd->add_option("--nav", args->nav, "RINEX 2/3 navigation file(s)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--sp3", args->sp3, "SP3-c/d precise orbit file (truth)")->check(CLI::ExistingFile);
  cmd->callback([args] { run_orbits(*args); });
}

}  // namespace pdnav::cli
