#include "pdnav/gnss/noise_model.h"

#include <algorithm>
#include <cmath>

#include "pdnav/gnss/measurements.h"

namespace pdnav::gnss {

SignalBand signal_band(double carrier_hz) {
  return std::isfinite(carrier_hz) && carrier_hz < 1.3e9 ? SignalBand::kL5 : SignalBand::kL1;
}

SignalBand code_band(bool iono_free, double carrier_hz) {
  return iono_free ? SignalBand::kL1 : signal_band(carrier_hz);
}

const char* to_string(SignalBand b) { return b == SignalBand::kL5 ? "L5" : "L1"; }

CodeNoiseModel CodeNoiseModel::uniform(double a_m2, double b_m2hz) {
  const CodeNoiseParams p{a_m2, b_m2hz};
  return CodeNoiseModel{p, p, p, p, p, p, p};
}

const CodeNoiseParams& CodeNoiseModel::params(Constellation sys, SignalBand band) const {
  const bool l5 = band == SignalBand::kL5;
  switch (sys) {
    case Constellation::kGlonass: return glonass_g1;
    case Constellation::kGalileo: return l5 ? galileo_e5a : galileo_e1;
    case Constellation::kBeidou: return l5 ? beidou_b2a : beidou_b1;
    case Constellation::kGps:
    case Constellation::kQzss: return l5 ? gps_l5 : gps_l1;
    default: return gps_l1;
  }
}

namespace {
double cn0_term(double b, double cn0_dbhz) { return b * std::pow(10.0, -cn0_dbhz / 10.0); }
bool combined(bool iono_free, double cn0_l5_dbhz) { return iono_free && std::isfinite(cn0_l5_dbhz); }
}  // namespace

double cn0_elevation_variance(double a, double b, double cn0_dbhz, double el_rad, double white_ratio) {
  const double s = std::max(std::sin(el_rad), 0.1);
  return a / (s * s) + white_ratio * cn0_term(b, cn0_dbhz);
}

double CodeNoiseModel::variance_m2(Constellation sys, double carrier_hz, double cn0_dbhz, double el_rad,
                                   double white_ratio) const {
  const CodeNoiseParams& p = params(sys, signal_band(carrier_hz));
  return cn0_elevation_variance(p.a_m2, p.b_m2hz, cn0_dbhz, el_rad, white_ratio);
}

double CodeNoiseModel::zenith_variance_m2(Constellation sys, SignalBand band, double cn0_dbhz) const {
  const CodeNoiseParams& p = params(sys, band);
  return cn0_elevation_variance(p.a_m2, p.b_m2hz, cn0_dbhz, kPi / 2);
}

double iono_free_variance_m2(const CodeNoiseModel& m, Constellation sys, double cn0_l1_dbhz, double cn0_l5_dbhz,
                             double el_rad, double white_ratio) {
  const CodeNoiseParams& p1 = m.params(sys, SignalBand::kL1);
  const CodeNoiseParams& p5 = m.params(sys, SignalBand::kL5);
  return kIfAlpha * kIfAlpha * cn0_elevation_variance(p1.a_m2, p1.b_m2hz, cn0_l1_dbhz, el_rad, white_ratio) +
         kIfBeta * kIfBeta * cn0_elevation_variance(p5.a_m2, p5.b_m2hz, cn0_l5_dbhz, el_rad, white_ratio);
}

double code_variance_m2(const CodeNoiseModel& m, Constellation sys, double carrier_hz, bool iono_free,
                        double cn0_dbhz, double cn0_l5_dbhz, double el_rad, double white_ratio) {
  return combined(iono_free, cn0_l5_dbhz) ? iono_free_variance_m2(m, sys, cn0_dbhz, cn0_l5_dbhz, el_rad, white_ratio)
                                          : m.variance_m2(sys, carrier_hz, cn0_dbhz, el_rad, white_ratio);
}

double code_white_variance_m2(const CodeNoiseModel& m, Constellation sys, double carrier_hz, bool iono_free,
                              double cn0_dbhz, double cn0_l5_dbhz) {
  if (combined(iono_free, cn0_l5_dbhz))
    return kIfAlpha * kIfAlpha * cn0_term(m.params(sys, SignalBand::kL1).b_m2hz, cn0_dbhz) +
           kIfBeta * kIfBeta * cn0_term(m.params(sys, SignalBand::kL5).b_m2hz, cn0_l5_dbhz);
  return cn0_term(m.params(sys, signal_band(carrier_hz)).b_m2hz, cn0_dbhz);
}

}  // namespace pdnav::gnss
