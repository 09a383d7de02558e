// Step length models (APT Sec. V-A; Weinberg, Analog Devices AN-602).
#include "pdnav/pdr/step_length.h"

#include <algorithm>
#include <cmath>

namespace pdnav::pdr {

StepLengthModel StepLengthModel::apt_male(double height_m) {
  StepLengthModel m;
  m.height_m = height_m;
  m.c1 = 0.415;
  return m;
}

StepLengthModel StepLengthModel::apt_female(double height_m) {
  StepLengthModel m;
  m.height_m = height_m;
  m.c1 = 0.413;
  return m;
}

StepLengthModel StepLengthModel::weinberg(double k) {
  StepLengthModel m;
  m.kind = StepLengthKind::kWeinberg;
  m.weinberg_k = k;
  return m;
}

StepLengthModel StepLengthModel::unknown_walker() {
  StepLengthModel m = weinberg(0.428);
  return m;
}

double StepLengthModel::length_m(double swing_mps2, double step_frequency_hz) const {
  const double s = (std::isfinite(scale) && scale > 0.0) ? scale : 1.0;
  switch (kind) {
    case StepLengthKind::kConstant:
      return s * constant_m;
    case StepLengthKind::kWeinberg:
      if (std::isfinite(swing_mps2) && swing_mps2 > 0.0) {
        return std::clamp(s * weinberg_k * std::pow(swing_mps2, 0.25), min_length_m, max_length_m);
      }
      return s * c1 * height_m;
    case StepLengthKind::kFrequency: {
      // Tian et al. 2016, Eq. 9; cadence outside 0.8-3.5 Hz (a first step, a pause) uses 1.79 Hz.
      const double f = (std::isfinite(step_frequency_hz) && step_frequency_hz >= 0.8 && step_frequency_hz <= 3.5)
                           ? step_frequency_hz
                           : 1.79;
      const double l = 0.7 + 0.371 * (height_m - 1.75) + 0.227 * (f - 1.79) * height_m / 1.75;
      return std::clamp(s * frequency_scale * l, min_length_m, max_length_m);
    }
    case StepLengthKind::kHeight:
    default:
      return s * c1 * height_m;
  }
}

}  // namespace pdnav::pdr
