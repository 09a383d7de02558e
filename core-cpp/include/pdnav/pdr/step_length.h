// Step length models. The default is APT's (Zhu/Li/Chen 2013, Sec. V-A): l = c1 * height with
// c1 = 0.415 (male) / 0.413 (female); the option is Weinberg's (Analog Devices AN-602, 2002):
// l = K * (a_max - a_min)^(1/4) over the step.
#pragma once

namespace pdnav::pdr {

enum class StepLengthKind {
  kHeight,    // APT: l = c1 * height
  kWeinberg,  // Weinberg: l = K * swing^(1/4), swing = max - min of |a| in the step (m/s^2)
  kConstant,  // a fixed length (e.g. calibrated by the user)
};

struct StepLengthModel {
  StepLengthKind kind = StepLengthKind::kHeight;
  double height_m = 1.75;         // user height (APT's model input)
  double c1 = 0.415;              // APT Sec. V-A: 0.415 male, 0.413 female
  double weinberg_k = 0.36;       // Weinberg K for |a| in m/s^2 (per-user calibration advised)
  double constant_m = 0.72;       // kConstant length
  double sigma_fraction = 0.10;   // 1-sigma of the length as a fraction of it
  double min_length_m = 0.2;      // clamp for the acceleration-based model
  double max_length_m = 1.2;

  static StepLengthModel apt_male(double height_m);
  static StepLengthModel apt_female(double height_m);
  static StepLengthModel weinberg(double k);

  /// Length of one step; swing_mps2 is used by kWeinberg only. Never NaN: a non-finite
  /// swing falls back to the height model.
  double length_m(double swing_mps2) const;
  double sigma_m(double length) const { return sigma_fraction * length; }
};

}  // namespace pdnav::pdr
