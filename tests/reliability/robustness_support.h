// Helpers shared by the reliability robustness tests: estimate sanity checks, a hilly
// synthetic DEM (in memory and as a .pdem file) and a simulated chest-mounted walker.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "pdnav/geo/estimate.h"
#include "pdnav/geo/samples.h"
#include "pdnav/terrain/dem.h"

namespace pdnav::reliability {

inline constexpr double kLat0 = 42.5063;  // Andorra la Vella (origin of the synthetic DEM)
inline constexpr double kLon0 = 1.5218;

/// A sane estimate: a valid one has a finite position and a finite, symmetric, positive
/// semi-definite covariance with a positive trace; any estimate has a finite covariance.
inline ::testing::AssertionResult sane(const Estimate& e) {
  if (!e.cov_en_m2.allFinite() || !std::isfinite(e.vertical_sigma_m))
    return ::testing::AssertionFailure() << "non-finite covariance, status " << to_string(e.status);
  if (!e.valid()) return ::testing::AssertionSuccess();
  if (!std::isfinite(e.position.lat_rad) || !std::isfinite(e.position.lon_rad) || !std::isfinite(e.position.h_m) ||
      !e.en_m.allFinite())
    return ::testing::AssertionFailure() << "valid estimate with a non-finite position (" << e.reason << ")";
  const Eigen::Matrix2d& c = e.cov_en_m2;
  if (std::abs(c(0, 1) - c(1, 0)) > 1e-6 * (1.0 + std::abs(c(0, 1))))
    return ::testing::AssertionFailure() << "asymmetric covariance";
  const Eigen::Vector2d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(c).eigenvalues();
  if (ev.minCoeff() < -1e-9 * (1.0 + ev.maxCoeff()) || !(c.trace() > 0.0))
    return ::testing::AssertionFailure() << "covariance not positive: eigenvalues " << ev.transpose();
  return ::testing::AssertionSuccess();
}

/// Elevation of the synthetic hills at local (east, north), metres.
inline double hill_elevation_m(double e_m, double n_m) {
  return 1200.0 + 60.0 * std::sin(e_m / 260.0) * std::cos(n_m / 340.0) + 25.0 * std::sin((e_m + n_m) / 90.0) +
         0.02 * e_m;
}

/// DEM info of a square tile centred on (kLat0, kLon0).
inline terrain::DemInfo hill_info(int nodes, double cell_m) {
  terrain::DemInfo info;
  info.origin_lat_deg = kLat0;
  info.origin_lon_deg = kLon0;
  info.cols = nodes;
  info.rows = nodes;
  info.cell_m = cell_m;
  info.x0_m = -0.5 * (nodes - 1) * cell_m;
  info.y0_m = info.x0_m;
  info.vertical_datum = "EGM96";
  info.source = "synthetic";
  return info;
}

/// Node values rows south -> north; all NaN when `void_everywhere`.
inline std::vector<float> hill_values(const terrain::DemInfo& info, bool void_everywhere) {
  std::vector<float> v(static_cast<std::size_t>(info.cols * info.rows));
  for (int j = 0; j < info.rows; ++j)
    for (int i = 0; i < info.cols; ++i)
      v[static_cast<std::size_t>(j * info.cols + i)] =
          void_everywhere ? std::nanf("")
                          : static_cast<float>(hill_elevation_m(info.x0_m + i * info.cell_m, info.y0_m + j * info.cell_m));
  return v;
}

inline std::shared_ptr<const terrain::Dem> hill_dem(int nodes = 101, double cell_m = 30.0, bool void_everywhere = false) {
  const auto info = hill_info(nodes, cell_m);
  return std::make_shared<const terrain::Dem>(terrain::Dem::from_grid(info, hill_values(info, void_everywhere)));
}

/// Writes the hills as a .pdem file (docs/dem-format.md) for the Navigator; voids = nodata.
inline std::string write_hill_pdem(const std::string& path, int nodes, double cell_m, bool void_everywhere = false) {
  const auto info = hill_info(nodes, cell_m);
  const auto values = hill_values(info, void_everywhere);
  std::string data(values.size() * 4, '\0');
  for (std::size_t i = 0; i < values.size(); ++i) {
    const float v = std::isfinite(values[i]) ? values[i] : -32768.0f;
    std::uint32_t u = 0;
    std::memcpy(&u, &v, 4);
    for (int b = 0; b < 4; ++b) data[i * 4 + static_cast<std::size_t>(b)] = static_cast<char>((u >> (8 * b)) & 0xFFu);
  }
  char crc[16];
  std::snprintf(crc, sizeof crc, "%08x",
                terrain::crc32(reinterpret_cast<const std::uint8_t*>(data.data()), data.size()));
  std::ostringstream h;
  h.precision(12);
  h << "PDEM 1\ncrs local_enu\norigin_lat_deg " << kLat0 << "\norigin_lon_deg " << kLon0 << "\ncols "
    << info.cols << "\nrows " << info.rows << "\ncell_m " << info.cell_m << "\nx0_m " << info.x0_m << "\ny0_m "
    << info.y0_m << "\nnodata -32768.0\nvertical_datum EGM96\nsource synthetic\ndata_crc32 " << crc
    << "\nend_header\n";
  std::ofstream f(path, std::ios::binary);
  f << h.str() << data;
  return path;
}

/// Accelerometer of a chest-mounted phone (top up: gravity on +Y) while walking at
/// `cadence_hz` steps per second from t_walk0_s to t_walk1_s (standing otherwise), sampled
/// at `rate_hz` with +-5 % timing jitter and 0.15 m/s^2 noise. Returns (t_ns, acc) pairs.
struct AccelTrace {
  std::vector<TimeNs> t_ns;
  std::vector<Eigen::Vector3d> acc_mps2;
};

inline AccelTrace walking_accel(double rate_hz, double duration_s, double t_walk0_s, double t_walk1_s,
                                double cadence_hz, std::uint64_t seed, TimeNs t0_ns = 1'000'000'000) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.15);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  AccelTrace tr;
  const double period_s = 1.0 / rate_hz;
  for (double t = 0.0; t < duration_s; t += period_s) {
    const double ts = t + (t > 0.0 ? jitter(rng) * period_s : 0.0);
    const bool walking = ts >= t_walk0_s && ts < t_walk1_s;
    const double ph = 2.0 * kPi * cadence_hz * (ts - t_walk0_s);
    Eigen::Vector3d a(0.0, kStandardGravity_mps2, 0.0);
    if (walking) a += Eigen::Vector3d(0.4 * std::sin(0.5 * ph + 0.3), 2.2 * std::sin(ph) + 0.5 * std::sin(2.0 * ph + 0.7),
                                      0.8 * std::sin(ph + 1.1));
    a += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    tr.t_ns.push_back(t0_ns + static_cast<TimeNs>(ts * 1e9));
    tr.acc_mps2.push_back(a);
  }
  return tr;
}

}  // namespace pdnav::reliability
