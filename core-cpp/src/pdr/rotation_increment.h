// The attitude increment of a gyro rate held for dt (internal to pdr/): the rotation by
// |rate| dt about rate / |rate|, identity when there is no rotation.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace pdnav::pdr::detail {

inline Eigen::Quaterniond rotation_increment(const Eigen::Vector3d& rate_radps, double dt_s) {
  const double angle = rate_radps.norm() * dt_s;
  if (!(angle > 0.0)) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, rate_radps.normalized()));
}

}  // namespace pdnav::pdr::detail
