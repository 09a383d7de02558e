#include "pdnav/geo/baro.h"

#include <cmath>
#include <limits>

namespace pdnav::geo {

double baro_altitude_m(double p, double p_ref, double h_ref, const BaroOptions& o) {
  if (!(p > 0.0) || !(p_ref > 0.0) || !std::isfinite(p) || !std::isfinite(p_ref))
    return std::numeric_limits<double>::quiet_NaN();
  const double expo = o.gas_constant_jpkgk * o.lapse_rate_kpm / o.gravity_mps2;
  return h_ref + o.ref_temperature_k / o.lapse_rate_kpm * (1.0 - std::pow(p / p_ref, expo));
}

double baro_pressure_pa(double h, double p_ref, double h_ref, const BaroOptions& o) {
  const double expo = o.gravity_mps2 / (o.gas_constant_jpkgk * o.lapse_rate_kpm);
  const double base = 1.0 - (h - h_ref) * o.lapse_rate_kpm / o.ref_temperature_k;
  if (!(base > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return p_ref * std::pow(base, expo);
}

double BaroAltimeter::update(double p) {
  if (!anchored_ || !(p > 0.0) || !std::isfinite(p)) return std::numeric_limits<double>::quiet_NaN();
  if (ref_p_pa_ <= 0.0) ref_p_pa_ = p;
  return baro_altitude_m(p, ref_p_pa_, ref_alt_m_, opt_);
}

}  // namespace pdnav::geo
