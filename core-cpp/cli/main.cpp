// pdnav: the host command-line tool. Thin: parse arguments, wire io to an engine, print.
#include <exception>
#include <iostream>
#include <string>

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
  // Issue 19.5: the first word that is not an option must be a command. CLI11 alone answers
  // "A subcommand is required" for `pdnav eval-fusion`, and prints the top help (exit 0) for
  // `pdnav NOSUCH --help`.
  if (argc >= 2 && argv[1][0] != '-') {
    const std::string name = argv[1];
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) known = known || sub->check_name(name);
    if (!known) {
      std::cerr << "pdnav: error: unknown command " << name << " (pdnav --help lists the commands)\n";
      return 2;
    }
  }
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
