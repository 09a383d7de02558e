#include "pdnav/geo/frames.h"

#include <cmath>

namespace pdnav::geo {

Geodetic Geodetic::from_deg(double lat_deg, double lon_deg, double h_m) {
  constexpr double k = 3.14159265358979323846 / 180.0;
  return Geodetic{lat_deg * k, lon_deg * k, h_m};
}
double Geodetic::lat_deg() const { return lat_rad * 180.0 / 3.14159265358979323846; }
double Geodetic::lon_deg() const { return lon_rad * 180.0 / 3.14159265358979323846; }

Ecef to_ecef(const Geodetic& g) {
  const double s = std::sin(g.lat_rad), c = std::cos(g.lat_rad);
  const double n = Wgs84::a_m / std::sqrt(1.0 - Wgs84::e2 * s * s);
  return Ecef((n + g.h_m) * c * std::cos(g.lon_rad), (n + g.h_m) * c * std::sin(g.lon_rad),
              (n * (1.0 - Wgs84::e2) + g.h_m) * s);
}

// Vermeille (2002) closed form; exact to < 1 nm for terrestrial and orbital points, and
// well defined at the poles (p = 0) and the centre of the Earth is excluded by callers.
Geodetic to_geodetic(const Ecef& x) {
  const double a = Wgs84::a_m, e2 = Wgs84::e2;
  const double X = x.p_m.x(), Y = x.p_m.y(), Z = x.p_m.z();
  const double p2 = X * X + Y * Y;
  const double p = std::sqrt(p2);
  if (p < 1e-9) {  // on the polar axis
    const double lat = Z >= 0 ? 3.14159265358979323846 / 2 : -3.14159265358979323846 / 2;
    return Geodetic{lat, 0.0, std::abs(Z) - Wgs84::b_m};
  }
  const double e4 = e2 * e2;
  const double pp = p2 / (a * a);
  const double q = (1.0 - e2) / (a * a) * Z * Z;
  const double r = (pp + q - e4) / 6.0;
  const double s = e4 * pp * q / (4.0 * r * r * r);
  const double t = std::cbrt(1.0 + s + std::sqrt(s * (2.0 + s)));
  const double u = r * (1.0 + t + 1.0 / t);
  const double v = std::sqrt(u * u + e4 * q);
  const double w = e2 * (u + v - q) / (2.0 * v);
  const double k = std::sqrt(u + v + w * w) - w;
  const double d = k * p / (k + e2);
  const double lat = 2.0 * std::atan2(Z, d + std::sqrt(d * d + Z * Z));
  const double h = (k + e2 - 1.0) / k * std::sqrt(d * d + Z * Z);
  return Geodetic{lat, std::atan2(Y, X), h};
}

Eigen::Matrix3d ecef_to_enu_rotation(const Geodetic& o) {
  const double sl = std::sin(o.lat_rad), cl = std::cos(o.lat_rad);
  const double so = std::sin(o.lon_rad), co = std::cos(o.lon_rad);
  Eigen::Matrix3d r;
  r << -so, co, 0.0,
       -sl * co, -sl * so, cl,
        cl * co, cl * so, sl;
  return r;
}

LocalFrame::LocalFrame(const Geodetic& origin)
    : origin_(origin), origin_ecef_(geo::to_ecef(origin)), r_ecef_to_enu_(ecef_to_enu_rotation(origin)) {}

Enu LocalFrame::to_enu(const Ecef& x) const { return Enu(r_ecef_to_enu_ * (x.p_m - origin_ecef_.p_m)); }
Enu LocalFrame::to_enu(const Geodetic& g) const { return to_enu(geo::to_ecef(g)); }
Ecef LocalFrame::to_ecef(const Enu& e) const { return Ecef(origin_ecef_.p_m + r_ecef_to_enu_.transpose() * e.p_m); }
Geodetic LocalFrame::to_geodetic(const Enu& e) const { return geo::to_geodetic(to_ecef(e)); }
Eigen::Matrix3d LocalFrame::cov_to_enu(const Eigen::Matrix3d& c) const {
  return r_ecef_to_enu_ * c * r_ecef_to_enu_.transpose();
}

double horizontal_distance_m(const Geodetic& a, const Geodetic& b) {
  const Enu e = LocalFrame(a).to_enu(b);
  return std::hypot(e.e_m(), e.n_m());
}

}  // namespace pdnav::geo
