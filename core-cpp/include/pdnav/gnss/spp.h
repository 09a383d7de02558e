// Single-point positioning: weighted least squares in ECEF with one receiver clock per epoch
// plus one inter-system bias per extra constellation (Walker, Remote Sens. 2019, Eq. 1 and
// its multi-GNSS form), Sagnac correction, Klobuchar + Saastamoinen, elevation mask, DOP and
// residual-based fault detection and exclusion (chi-square test, exclude worst, repeat).
#pragma once
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/frames.h"
#include "pdnav/geo/samples.h"
#include "pdnav/gnss/atmosphere.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/noise_model.h"
#include "pdnav/gnss/types.h"

namespace pdnav::gnss {

/// Upper quantile of the chi-square distribution (Wilson-Hilferty approximation, relative
/// error < 3 % for dof >= 1 at P_fa 1e-3..0.05, erring high, i.e. slightly conservative).
double chi_square_quantile(double p_false_alarm, int dof);

/// How the FDE picks what to exclude when the chi-square test fails.
enum class SppFde {
  kLargestResidual,  // drop the largest normalised residual, refit, repeat (classic RAIM)
  kSubsets,          // test subsets: leave-one-out, then leave-two-out, on the candidates with the
                     // largest standardised residuals (Baarda w-test ranking), chi-square on each
};

struct SppOptions {
  double elevation_mask_deg = 10.0;     // Walker 2019 Sec. 2.2 (10 deg mask)
  // code variance a / sin^2(el) + b 10^(-C/N0/10) per constellation and band (Walker 2019
  // Sec. 2.3 form; a, b learned from the shared data: noise_model.h, docs/gnss.md)
  CodeNoiseModel code_noise;
  double fde_false_alarm = 1e-3;        // chi-square test probability (RAIM P_fa)
  int max_fde_exclusions = 4;           // stop excluding after this many satellites
  SppFde fde = SppFde::kSubsets;        // two 30-60 m multipath faults defeat kLargestResidual (tests)
  int fde_candidates = 6;               // subsets are drawn from this many worst standardised residuals
  // After the FDE: IGG-III equivalent weights on the standardised residuals (Yang, Song & Xu
  // 2002, J. Geodesy 76:353-358), k0 = 1.5, k1 = 3.0; iterated reweighting, at most 5 passes.
  bool robust_igg3 = true;
  double igg_k0 = 1.5;
  double igg_k1 = 3.0;
  int max_iterations = 12;
  double convergence_m = 1e-4;
  double max_gdop = 30.0;               // worse geometry is rejected as singular
  double min_rcond = 1e-10;             // normal-matrix reciprocal condition number guard
  bool ionosphere = true;               // Klobuchar (IS-GPS-200 20.3.3.5.2.5), scaled by (f_L1/f)^2
  bool troposphere = true;              // Saastamoinen + mapping function
  bool drop_single_sat_systems = true;  // a lone satellite of a system only feeds its own ISB
};

/// One pseudorange with the satellite state at its transmit time.
struct SppObservation {
  SatId sat;
  double pseudorange_m = 0.0;
  double cn0_dbhz = 0.0;
  double carrier_hz = 1575.42e6;
  SatState state;  // at transmit time, from EphemerisStore::state
  /// The code is the L1/L5 ionosphere-free combination (measurements.h): no Klobuchar and no
  /// TGD/BGD (the combination removes both); its variance is iono_free_variance_m2 from the L1
  /// and L5 C/N0 (noise_model.h).
  bool iono_free = false;
  double var_scale = 1.0;           // multiplies the model variance
  double cn0_l5_dbhz = kNaN;        // the L5/E5a C/N0 of an iono_free code
  /// The share of the white (C/N0) noise variance left after carrier smoothing
  /// (CodeSmoother::white_variance_ratio); 1 = raw code.
  double white_var_ratio = 1.0;
};

struct SppSolution {
  bool ok = false;
  std::string reason;                              // why not ok ("fewer than 4 satellites", ...)
  geo::Ecef pos;
  double clock_m = 0.0;                            // receiver clock of the reference system, c*dt
  Constellation clock_system = Constellation::kGps;
  SignalBand clock_band = SignalBand::kL1;         // band of the reference clock (L5 only without GPS L1)
  std::map<Constellation, double> isb_m;           // inter-system bias vs the reference system (L1 band)
  std::map<Constellation, double> isb_l5_m;        // the L5-band clocks (FrequencyMode::kBest) vs the reference
  Eigen::Matrix3d pos_cov_ecef = Eigen::Matrix3d::Identity();  // a priori weights, m^2
  double clock_var_m2 = 0.0;
  double gdop = 0.0, pdop = 0.0, hdop = 0.0, vdop = 0.0;
  std::vector<SatId> used;
  std::vector<double> residuals_m;                 // post-fit, same order as used
  std::vector<double> elevations_rad;              // same order as used
  std::vector<SatId> excluded_fde;
  std::map<std::string, std::int64_t> excluded;    // reason -> count (mask, single-sat system, FDE)
  int iterations = 0;
  double chi2 = 0.0;                               // weighted sum of squared residuals (robust weights in)
  int downweighted = 0;                            // satellites with an IGG-III weight < 1
  std::map<Constellation, int> used_by_sys() const;
};

/// Solves one epoch. `initial` is a position guess (Earth centre when unknown); the elevation
/// mask and atmosphere are applied once the iterate is near the Earth's surface. `gps_tow_s`
/// is the reception time of week for Klobuchar; `klob` may be null (no ionosphere model).
SppSolution solve_spp(const std::vector<SppObservation>& obs, const geo::Ecef& initial,
                      double gps_tow_s, const KlobucharParams* klob, const SppOptions& opt);

/// One code residual at a known receiver position (noise-model learning, noise_model.h).
struct TruthResidual {
  SatId sat;
  double carrier_hz = 0.0;
  double cn0_dbhz = 0.0;
  double el_rad = 0.0;
  double az_rad = 0.0;      // clockwise from north
  double residual_m = 0.0;  // measured - modelled - receiver clock of its clock group
  int group_size = 0;       // satellites of its clock group that epoch
};

struct TruthResidualOptions {
  int min_group = 3;               // clock groups with fewer satellites are left out
  bool estimate_height = false;    // the truth's height is unknown or biased: estimate an offset
};

/// Residuals of `obs` at the receiver position `truth`, with solve_spp's corrections (Sagnac,
/// satellite clock and group delay, Klobuchar, Saastamoinen, elevation mask). The receiver
/// clock of each clock group (and with estimate_height a height offset along the truth's up)
/// is fitted by least absolute deviations (robust to multipath tails); the residuals are
/// scaled by sqrt(N / (N - P)) for the P fitted unknowns.
std::vector<TruthResidual> residuals_at_truth(const std::vector<SppObservation>& obs, const geo::Ecef& truth,
                                              double gps_tow_s, const KlobucharParams* klob, const SppOptions& opt,
                                              const TruthResidualOptions& ropt = {});

/// The receiver-clock group of a system: QZSS shares GPS time (IS-QZSS-PNT 3.2: QZSST is
/// steered to GPST and L1 C/A is interoperable), every other system has its own ISB.
Constellation clock_group(Constellation sys);

/// Sagnac (Earth rotation during signal travel) correction: the satellite position of the
/// transmit instant expressed in the ECEF frame of the receive instant.
Eigen::Vector3d rotate_for_travel_time(const Eigen::Vector3d& sat_ecef_m, double travel_s);

}  // namespace pdnav::gnss
