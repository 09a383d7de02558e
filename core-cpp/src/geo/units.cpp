#include "pdnav/geo/units.h"

#include <cmath>

namespace pdnav {

double wrap_pi(double angle_rad) {
  double a = std::remainder(angle_rad, 2.0 * kPi);  // [-pi, pi]
  if (a <= -kPi) a += 2.0 * kPi;
  return a;
}

double wrap_two_pi(double angle_rad) {
  double a = std::fmod(angle_rad, 2.0 * kPi);
  if (a < 0.0) a += 2.0 * kPi;
  if (a >= 2.0 * kPi) a = 0.0;
  return a;
}

}  // namespace pdnav
