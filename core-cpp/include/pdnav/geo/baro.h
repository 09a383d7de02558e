// Barometric altitude. Hypsometric equation in the standard-atmosphere form
// (Walker, Remote Sens. 2019, Eq. 10; ICAO Doc 7488 lapse rate and constants):
//   h = h_ref + (T_ref / L) * (1 - (p / p_ref)^(R L / g))
#pragma once

namespace pdnav::geo {

struct BaroOptions {
  double lapse_rate_kpm = 0.0065;       // L, K/m (ICAO standard atmosphere)
  double ref_temperature_k = 288.15;    // T_ref at the reference altitude
  double gas_constant_jpkgk = 287.053;  // R for dry air
  double gravity_mps2 = 9.80665;        // g
};

/// Altitude (m) of pressure p given a reference pressure at a reference altitude.
double baro_altitude_m(double pressure_pa, double ref_pressure_pa, double ref_altitude_m,
                       const BaroOptions& opt = {});

/// Pressure (Pa) expected at altitude h given the reference; inverse of baro_altitude_m.
double baro_pressure_pa(double altitude_m, double ref_pressure_pa, double ref_altitude_m,
                        const BaroOptions& opt = {});

/// Barometric altimeter anchored at a known altitude: the first pressure sample after
/// anchor() becomes the reference pressure (e.g. DEM elevation at the declared start).
class BaroAltimeter {
 public:
  explicit BaroAltimeter(BaroOptions opt = {}) : opt_(opt) {}
  /// Declare the altitude at which the next pressure sample is taken.
  void anchor(double altitude_m) { ref_alt_m_ = altitude_m; ref_p_pa_ = 0.0; anchored_ = true; }
  /// Feed a pressure sample; returns the altitude, or NaN before anchoring / on bad input.
  double update(double pressure_pa);
  bool ready() const { return anchored_ && ref_p_pa_ > 0.0; }
  double reference_pressure_pa() const { return ref_p_pa_; }

 private:
  BaroOptions opt_;
  bool anchored_ = false;
  double ref_alt_m_ = 0.0;
  double ref_p_pa_ = 0.0;
};

}  // namespace pdnav::geo
