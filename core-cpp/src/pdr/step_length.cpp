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

double StepLengthModel::length_m(double swing_mps2) const {
  switch (kind) {
    case StepLengthKind::kConstant:
      return constant_m;
    case StepLengthKind::kWeinberg:
      if (std::isfinite(swing_mps2) && swing_mps2 > 0.0) {
        return std::clamp(weinberg_k * std::pow(swing_mps2, 0.25), min_length_m, max_length_m);
      }
      return c1 * height_m;
    case StepLengthKind::kHeight:
    default:
      return c1 * height_m;
  }
}

}  // namespace pdnav::pdr
