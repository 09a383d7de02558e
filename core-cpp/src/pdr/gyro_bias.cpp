#include "pdnav/pdr/gyro_bias.h"

#include <algorithm>
#include <cmath>

namespace pdnav::pdr {

std::int64_t GyroBiasAtRest::block_of(TimeNs t_ns) {
  if (t0_ns_ < 0) t0_ns_ = t_ns;
  const double b = std::floor(ns_to_s(t_ns - t0_ns_) / o_.block_s);
  return b < 0.0 ? -1 : static_cast<std::int64_t>(b);
}

void GyroBiasAtRest::feed_accel(TimeNs t_ns, const Eigen::Vector3d& acc_mps2) {
  if (!acc_mps2.allFinite()) return;
  const std::int64_t k = block_of(t_ns);
  if (k < 0) return;
  if (k != accel_.index) {
    if (accel_.index >= 0 && k > accel_.index) accel_done_ = accel_;
    if (k < accel_.index) return;  // late sample of a closed block
    accel_ = ScalarBlock{};
    accel_.index = k;
  }
  const double a = acc_mps2.norm();
  ++accel_.n;
  accel_.sum += a;
  accel_.sum2 += a * a;
}

void GyroBiasAtRest::feed_gyro(TimeNs t_ns, const Eigen::Vector3d& rate_radps) {
  if (!rate_radps.allFinite()) return;
  const std::int64_t k = block_of(t_ns);
  if (k < 0) return;
  if (k != gyro_.index) {
    if (k < gyro_.index) return;  // late sample of a closed block
    if (gyro_.index >= 0) close_gyro_block();
    gyro_ = Block{};
    gyro_.index = k;
  }
  gyro_.add(rate_radps);
}

void GyroBiasAtRest::close_gyro_block() {
  if (gyro_.n < o_.min_samples) return;
  const double n = static_cast<double>(gyro_.n);
  const Eigen::Vector3d mean = gyro_.sum / n;
  const Eigen::Vector3d var = (gyro_.sum2 / n - mean.cwiseProduct(mean)).cwiseMax(0.0);
  if (var.maxCoeff() > o_.max_rate_std_radps * o_.max_rate_std_radps) return;
  if (mean.norm() > o_.max_bias_radps) return;
  // the accelerometer's block of the same time, when the phone has one, must be still too
  const ScalarBlock* a = accel_.index == gyro_.index ? &accel_ : accel_done_.index == gyro_.index ? &accel_done_ : nullptr;
  if (a != nullptr) {
    if (a->n < o_.min_samples) return;
    const double am = a->sum / a->n;
    if (std::max(0.0, a->sum2 / a->n - am * am) > o_.max_accel_std_mps2 * o_.max_accel_std_mps2) return;
  } else if (accel_.index >= 0 || accel_done_.index >= 0) {
    return;  // an accelerometer exists but gave nothing in this block: not judged still
  }
  const TimeNs t_ns = t0_ns_ + s_to_ns(static_cast<double>(gyro_.index + 1) * o_.block_s);
  if (last_still_ns_ >= 0) {
    const double decay = std::exp(-std::max(0.0, ns_to_s(t_ns - last_still_ns_)) / o_.tau_s);
    sum_ *= decay;
    weight_ *= decay;
  }
  sum_ += mean;
  weight_ += 1.0;
  last_still_ns_ = t_ns;
  ++still_blocks_;
}

}  // namespace pdnav::pdr
