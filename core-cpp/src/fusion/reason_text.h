// Numbers in the fusion's reason strings (internal to fusion/): fixed-point, `prec` decimals.
#pragma once
#include <sstream>
#include <string>

namespace pdnav::fusion::detail {

inline std::string fmt(double v, int prec = 1) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(prec);
  s << v;
  return s.str();
}

}  // namespace pdnav::fusion::detail
