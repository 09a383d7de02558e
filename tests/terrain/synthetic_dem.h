// Synthetic DEM tiles with known elevations for the terrain tests.
#pragma once
#include <cmath>
#include <cstdio>
#include <cstring>
#include <cstdint>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "pdnav/terrain/dem.h"

namespace pdnav::test {

/// Header of a tile with the given grid; origin in the Pyrenees.
inline terrain::DemInfo synthetic_info(int cols, int rows, double cell_m) {
  terrain::DemInfo info;
  info.origin_lat_deg = 42.5;
  info.origin_lon_deg = 1.5;
  info.cols = cols;
  info.rows = rows;
  info.cell_m = cell_m;
  info.x0_m = -0.5 * (cols - 1) * cell_m;
  info.y0_m = -0.5 * (rows - 1) * cell_m;
  info.vertical_datum = "EGM96";
  info.source = "synthetic";
  return info;
}

/// A tile sampling f(east, north) at the nodes.
inline terrain::Dem synthetic_dem(int cols, int rows, double cell_m, const std::function<double(double, double)>& f) {
  terrain::DemInfo info = synthetic_info(cols, rows, cell_m);
  std::vector<float> v(static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows));
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i)
      v[static_cast<std::size_t>(j) * cols + i] = static_cast<float>(f(info.x0_m + i * cell_m, info.y0_m + j * cell_m));
  return terrain::Dem::from_grid(info, std::move(v));
}

/// Hilly terrain: a sum of sinusoidal ridges at several wavelengths (200 m .. 2 km), ~300 m relief.
inline double hills(double e, double n) {
  return 1500.0 + 120.0 * std::sin(e / 700.0) * std::cos(n / 900.0) + 60.0 * std::sin((e + 2 * n) / 330.0) +
         35.0 * std::cos((3 * e - n) / 210.0) + 80.0 * std::sin(n / 1500.0 + 1.0);
}

/// The bytes of a .pdem file for `info` and values (as dem-tools writes it; docs/dem-format.md).
inline std::string pdem_bytes(const terrain::DemInfo& info, const std::vector<float>& values,
                              const std::string& extra_header = "") {
  std::string data(values.size() * 4, '\0');
  for (std::size_t k = 0; k < values.size(); ++k) {
    std::uint32_t bits;
    std::memcpy(&bits, &values[k], 4);
    for (int b = 0; b < 4; ++b) data[4 * k + b] = static_cast<char>((bits >> (8 * b)) & 0xFFu);
  }
  const std::uint32_t crc = terrain::crc32(reinterpret_cast<const std::uint8_t*>(data.data()), data.size());
  std::ostringstream h;
  h.precision(17);
  char crc_hex[16];
  std::snprintf(crc_hex, sizeof crc_hex, "%08x", crc);
  h << "PDEM 1\ncrs local_enu\norigin_lat_deg " << info.origin_lat_deg << "\norigin_lon_deg " << info.origin_lon_deg
    << "\ncols " << info.cols << "\nrows " << info.rows << "\ncell_m " << info.cell_m << "\nx0_m " << info.x0_m
    << "\ny0_m " << info.y0_m << "\nnodata -32768\nvertical_datum EGM96\nsource test\n"
    << extra_header << "data_crc32 " << crc_hex << "\nend_header\n";
  return h.str() + data;
}

}  // namespace pdnav::test
