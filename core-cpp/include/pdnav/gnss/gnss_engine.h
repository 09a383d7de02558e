// The GNSS engine's face (docs/architecture.md): GnssOptions -> GnssEngine(options, eph, seed)
// -> feed(GnssRawSample) / estimate(). Raw rows are grouped into receiver epochs by TimeNanos;
// each epoch runs measurements -> SPP -> TDCP (or Doppler) -> robust KF (Walker 2019).
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/estimate.h"
#include "pdnav/geo/frames.h"
#include "pdnav/geo/samples.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/kalman.h"
#include "pdnav/gnss/measurements.h"
#include "pdnav/gnss/solver_smoothing.h"
#include "pdnav/gnss/spp.h"
#include "pdnav/gnss/tdcp.h"

namespace pdnav::gnss {

struct GnssOptions {
  MeasurementOptions measurements;   // C/N0 >= 15 dB-Hz etc. (Walker 2019 Sec. 2.2)
  SmoothingOptions smoothing;        // Hatch carrier smoothing, 100 s (RTCA DO-229); window_s = 0 = raw code
  /// Weight a smoothed code by what smoothing left of its white (C/N0) noise, the elevation
  /// (multipath) term whole (RTCA DO-229 Appendix J's smoothed receiver noise vs multipath).
  bool smoothed_code_white_noise = true;
  /// The fixes' common bias that no averaging within a log removes (single-frequency
  /// ionosphere and troposphere residuals, receiver biases): a consider variance (Schmidt 1966)
  /// added to each horizontal axis of the KF's reported covariance; the estimate is unchanged.
  /// 1.0 m = RMS of the per-axis mean SPP error of the two real logs with truth (Mountain View
  /// 1.04 / -0.14 m e/n, GSDC drive -0.15 / 1.79 m; docs/gnss.md). 0 = off.
  double fix_bias_sigma_h_m = 1.0;
  SppOptions spp;                    // WLS + ISB + FDE (Walker 2019 Eq. 1)
  TdcpOptions tdcp;                  // a = 10, b = 150^2 (Walker 2019 Sec. 2.4)
  KalmanOptions kalman;              // residual test 36 (Walker 2019 Sec. 2.5); dynamics (Groves 2013)
  double max_epoch_gap_s = 10.0;     // a longer gap drops the previous epoch (no TDCP across it)
  bool use_doppler_fallback = true;  // pseudorange-rate velocity when TDCP is unavailable
  int lost_after_epochs = 30;        // status kLost after this many epochs without an SPP update
  int min_sats_ok = 6;               // fewer used satellites -> status kDegraded
  /// Scale the SPP covariance given to the KF by max(1, chi2/dof), the a-posteriori variance
  /// of unit weight (Teunissen, Adjustment Theory 2003, Sec. 4.3); docs/gnss.md has the effect.
  bool scale_fix_by_variance_factor = true;
  /// Keep each epoch's SPP inputs in EpochSolution::code_obs (noise-model learning; off in use).
  bool record_code_observations = false;
};

/// One receiver epoch's result.
struct EpochSolution {
  TimeNs t_ns = 0;                          // elapsedRealtimeNanos of the epoch
  std::int64_t gps_ns = 0;                  // receive time, GPS time
  geo::Ecef spp;
  bool spp_ok = false;
  std::string spp_reason;                   // why not ok
  double hdop = 0.0, pdop = 0.0;
  Eigen::Matrix3d spp_cov_enu = Eigen::Matrix3d::Identity();  // m^2, the SPP's a-priori (code noise model) covariance
  double spp_variance_factor = kNaN;        // chi2 / dof of the SPP fit (NaN without redundancy)
  Eigen::Vector3d tdcp_disp_m = Eigen::Vector3d::Zero();  // ENU displacement since the previous epoch
  bool tdcp_ok = false;
  std::string disp_source;                  // "tdcp", "doppler" or "" (none)
  double disp_dt_s = 0.0;
  int tdcp_sats = 0;
  geo::Ecef kf;
  bool kf_ok = false;
  bool kf_update_accepted = false;
  Eigen::Matrix3d kf_cov_enu = Eigen::Matrix3d::Identity();  // m^2, at the KF position
  Eigen::Vector3d kf_vel_enu_mps = Eigen::Vector3d::Zero();  // KF velocity, ENU at the KF position
  double clock_m = 0.0;                     // KF receiver clock (reference system), m
  int sats_used = 0;                        // in SPP
  int sats_tracked = 0;                     // rows of the epoch
  std::map<Constellation, int> used_by_sys;
  Constellation clock_system = Constellation::kGps;  // reference system of the SPP clock
  /// The engine status after this epoch (what estimate() returns then): kOk, kDegraded (coasting
  /// or fewer than min_sats_ok satellites; still a usable position), kLost, kNotInitialized.
  EstimateStatus status = EstimateStatus::kNotInitialized;
  /// With GnssOptions::record_code_observations: the SPP's code observations (smoothed as the
  /// SPP used them) and, in the same order, the code before smoothing.
  std::vector<SppObservation> code_obs;
  std::vector<double> code_raw_m;
};

class GnssEngine {
 public:
  /// `eph` may be null (then every satellite is excluded as "ephemeris: no ephemeris").
  /// The engine is deterministic; the seed is kept for the common engine face.
  GnssEngine(const GnssOptions& options, std::shared_ptr<const EphemerisStore> eph, std::uint64_t seed);
  ~GnssEngine();
  GnssEngine(GnssEngine&&) noexcept;
  GnssEngine& operator=(GnssEngine&&) noexcept;

  /// Rows of one epoch share TimeNanos; an epoch is processed when the next one starts, or
  /// at once by flush() when the caller knows the epoch is complete (a GnssMeasurementsEvent,
  /// the end of a RINEX epoch, the first non-Raw line after Raw lines of a log).
  void feed(const GnssRawSample& s);
  /// All rows of one epoch (one GnssMeasurementsEvent): processed immediately, no latency.
  void feed_epoch(const std::vector<GnssRawSample>& rows);
  /// GPS LNAV subframes (type 0x0101) go into the engine's own copy of the ephemeris store.
  void feed(const NavMessageSample& s);
  /// Process the pending epoch.
  void flush();
  /// Reset the filter (e.g. after the fusion layer detects a jump).
  void reset();

  /// KF estimate: kOk / kDegraded / kLost with a reason; kNotInitialized before a first fix.
  Estimate estimate() const;
  /// Epoch solutions produced since the last call.
  std::vector<EpochSolution> take_solutions();
  /// Everything excluded or skipped so far, by reason.
  const std::map<std::string, std::int64_t>& exclusions() const;
  std::int64_t epochs() const;
  std::uint64_t seed() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pdnav::gnss
