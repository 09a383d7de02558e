// Walk fixtures shared by the benchmarks (core-cpp/bench) and the tests: the benchmarks'
// 12 x 12 km hills tile, the step events of a chest-mounted phone and its chipset Fix rows. Header-only, no GoogleTest
// (the benchmarks include it too).
#pragma once
#include <array>
#include <cmath>
#include <memory>

#include <Eigen/Geometry>

#include "../terrain/synthetic_dem.h"
#include "pdnav/geo/frames.h"
#include "pdnav/geo/samples.h"
#include "pdnav/terrain/dem.h"

namespace pdnav::test {

/// 12 x 12 km of hills at 30 m (401 x 401 nodes around 42.5 N 1.5 E: the size of the Andorra
/// eval tile), two sinusoidal ridge sets of ~360 m relief.
inline std::shared_ptr<const terrain::Dem> bench_hills_dem() {
  return std::make_shared<const terrain::Dem>(synthetic_dem(401, 401, 30.0, [](double e, double n) {
    return 1500 + 120 * std::sin(e / 700) * std::cos(n / 900) + 60 * std::sin((e + 2 * n) / 330);
  }));
}

/// A phone on the chest, camera (-Z) forward, the walker facing north: device X east, Y up, Z south.
inline Eigen::Matrix3d chest_facing_north() {
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(1, 0, 0);
  r.col(1) = Eigen::Vector3d(0, 0, 1);
  r.col(2) = Eigen::Vector3d(0, -1, 0);
  return r;
}

/// That phone's attitude when the walker faces heading_rad (clockwise from north).
inline Eigen::Quaterniond chest_facing(double heading_rad) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(-heading_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                            chest_facing_north());
}

/// One step as Android logs it: the rotation vector (attitude q, heading accuracy 0.1 rad) at
/// rv_t_ns, then the step-detector event at step_t_ns.
inline std::array<Sample, 2> step_events(TimeNs rv_t_ns, TimeNs step_t_ns, const Eigen::Quaterniond& q) {
  RotationVectorSample rv;
  rv.t_ns = rv_t_ns;
  rv.quat_xyzw = Eigen::Vector4d(q.x(), q.y(), q.z(), q.w());
  rv.heading_accuracy_rad = 0.1;
  StepDetectorSample sd;
  sd.t_ns = step_t_ns;
  return {Sample(rv), Sample(sd)};
}

/// A chipset Fix row (provider GPS) at t_ns: position g, altitude alt_m, horizontal accuracy accuracy_m.
inline FixSample gps_fix(TimeNs t_ns, const geo::Geodetic& g, double alt_m, double accuracy_m) {
  FixSample f;
  f.t_ns = t_ns;
  f.provider = "GPS";
  f.lat_deg = g.lat_deg();
  f.lon_deg = g.lon_deg();
  f.alt_m = alt_m;
  f.accuracy_m = accuracy_m;
  return f;
}

}  // namespace pdnav::test
