#include "pdnav/geo/geodesic.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <GeographicLib/Geodesic.hpp>

#include "pdnav/geo/units.h"

namespace pdnav::geo {

GeodesicInverse geodesic_inverse(double lat1_deg, double lon1_deg, double lat2_deg, double lon2_deg) {
  for (double v : {lat1_deg, lon1_deg, lat2_deg, lon2_deg}) {
    if (!std::isfinite(v)) throw std::invalid_argument("geodesic_inverse: non-finite coordinate");
  }
  if (std::fabs(lat1_deg) > 90.0 || std::fabs(lat2_deg) > 90.0) {
    throw std::invalid_argument("geodesic_inverse: |latitude| > 90 deg (" + std::to_string(lat1_deg) +
                                ", " + std::to_string(lat2_deg) + ")");
  }
  double s12_m = 0.0, azi1_deg = 0.0, azi2_deg = 0.0;
  GeographicLib::Geodesic::WGS84().Inverse(lat1_deg, lon1_deg, lat2_deg, lon2_deg, s12_m, azi1_deg, azi2_deg);
  double b = deg_to_rad(azi1_deg);
  if (b < 0.0) b += 2.0 * kPi;
  if (b >= 2.0 * kPi) b -= 2.0 * kPi;
  return GeodesicInverse{s12_m, b};
}

}  // namespace pdnav::geo
