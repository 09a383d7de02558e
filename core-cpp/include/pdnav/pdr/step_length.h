// Step length models. The default is APT's (Zhu/Li/Chen 2013, Sec. V-A): l = c1 * height with
// c1 = 0.415 (male) / 0.413 (female); the option is Weinberg's (Analog Devices AN-602, 2002):
// l = K * (a_max - a_min)^(1/4) over the step; or the step-frequency model of Tian, Salcic,
// Wang, Pan, "A multi-mode dead reckoning system for pedestrian tracking using smartphones",
// IEEE Sensors J. 16(7), 2016, Eq. 9: l = 0.7 + 0.371 (h - 1.75) + 0.227 (f - 1.79) h / 1.75.
// Every model's output is multiplied by `scale` (1 by default): the per-walker constant that
// fusion learns online (Pdr::set_length_scale).
#pragma once

namespace pdnav::pdr {

enum class StepLengthKind {
  kHeight,    // APT: l = c1 * height
  kWeinberg,  // Weinberg: l = K * swing^(1/4), swing = max - min of |a| in the step (m/s^2)
  kConstant,  // a fixed length (e.g. calibrated by the user)
  kFrequency, // Tian et al. 2016: l = 0.7 + 0.371 (h - 1.75) + 0.227 (f - 1.79) h / 1.75
};

struct StepLengthModel {
  StepLengthKind kind = StepLengthKind::kHeight;
  double height_m = 1.75;         // user height (APT's model input)
  double c1 = 0.415;              // APT Sec. V-A: 0.415 male, 0.413 female
  double weinberg_k = 0.36;       // Weinberg K for |a| in m/s^2 (per-user calibration advised)
  double constant_m = 0.72;       // kConstant length
  double frequency_scale = 1.0;   // kFrequency: multiplies Tian's length (1 = the paper)
  double scale = 1.0;             // any model: learned walker scale (1 = the model as published)
  double sigma_fraction = 0.10;   // 1-sigma of the length as a fraction of it
  double min_length_m = 0.2;      // clamp for the acceleration-based model
  double max_length_m = 1.2;

  static StepLengthModel apt_male(double height_m);
  static StepLengthModel apt_female(double height_m);
  static StepLengthModel weinberg(double k);
  /// The default when the walker is unknown (no height): Weinberg with K = 0.428, the constant
  /// that gives the surveyed path length on the hand-held ILC 2020 walks (site2 median length
  /// ratio 1.012, checked on site1; docs/pdr.md) with the step detector's swing (its low-pass,
  /// StepDetectorOptions::lowpass_hz). Adapts with the step's vertical swing.
  static StepLengthModel unknown_walker();

  /// Length of one step; swing_mps2 is used by kWeinberg, step_frequency_hz (1 / the step's
  /// interval) by kFrequency. Never NaN: a non-finite input falls back to the height model.
  double length_m(double swing_mps2, double step_frequency_hz = 0.0) const;
  double sigma_m(double length) const { return sigma_fraction * length; }
};

}  // namespace pdnav::pdr
