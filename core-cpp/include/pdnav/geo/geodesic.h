// Geodesics on the WGS84 ellipsoid: the inverse problem (distance and initial bearing between
// two points), Karney, "Algorithms for geodesics", J. Geodesy 87 (2013) 43-55, through
// GeographicLib (accurate to ~15 nm everywhere, antipodal points included).
#pragma once

namespace pdnav::geo {

struct GeodesicInverse {
  double distance_m = 0.0;            // along the ellipsoid's geodesic
  double initial_bearing_rad = 0.0;   // at the first point, clockwise from true north, [0, 2pi)
};

/// Distance and initial bearing from (lat1, lon1) to (lat2, lon2), degrees (WGS84).
/// Throws std::invalid_argument for non-finite input or |lat| > 90.
GeodesicInverse geodesic_inverse(double lat1_deg, double lon1_deg, double lat2_deg, double lon2_deg);

}  // namespace pdnav::geo
