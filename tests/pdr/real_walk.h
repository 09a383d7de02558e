// One real ILC 2020 walk in memory (accelerometer, gyroscope, rotation vector) and a helper
// that feeds one or two such recordings through a Pdr in time order. Shared by the motion,
// placement and vehicle tests.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pdnav/geo/samples.h"
#include "pdnav/pdr/pdr.h"

namespace pdnav::test {

struct RealWalk {
  std::vector<AccelSample> accel;
  std::vector<GyroSample> gyro;
  std::vector<RotationVectorSample> rotation;
  std::vector<MagSample> mag;  // read, not fed by run() (run_without_gyro feeds it)
};

/// The sensor lines of one ILC walk (tab-separated "unix_ms TYPE x y z [acc]").
inline RealWalk read_ilc(const std::string& path) {
  RealWalk w;
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::int64_t ms = 0;
    std::string type;
    double x = 0, y = 0, z = 0;
    if (!(ss >> ms >> type >> x >> y >> z)) continue;
    const TimeNs t = ms * 1'000'000;
    if (type == "TYPE_ACCELEROMETER") w.accel.push_back({t, ms, {x, y, z}});
    else if (type == "TYPE_GYROSCOPE") w.gyro.push_back({t, ms, {x, y, z}});
    else if (type == "TYPE_MAGNETIC_FIELD") w.mag.push_back({t, ms, {x, y, z}});
    else if (type == "TYPE_ROTATION_VECTOR")
      w.rotation.push_back({t, ms, {x, y, z, std::sqrt(std::max(0.0, 1 - x * x - y * y - z * z))}, kNaN});
  }
  return w;
}

inline std::vector<PdrStep> run(const pdr::PdrOptions& o, const RealWalk& a, const RealWalk* b = nullptr) {
  pdr::Pdr p(o);
  std::vector<PdrStep> out;
  auto feed = [&](const RealWalk& w) {
    std::size_t ig = 0, ir = 0;
    for (const auto& s : w.accel) {
      while (ig < w.gyro.size() && w.gyro[ig].t_ns <= s.t_ns) p.feed(w.gyro[ig++]);
      while (ir < w.rotation.size() && w.rotation[ir].t_ns <= s.t_ns) p.feed(w.rotation[ir++]);
      p.feed(s);
      for (const auto& st : p.take_steps()) out.push_back(st);
    }
  };
  feed(a);
  if (b) feed(*b);
  p.finish();  // a short last walk and any step still waiting are released
  for (const auto& st : p.take_steps()) out.push_back(st);
  return out;
}

/// As run(), a phone without a gyroscope: the accelerometer and the magnetometer in time order.
inline std::vector<PdrStep> run_without_gyro(const pdr::PdrOptions& o, const RealWalk& a, const RealWalk* b = nullptr) {
  pdr::Pdr p(o);
  std::vector<PdrStep> out;
  auto feed = [&](const RealWalk& w) {
    std::size_t im = 0;
    for (const auto& s : w.accel) {
      while (im < w.mag.size() && w.mag[im].t_ns <= s.t_ns) p.feed(w.mag[im++]);
      p.feed(s);
      for (const auto& st : p.take_steps()) out.push_back(st);
    }
  };
  feed(a);
  if (b) feed(*b);
  p.finish();
  for (const auto& st : p.take_steps()) out.push_back(st);
  return out;
}

/// Feeds a recording's accelerometer and gyroscope in time order plus an Android step-detector
/// event every period_ns from first_event_ns (a phone detector firing); returns the steps taken
/// (including those released by finish() when `finish`).
inline std::size_t feed_with_step_events(pdr::Pdr& p, const RealWalk& w, TimeNs first_event_ns, TimeNs period_ns,
                                         bool finish) {
  std::size_t ig = 0, counted = 0;
  TimeNs next_event = first_event_ns;
  for (const auto& s : w.accel) {
    while (ig < w.gyro.size() && w.gyro[ig].t_ns <= s.t_ns) p.feed(w.gyro[ig++]);
    p.feed(s);
    if (s.t_ns >= next_event) {
      p.feed(StepDetectorSample{s.t_ns, kMissingInt});
      next_event += period_ns;
    }
    counted += p.take_steps().size();
  }
  if (finish) {
    p.finish();
    counted += p.take_steps().size();
  }
  return counted;
}

}  // namespace pdnav::test
