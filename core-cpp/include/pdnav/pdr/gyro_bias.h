// The bias of an uncalibrated gyroscope from the intervals the phone lies still (a zero angular
// rate update: Foxlin, IEEE CG&A 2005; the same stillness test Android's own gyro calibration
// runs before it reports TYPE_GYROSCOPE). Used for an uncalibrated stream whose logger did not
// export the platform's drift estimate (Sensor Logger's GyroscopeUncalibrated.csv): a MEMS gyro's
// zero-rate offset is 1-5 deg/s (the shared ETH phone: -3.5, +2.8, +3.9 deg/s), which integrated
// over a 30 s straight is a phantom turn of ~100 deg and tilts the attitude the placement,
// compass and hard-iron pairs read. Nothing is assumed before the first still interval.
#pragma once
#include <cstdint>

#include <Eigen/Core>

#include "pdnav/geo/samples.h"
#include "pdnav/geo/units.h"

namespace pdnav::pdr {

struct GyroBiasOptions {
  double block_s = 2.0;  // the rate is averaged over consecutive blocks of this length
  // a block is still when every axis' rate scatters less than this about its mean (a phone on a
  // table: 0.1-0.2 deg/s of sensor noise; held in the hand 1-3 deg/s, walking > 5 deg/s) ...
  double max_rate_std_radps = 0.5 * kDegToRad;
  // ... and |a| less than this (any handling or vehicle vibration moves it by more)
  double max_accel_std_mps2 = 0.05;
  int min_samples = 20;      // gyro samples in a still block (and accelerometer samples, if any)
  double tau_s = 600.0;      // memory of the still blocks' means (the offset follows temperature)
  double max_bias_radps = 10.0 * kDegToRad;  // a block mean beyond this is a slow turn, not a bias
};

class GyroBiasAtRest {
 public:
  explicit GyroBiasAtRest(const GyroBiasOptions& o = {}) : o_(o) {}
  /// A raw (uncalibrated, drift not removed) angular rate.
  void feed_gyro(TimeNs t_ns, const Eigen::Vector3d& rate_radps);
  /// The specific force in the phone (calibrated or not: only |a|'s scatter is read).
  void feed_accel(TimeNs t_ns, const Eigen::Vector3d& acc_mps2);
  /// The bias estimate (zero before the first still block).
  Eigen::Vector3d bias_radps() const { return weight_ > 0.0 ? Eigen::Vector3d(sum_ / weight_) : Eigen::Vector3d::Zero(); }
  std::int64_t still_blocks() const { return still_blocks_; }
  bool known() const { return still_blocks_ > 0; }

 private:
  struct Block {
    std::int64_t index = -1;
    int n = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum2 = Eigen::Vector3d::Zero();
    void add(const Eigen::Vector3d& x) { ++n, sum += x, sum2 += x.cwiseProduct(x); }
  };
  struct ScalarBlock {
    std::int64_t index = -1;
    int n = 0;
    double sum = 0.0, sum2 = 0.0;
  };
  std::int64_t block_of(TimeNs t_ns);
  void close_gyro_block();

  GyroBiasOptions o_;
  TimeNs t0_ns_ = -1;
  Block gyro_;
  ScalarBlock accel_, accel_done_;  // the current accelerometer block and the last closed one
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero();
  double weight_ = 0.0;
  TimeNs last_still_ns_ = -1;
  std::int64_t still_blocks_ = 0;
};

}  // namespace pdnav::pdr
