#include "support/route_graph_cache.h"

#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <stdexcept>
#include <string>

namespace pdnav::cli {
namespace {

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) {
    if (c == '\'') q += "'\\''";
    else q += c;
  }
  return q + "'";
}

}  // namespace

std::string default_graph_tool() {
  // The source tree's dem-tools, as an absolute path from CMake: __FILE__ is relative to the
  // build folder when ccache rewrites paths (CCACHE_BASEDIR), which broke the default when
  // pdnav ran from another folder (ctest runs tests from build/dev/tests).
  return (std::filesystem::path(PDNAV_SOURCE_DIR) / "dem-tools" / "pdnav_graph.py").string();
}

std::string build_graph_cached(const std::string& osm_path, const std::string& cache_dir,
                               const std::string& graph_tool, const std::string& python) {
  namespace fs = std::filesystem;
  const fs::path osm = fs::absolute(osm_path);
  std::error_code ec;
  const auto size = fs::file_size(osm, ec);
  if (ec) throw std::runtime_error(osm.string() + ": cannot read (" + ec.message() + ")");
  const auto mtime = fs::last_write_time(osm, ec).time_since_epoch().count();
  const std::string identity = osm.string() + "|" + std::to_string(size) + "|" + std::to_string(mtime);
  const fs::path dir = cache_dir.empty() ? fs::temp_directory_path() / "pdnav-graph-cache" : fs::path(cache_dir);
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir.string() + ": cannot create cache directory (" + ec.message() + ")");
  std::string stem = osm.filename().string();
  stem = stem.substr(0, stem.find('.'));
  const fs::path out = dir / (stem + "-" + std::to_string(std::hash<std::string>{}(identity)) + ".graph");
  if (fs::exists(out)) return out.string();
  if (!fs::exists(graph_tool)) throw std::runtime_error(graph_tool + ": graph tool not found (use --graph-tool)");
  const std::string cmd = shell_quote(python) + " " + shell_quote(graph_tool) + " " + shell_quote(osm.string()) +
                          " " + shell_quote(out.string()) + " 1>&2";
  std::cerr << "eval-route: building the walkway graph: " << cmd << "\n";
  const int rc = std::system(cmd.c_str());
  if (rc != 0 || !fs::exists(out)) {
    throw std::runtime_error("graph tool failed (exit " + std::to_string(rc) + "): " + cmd);
  }
  return out.string();
}

}  // namespace pdnav::cli
