// The --format option and opening of any recording through io::open_sample_source, shared by
// the commands that read logs (replay, inspect, import, gnss, rinex, steps, eval-*).
#pragma once
#include <memory>
#include <ostream>
#include <string>

#include <CLI/CLI.hpp>

#include "pdnav/io/sample_source.h"

namespace pdnav::cli {

inline constexpr const char* kFormatHelp =
    "input format: auto (detected from the content) | session | gnsslogger | sensorlogger | phyphox | getsensordata";

inline CLI::Option* add_format_option(CLI::App* c, std::string& format) {
  return c->add_option("--format", format, kFormatHelp)->capture_default_str();
}

/// Opens a log file, a Sensor Logger / phyphox folder or zip, or a GetSensorData file.
inline std::unique_ptr<io::SampleSource> open_source(const std::string& path, const std::string& format,
                                                     io::SourceOptions opt = {}) {
  return io::open_sample_source(path, io::parse_format(format), opt);
}

/// "not used: FILE: why" lines of a multi-file recording.
inline void print_not_used(std::ostream& out, const io::ReadStats& st, const char* indent = "  ") {
  for (const auto& [what, why] : st.not_used) out << indent << "not used: " << what << ": " << why << "\n";
}

}  // namespace pdnav::cli
