// Building a walkway graph from an OpenStreetMap extract for CLI commands: the core cannot
// read .osm.pbf, so this runs dem-tools/pdnav_graph.py (GDAL) once per input file identity
// (path, size, modification time) and keeps the result in a cache directory.
#pragma once
#include <string>

namespace pdnav::cli {

/// dem-tools/pdnav_graph.py of the source tree this binary was built from.
std::string default_graph_tool();

/// Path of the graph for `osm_path`, building it with `python graph_tool` when not cached.
/// Empty cache_dir = <system temp>/pdnav-graph-cache. Throws std::runtime_error on failure.
std::string build_graph_cached(const std::string& osm_path, const std::string& cache_dir,
                               const std::string& graph_tool, const std::string& python);

}  // namespace pdnav::cli
