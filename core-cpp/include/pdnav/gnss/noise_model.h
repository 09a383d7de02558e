// Code (pseudorange) noise per constellation and band (issue 15):
//   sigma^2 = a / sin^2(el) + b * 10^(-C/N0 / 10)
// the SNR form of Walker 2019 Sec. 2.3 (sigma^2 = a + b 10^(-C/N0/10)) with the constant term
// mapped by elevation (RTKLIB-style) for multipath. a and b per constellation and band are
// learned from the shared real data's code residuals against truth (`pdnav gnss
// --residuals-out`, `tools/gnss-noise-fit`); docs/gnss.md "Code noise model" has the fit.
#pragma once
#include "pdnav/gnss/types.h"

namespace pdnav::gnss {

/// L1 = GPS/QZSS L1, Galileo E1, BeiDou B1I/B1C, GLONASS G1; L5 = GPS/QZSS L5, Galileo E5a,
/// BeiDou B2a (1176.45 MHz). A carrier below 1.3 GHz is L5; an unknown (NaN) carrier is L1.
enum class SignalBand : int { kL1 = 0, kL5 = 1 };
SignalBand signal_band(double carrier_hz);
/// The band a code is on for its receiver clock and smoothing: an ionosphere-free L1/L5 code is
/// formed on the L1 clock (measurements.h combine_dual_frequency), any other code on its carrier's.
SignalBand code_band(bool iono_free, double carrier_hz);
const char* to_string(SignalBand b);

struct CodeNoiseParams {
  double a_m2 = 4.0;        // elevation-mapped constant [m^2]
  double b_m2hz = 160000.0; // C/N0 term [m^2 Hz]
};

/// Defaults: the fit of tools/gnss-noise-fit over the GSDC Pixel 5 drive and the Mountain View
/// static log (raw code, residuals at truth; docs/gnss.md). Signals the data does not have
/// (BeiDou, QZSS L5) take the parameters of the physically closest fitted signal, stated per field.
struct CodeNoiseModel {
  CodeNoiseParams gps_l1{1.62, 63460.0};
  CodeNoiseParams gps_l5{0.38, 1728.0};
  CodeNoiseParams glonass_g1{9.89, 221300.0};
  CodeNoiseParams galileo_e1{1.13, 18090.0};
  CodeNoiseParams galileo_e5a{0.25, 1059.0};  // a at the fit's floor (0.5 m zenith, docs/gnss.md)
  CodeNoiseParams beidou_b1{1.62, 63460.0};   // no BeiDou in the data: GPS L1's
  CodeNoiseParams beidou_b2a{0.38, 1728.0};   // no BeiDou in the data: GPS L5's

  /// Every signal with the same (a, b) (tests with a known simulated noise).
  static CodeNoiseModel uniform(double a_m2, double b_m2hz);
  /// QZSS uses GPS's, SBAS/IRNSS/unknown GPS L1's.
  const CodeNoiseParams& params(Constellation sys, SignalBand band) const;
  /// sigma^2 of one code measurement [m^2]; sin(el) is floored at 0.1.
  /// `white_ratio` scales the C/N0 (white, thermal) term only: what carrier smoothing leaves of
  /// it (CodeSmoother::white_variance_ratio); the elevation term (multipath, slow) stays, as in
  /// RTCA DO-229's split of the smoothed-code error into receiver noise and multipath.
  double variance_m2(Constellation sys, double carrier_hz, double cn0_dbhz, double el_rad, double white_ratio = 1.0) const;
  /// Without the elevation term's mapping (el = 90 deg): the zenith variance.
  double zenith_variance_m2(Constellation sys, SignalBand band, double cn0_dbhz) const;
};

/// Variance of the L1/L5 ionosphere-free code alpha P1 - beta P5 (measurements.h) with
/// independent noise on the two bands: alpha^2 v_L1 + beta^2 v_L5 (Misra & Enge 2011 Sec. 5.3.2),
/// each band from its own (a, b) and C/N0 at the same elevation.
double iono_free_variance_m2(const CodeNoiseModel& m, Constellation sys, double cn0_l1_dbhz, double cn0_l5_dbhz,
                             double el_rad, double white_ratio = 1.0);

/// The same model for one (a, b): a / max(sin el, 0.1)^2 + b 10^(-C/N0/10).
double cn0_elevation_variance(double a, double b, double cn0_dbhz, double el_rad, double white_ratio = 1.0);

/// One code's variance, the one dispatch the SPP and the smoother share: the ionosphere-free
/// model when the code is an L1/L5 combination with its L5 C/N0 known, else its carrier's band.
double code_variance_m2(const CodeNoiseModel& m, Constellation sys, double carrier_hz, bool iono_free,
                        double cn0_dbhz, double cn0_l5_dbhz, double el_rad, double white_ratio = 1.0);
/// The white (C/N0) term of that variance alone, b 10^(-C/N0/10) (per band for the combination):
/// the share carrier smoothing averages (CodeSmoother::white_variance_ratio).
double code_white_variance_m2(const CodeNoiseModel& m, Constellation sys, double carrier_hz, bool iono_free,
                              double cn0_dbhz, double cn0_l5_dbhz);

}  // namespace pdnav::gnss
