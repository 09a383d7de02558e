// Time-differenced carrier phase (TDCP): the receiver displacement between two epochs from
// accumulated-delta-range differences (Walker, Remote Sens. 2019, Sec. 2.4), with the SNR
// weighting sigma^2 = a + b 10^(-C/N0/10), a = 10, b = 150^2 (mm^2), the receiver clock
// drift estimated, and Doppler (pseudorange-rate) velocity as the fallback without ADR.
#pragma once
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/frames.h"
#include "pdnav/geo/samples.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/types.h"

namespace pdnav::gnss {

struct TdcpOptions {
  double snr_a_mm2 = 10.0;               // Walker 2019 Eq. (SNR weighting): a = 10
  double snr_b_mm2 = 150.0 * 150.0;      // b = 150^2
  double elevation_mask_deg = 10.0;      // same mask as SPP (Walker 2019 Sec. 2.2)
  double max_rate_mismatch_mps = 3.0;    // |dADR/dt - pseudorange rate| above this: ADR dropped
  double fde_false_alarm = 1e-3;         // chi-square test, exclude worst, repeat
  int max_fde_exclusions = 4;
  double min_rcond = 1e-10;
  double max_gdop = 30.0;
  // Doppler fallback: sigma^2 = a + b 10^(-C/N0/10) in (m/s)^2, used when the row has no
  // PseudorangeRateUncertainty.
  double doppler_a_m2ps2 = 0.01;
  double doppler_b_m2ps2 = 100.0;        // 0.1 m/s at 30 dB-Hz, 0.03 m/s at 40 dB-Hz
};

/// One satellite in one epoch for TDCP / Doppler.
struct CarrierObservation {
  SatId sat;
  double adr_m = kNaN;                 // NaN when ADR is missing, reset or slipped
  double pr_rate_mps = kNaN;
  double pr_rate_sigma_mps = kNaN;
  double cn0_dbhz = 0.0;
  SatState state;                      // at this epoch's transmit time
  double carrier_hz = kNaN;            // signal identity: TDCP differences only the same signal
  std::string code_type;               // tracking code ("C", "X", ...), "" when unknown
};

/// True when two observations are of the same signal (carrier within 1 kHz when both known,
/// same tracking code when both known); TDCP across a signal change is meaningless.
bool same_signal(const CarrierObservation& a, const CarrierObservation& b);

/// The Doppler (pseudorange rate) variance from C/N0 alone, doppler_a + doppler_b 10^(-C/N0/10)
/// [(m/s)^2]: the Doppler velocity's weight without a reported uncertainty, and the code
/// smoother's propagation noise.
double doppler_cn0_variance_m2ps2(const TdcpOptions& opt, double cn0_dbhz);

struct DisplacementSolution {
  bool ok = false;
  std::string reason;
  std::string source;                  // "tdcp" or "doppler"
  Eigen::Vector3d disp_ecef_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_ecef_m2 = Eigen::Matrix3d::Identity();
  double clock_change_m = 0.0;         // c * (dt2 - dt1) (TDCP) or c * drift * dt (Doppler)
  double clock_change_var_m2 = 0.0;
  double dt_s = 0.0;
  std::vector<SatId> used;
  // false when the chi-square test could not vouch for the solution: no redundant satellite
  // (4 used), or failed with nothing left to exclude. A receiver autonomous integrity check
  // detects nothing without redundancy (Brown, NAVIGATION 1992): such a displacement needs
  // another check (the engine tests it against its KF's prediction).
  bool self_checked = true;
  std::vector<SatId> excluded_fde;
  std::map<std::string, std::int64_t> excluded;
};

/// TDCP displacement from epoch 1 to epoch 2 (both lists: satellites with their states).
/// `rx_ecef` is an approximate receiver position at epoch 1 (SPP quality suffices: the
/// linearisation error is ~ position error x satellite angular motion, < 1 mm for 10 m).
DisplacementSolution solve_tdcp(const std::vector<CarrierObservation>& epoch1,
                                const std::vector<CarrierObservation>& epoch2, double dt_s,
                                const geo::Ecef& rx_ecef, const TdcpOptions& opt);

/// Velocity from pseudorange rates at one epoch (ECEF, m/s) times dt_s as a displacement;
/// the fallback when carrier phase is missing (duty-cycled logs).
DisplacementSolution solve_doppler(const std::vector<CarrierObservation>& epoch, double dt_s,
                                   const geo::Ecef& rx_ecef, const TdcpOptions& opt);

}  // namespace pdnav::gnss
