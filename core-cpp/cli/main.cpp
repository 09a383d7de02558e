// pdnav: the host command-line tool. Thin: parse arguments, wire io to an engine, print.
#include <exception>
#include <iostream>

#include <CLI/CLI.hpp>

namespace pdnav::cli {
#define PDNAV_COMMAND(name) void register_##name(CLI::App& app);
#include "pdnav_commands.inc"
#undef PDNAV_COMMAND
}  // namespace pdnav::cli

int main(int argc, char** argv) {
  CLI::App app{"pdnav: pedestrian navigation where GNSS is weak, jammed or absent.\n"
               "Replays session logs through the same C++ core the Android app runs."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pdnav 0.1.0");
#define PDNAV_COMMAND(name) pdnav::cli::register_##name(app);
#include "pdnav_commands.inc"
#undef PDNAV_COMMAND
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "pdnav: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
