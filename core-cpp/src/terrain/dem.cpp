// .pdem reader (docs/dem-format.md) and bilinear lookups.
#include "pdnav/terrain/dem.h"

#include "pdnav/geo/units.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>

namespace pdnav::terrain {
namespace {

constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
constexpr std::int64_t kMaxNodes = 256LL * 1024 * 1024;  // 1 GiB of float32
constexpr int kMaxSide = 1 << 20;

/// The "not a .pdem" error, with the exact dem-tools command that makes a tile from the file
/// (issue 19.5): an SRTM name (N43E007.hgt[.zip]) gives its one-degree box; another raster
/// (GeoTIFF, DTED, ...) the command with the area left to the user.
std::string not_pdem_message(const std::string& name) {
  std::string msg = "bad magic (not a .pdem tile): expected 'PDEM 1'";
  const auto slash = name.find_last_of('/');
  const std::string base = slash == std::string::npos ? name : name.substr(slash + 1);
  std::string stem = base, gdal_path = name;
  const auto ends_with = [](const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (ends_with(base, ".pdem") || base.empty()) return msg;
  if (ends_with(base, ".zip")) {
    stem = base.substr(0, base.size() - 4);
    gdal_path = "/vsizip/" + name + "/" + stem;  // the raster inside the zip
  }
  const std::string tile = stem.substr(0, stem.find('.'));
  int lat = 0, lon = 0;
  char ns = 0, ew = 0;
  const bool srtm = tile.size() == 7 && std::sscanf(tile.c_str(), "%c%2d%c%3d", &ns, &lat, &ew, &lon) == 4 &&
                    (ns == 'N' || ns == 'S') && (ew == 'E' || ew == 'W');
  msg += "; make one with: dem-tools/pdnav_dem.py tile " + gdal_path + " -o " + tile + ".pdem";
  if (srtm) {
    // The tile's centre and the largest square (in metres) that stays inside the one-degree
    // tile at its poleward edge, with a 10 % margin (the tool refuses an area partly outside).
    const int s = ns == 'N' ? lat : -lat, w = ew == 'E' ? lon : -lon;
    const double poleward_rad = std::max(std::abs(s), std::abs(s + 1)) * pdnav::kDegToRad;
    constexpr double kMetresPerDegree = 111320.0;
    const double radius_m = 0.45 * kMetresPerDegree * std::min(1.0, std::cos(poleward_rad));
    char area[96];
    std::snprintf(area, sizeof area, " --center %.1f %.1f --radius %.0f", s + 0.5, w + 0.5, 1000.0 * std::floor(radius_m / 1000.0));
    msg += std::string(area) + " --cell 30 --fill-voids";
  } else {
    msg += " --center LAT LON --radius METRES";
  }
  return msg + " (docs/dem-format.md)";
}

/// Header lines "key value" after the magic line, up to "end_header".
struct RawHeader {
  std::map<std::string, std::string> fields;
  std::size_t data_offset = 0;
};

RawHeader split_header(const std::uint8_t* data, std::size_t size, const std::string& name) {
  RawHeader h;
  std::size_t pos = 0;
  int line_no = 0;
  bool ended = false;
  while (pos < size && pos < kMaxHeaderBytes) {
    const void* nl = std::memchr(data + pos, '\n', size - pos);
    if (nl == nullptr) break;
    const std::size_t end = static_cast<std::size_t>(static_cast<const std::uint8_t*>(nl) - data);
    std::string line(reinterpret_cast<const char*>(data + pos), end - pos);
    pos = end + 1;
    ++line_no;
    if (line_no == 1) {
      if (line.rfind("PDEM ", 0) != 0) throw DemError(name, not_pdem_message(name));
      h.fields["version"] = line.substr(5);
      continue;
    }
    if (line == "end_header") {
      ended = true;
      break;
    }
    const auto sp = line.find(' ');
    if (sp == std::string::npos || sp == 0 || sp + 1 >= line.size())
      throw DemError(name, "header line " + std::to_string(line_no) + ": expected 'key value'");
    const std::string key = line.substr(0, sp);
    if (!h.fields.emplace(key, line.substr(sp + 1)).second)
      throw DemError(name, "header line " + std::to_string(line_no) + ": duplicate key '" + key + "'");
  }
  if (line_no == 0) throw DemError(name, size == 0 ? "empty file" : not_pdem_message(name));
  if (!ended) throw DemError(name, "truncated or oversized header: no 'end_header' line in the first 64 KiB");
  h.data_offset = pos;
  return h;
}

const std::string& require(const RawHeader& h, const std::string& key, const std::string& name) {
  const auto it = h.fields.find(key);
  if (it == h.fields.end()) throw DemError(name, "header: missing key '" + key + "'");
  return it->second;
}

double parse_double(const RawHeader& h, const std::string& key, const std::string& name) {
  const std::string& s = require(h, key, name);
  std::istringstream in(s);
  in.imbue(std::locale::classic());
  double v = 0.0;
  in >> v;
  if (in.fail() || !in.eof() || !std::isfinite(v))
    throw DemError(name, "header: '" + key + "' is not a finite number: '" + s + "'");
  return v;
}

std::int64_t parse_int(const RawHeader& h, const std::string& key, const std::string& name) {
  const std::string& s = require(h, key, name);
  if (s.empty() || s.size() > 18 || s.find_first_not_of("0123456789-") != std::string::npos)
    throw DemError(name, "header: '" + key + "' is not an integer: '" + s + "'");
  std::istringstream in(s);
  std::int64_t v = 0;
  in >> v;
  if (in.fail() || !in.eof()) throw DemError(name, "header: '" + key + "' is not an integer: '" + s + "'");
  return v;
}

std::string optional(const RawHeader& h, const std::string& key) {
  const auto it = h.fields.find(key);
  return it == h.fields.end() ? std::string() : it->second;
}

DemInfo parse_info(const RawHeader& h, const std::string& name) {
  DemInfo info;
  if (parse_int(h, "version", name) != 1)
    throw DemError(name, "unsupported .pdem version '" + require(h, "version", name) + "' (this reader: 1)");
  info.crs = require(h, "crs", name);
  if (info.crs != "local_enu") throw DemError(name, "header: unsupported crs '" + info.crs + "' (expected local_enu)");
  info.origin_lat_deg = parse_double(h, "origin_lat_deg", name);
  info.origin_lon_deg = parse_double(h, "origin_lon_deg", name);
  if (std::abs(info.origin_lat_deg) >= 89.0 || std::abs(info.origin_lon_deg) > 180.0)
    throw DemError(name, "header: origin outside -89..89 / -180..180 degrees");
  const std::int64_t cols = parse_int(h, "cols", name);
  const std::int64_t rows = parse_int(h, "rows", name);
  if (cols < 2 || rows < 2 || cols > kMaxSide || rows > kMaxSide || cols * rows > kMaxNodes)
    throw DemError(name, "header: grid size " + std::to_string(cols) + "x" + std::to_string(rows) +
                             " out of range (2..2^20 per side, at most 2^28 nodes)");
  info.cols = static_cast<int>(cols);
  info.rows = static_cast<int>(rows);
  info.cell_m = parse_double(h, "cell_m", name);
  if (!(info.cell_m >= 0.01 && info.cell_m <= 10000.0)) throw DemError(name, "header: cell_m outside 0.01..10000 m");
  info.x0_m = parse_double(h, "x0_m", name);
  info.y0_m = parse_double(h, "y0_m", name);
  const double span = 2.0e6;  // a tangent-plane tile beyond +-2000 km is meaningless
  if (std::abs(info.x0_m) > span || std::abs(info.y0_m) > span ||
      std::abs(info.x0_m + info.cell_m * static_cast<double>(cols - 1)) > span ||
      std::abs(info.y0_m + info.cell_m * static_cast<double>(rows - 1)) > span)
    throw DemError(name, "header: grid extends beyond +-2000 km of the origin");
  info.nodata = parse_double(h, "nodata", name);
  info.vertical_datum = require(h, "vertical_datum", name);
  info.source = optional(h, "source");
  info.source_sha256 = optional(h, "source_sha256");
  const std::string crc = require(h, "data_crc32", name);
  if (crc.size() != 8 || crc.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
    throw DemError(name, "header: data_crc32 must be 8 hex digits");
  info.data_crc32 = static_cast<std::uint32_t>(std::stoul(crc, nullptr, 16));
  return info;
}

float read_le_float(const std::uint8_t* p) {
  const std::uint32_t bits = static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
                             (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}

}  // namespace

const char* to_string(DemValidity v) {
  switch (v) {
    case DemValidity::kValid: return "valid";
    case DemValidity::kVoid: return "void";
    case DemValidity::kOffMap: return "off-map";
  }
  return "?";
}

std::uint32_t crc32(const std::uint8_t* data, std::size_t size) {
  static const std::array<std::uint32_t, 256> table = make_crc_table();  // immutable after init
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) c = table[(c ^ data[i]) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

Dem::Dem(DemInfo info, std::vector<float> values)
    : info_(std::move(info)),
      values_(std::move(values)),
      frame_(geo::Geodetic::from_deg(info_.origin_lat_deg, info_.origin_lon_deg, 0.0)),
      cols_(static_cast<std::size_t>(info_.cols)),
      x0_f_(static_cast<float>(info_.x0_m)),
      y0_f_(static_cast<float>(info_.y0_m)),
      inv_cell_f_(static_cast<float>(1.0 / info_.cell_m)),
      max_fx_(static_cast<float>(info_.cols - 1)),
      max_fy_(static_cast<float>(info_.rows - 1)),
      nanf_(std::numeric_limits<float>::quiet_NaN()) {}

Dem Dem::parse(const std::uint8_t* data, std::size_t size, const std::string& name) {
  const RawHeader h = split_header(data, size, name);
  DemInfo info = parse_info(h, name);
  const std::size_t nodes = static_cast<std::size_t>(info.cols) * static_cast<std::size_t>(info.rows);
  const std::size_t want = nodes * 4;
  const std::size_t have = size - h.data_offset;
  if (have < want)
    throw DemError(name, "truncated: " + std::to_string(have) + " data bytes, header promises " +
                             std::to_string(want) + " (" + std::to_string(info.cols) + "x" +
                             std::to_string(info.rows) + " float32)");
  if (have > want) throw DemError(name, "trailing bytes: " + std::to_string(have - want) + " after the grid");
  const std::uint8_t* p = data + h.data_offset;
  const std::uint32_t crc = crc32(p, want);
  if (crc != info.data_crc32) {
    std::ostringstream os;
    os << std::hex << "data checksum mismatch: crc32 " << crc << ", header " << info.data_crc32 << " (corrupt tile)";
    throw DemError(name, os.str());
  }
  std::vector<float> values(nodes);
  std::int64_t voids = 0;
  const auto nodata = static_cast<float>(info.nodata);
  for (std::size_t k = 0; k < nodes; ++k) {
    float v = read_le_float(p + 4 * k);
    if (!std::isfinite(v) || v == nodata || std::abs(v) > 12000.0f) {
      v = std::numeric_limits<float>::quiet_NaN();
      ++voids;
    }
    values[k] = v;
  }
  info.voids = voids;
  if (voids == static_cast<std::int64_t>(nodes)) throw DemError(name, "every node is void");
  return Dem(std::move(info), std::move(values));
}

Dem Dem::load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DemError(path, "cannot open for reading");
  in.seekg(0, std::ios::end);
  const std::streamoff len = in.tellg();
  if (len < 0) throw DemError(path, "cannot determine the file size");
  if (static_cast<std::uint64_t>(len) > static_cast<std::uint64_t>(kMaxNodes) * 4 + kMaxHeaderBytes)
    throw DemError(path, "file larger than the largest allowed tile");
  in.seekg(0, std::ios::beg);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(len));
  if (len > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), len)) throw DemError(path, "read error");
  return parse(bytes.data(), bytes.size(), path);
}

Dem Dem::from_grid(DemInfo info, std::vector<float> values) {
  const std::string name = "in-memory DEM";
  if (info.cols < 2 || info.rows < 2 || info.cols > kMaxSide || info.rows > kMaxSide)
    throw DemError(name, "grid size out of range");
  if (!(info.cell_m > 0.0) || !std::isfinite(info.cell_m)) throw DemError(name, "cell_m must be > 0");
  if (values.size() != static_cast<std::size_t>(info.cols) * static_cast<std::size_t>(info.rows))
    throw DemError(name, "values size does not match cols x rows");
  info.voids = 0;
  for (float& v : values) {
    if (!std::isfinite(v)) {
      v = std::numeric_limits<float>::quiet_NaN();
      ++info.voids;
    }
  }
  return Dem(std::move(info), std::move(values));
}

DemSample Dem::at_local(double e_m, double n_m) const {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  const double fx = (e_m - info_.x0_m) / info_.cell_m;
  const double fy = (n_m - info_.y0_m) / info_.cell_m;
  if (!(fx >= 0.0 && fy >= 0.0 && fx <= info_.cols - 1 && fy <= info_.rows - 1))
    return {nan, DemValidity::kOffMap};
  const int ix = std::min(static_cast<int>(fx), info_.cols - 2);
  const int iy = std::min(static_cast<int>(fy), info_.rows - 2);
  const double tx = fx - ix;
  const double ty = fy - iy;
  const double v00 = node(ix, iy), v10 = node(ix + 1, iy), v01 = node(ix, iy + 1), v11 = node(ix + 1, iy + 1);
  const double v = (1 - ty) * ((1 - tx) * v00 + tx * v10) + ty * ((1 - tx) * v01 + tx * v11);
  if (!std::isfinite(v)) return {nan, DemValidity::kVoid};
  return {v, DemValidity::kValid};
}

Eigen::Vector2d Dem::to_local(const geo::Geodetic& g) const {
  geo::Geodetic on_ellipsoid = g;
  on_ellipsoid.h_m = 0.0;  // the tile plane is the ortho projection of the ellipsoid surface
  const geo::Enu enu = frame_.to_enu(on_ellipsoid);
  return {enu.e_m(), enu.n_m()};
}

geo::Geodetic Dem::to_geodetic(double e_m, double n_m) const {
  // Inverse of the orthographic projection: find u so that the ENU point lies on h = 0.
  double u = 0.0;
  geo::Geodetic g;
  for (int k = 0; k < 3; ++k) {
    g = frame_.to_geodetic(geo::Enu(e_m, n_m, u));
    u -= g.h_m;
  }
  g.h_m = 0.0;
  return g;
}

DemSample Dem::at(const geo::Geodetic& g) const {
  const Eigen::Vector2d en = to_local(g);
  return at_local(en.x(), en.y());
}

}  // namespace pdnav::terrain
