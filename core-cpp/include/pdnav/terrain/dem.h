// The project DEM tile (.pdem, docs/dem-format.md): the one reader of the format that
// dem-tools/pdnav_dem.py writes. A regular grid of float32 elevations at nodes every cell_m
// metres in the local ENU tangent plane of a geodetic origin (pdnav::geo::LocalFrame at
// (origin_lat, origin_lon, 0)), with bilinear interpolation and a validity flag.
#pragma once
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "pdnav/geo/frames.h"

namespace pdnav::terrain {

/// A DEM input error naming the file and the reason: what() is "file: reason".
class DemError : public std::runtime_error {
 public:
  DemError(const std::string& file, const std::string& reason)
      : std::runtime_error(file + ": " + reason) {}
};

/// Header of a .pdem tile (docs/dem-format.md); every field is validated on load.
struct DemInfo {
  int version = 1;
  std::string crs = "local_enu";  // the only CRS: ENU tangent plane at the origin (h = 0)
  double origin_lat_deg = 0.0;
  double origin_lon_deg = 0.0;
  int cols = 0;            // nodes west -> east
  int rows = 0;            // nodes south -> north
  double cell_m = 0.0;     // node spacing
  double x0_m = 0.0;       // east of node (0, 0) (south-west corner)
  double y0_m = 0.0;       // north of node (0, 0)
  double nodata = -32768.0;
  std::string vertical_datum;  // e.g. EGM96 (SRTM)
  std::string source;          // source file name
  std::string source_sha256;
  std::int64_t voids = 0;      // void nodes in the tile
  std::uint32_t data_crc32 = 0;
};

enum class DemValidity { kValid, kVoid, kOffMap };
const char* to_string(DemValidity v);

/// Elevation lookup result; elevation_m is NaN unless valid().
struct DemSample {
  double elevation_m;
  DemValidity validity;
  bool valid() const { return validity == DemValidity::kValid; }
};

class Dem {
 public:
  /// Reads and validates a .pdem file; throws DemError (file + reason) on any problem.
  static Dem load(const std::string& path);
  /// Same from bytes in memory (`name` is used in messages); the fuzzer's entry point.
  static Dem parse(const std::uint8_t* data, std::size_t size, const std::string& name);
  /// A tile from values (rows south -> north, NaN = void); tests and simulations.
  static Dem from_grid(DemInfo info, std::vector<float> values);

  /// Bilinear elevation at local ENU metres of the tile frame.
  DemSample at_local(double e_m, double n_m) const;
  /// Bilinear elevation at a geodetic position (its height is ignored).
  DemSample at(const geo::Geodetic& g) const;
  /// Hot-path lookup for the particle filter: bilinear elevation, NaN when void or off map.
  float elevation_or_nan(float e_m, float n_m) const {
    const float fx = (e_m - x0_f_) * inv_cell_f_;
    const float fy = (n_m - y0_f_) * inv_cell_f_;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < max_fx_ && fy < max_fy_)) return nanf_;
    const int ix = static_cast<int>(fx);
    const int iy = static_cast<int>(fy);
    const float tx = fx - static_cast<float>(ix);
    const float ty = fy - static_cast<float>(iy);
    const float* p = values_.data() + static_cast<std::size_t>(iy) * cols_ + static_cast<std::size_t>(ix);
    const float south = p[0] + tx * (p[1] - p[0]);
    const float north = p[cols_] + tx * (p[cols_ + 1] - p[cols_]);
    return south + ty * (north - south);
  }

  /// Hot-path view of the grid for lookups in blocks (the particle filter): node values
  /// row-major, south -> north, and the float transform elevation_or_nan uses. A node index
  /// fits int32 (the format caps a tile at 2^28 nodes). Valid while the Dem lives.
  struct Grid {
    const float* values;
    std::int32_t cols;
    float x0_m, y0_m, inv_cell, max_fx, max_fy;
    float last_fx, last_fy;  // the largest float below max_fx / max_fy: inside the last cell
  };
  Grid grid() const {
    return {values_.data(), static_cast<std::int32_t>(cols_), x0_f_, y0_f_, inv_cell_f_, max_fx_, max_fy_,
            std::nextafter(max_fx_, 0.0f), std::nextafter(max_fy_, 0.0f)};
  }

  /// The tile's ENU frame (origin at origin_lat/lon, h = 0).
  const geo::LocalFrame& frame() const { return frame_; }
  const DemInfo& info() const { return info_; }
  /// Local (east, north) of a geodetic point in the tile frame.
  Eigen::Vector2d to_local(const geo::Geodetic& g) const;
  /// Geodetic point on the ellipsoid (h = 0) below local (east, north).
  geo::Geodetic to_geodetic(double e_m, double n_m) const;
  /// Node value (NaN = void); i west -> east, j south -> north.
  float node(int i, int j) const { return values_[static_cast<std::size_t>(j) * cols_ + static_cast<std::size_t>(i)]; }
  /// Extent of the grid in local metres.
  double min_e_m() const { return info_.x0_m; }
  double min_n_m() const { return info_.y0_m; }
  double max_e_m() const { return info_.x0_m + (info_.cols - 1) * info_.cell_m; }
  double max_n_m() const { return info_.y0_m + (info_.rows - 1) * info_.cell_m; }

 private:
  Dem(DemInfo info, std::vector<float> values);
  DemInfo info_;
  std::vector<float> values_;
  geo::LocalFrame frame_;
  std::size_t cols_ = 0;
  float x0_f_ = 0, y0_f_ = 0, inv_cell_f_ = 1, max_fx_ = 0, max_fy_ = 0;
  float nanf_;
};

/// CRC-32 (IEEE 802.3, as zlib.crc32) of a byte range; the tile's data checksum.
std::uint32_t crc32(const std::uint8_t* data, std::size_t size);

}  // namespace pdnav::terrain
