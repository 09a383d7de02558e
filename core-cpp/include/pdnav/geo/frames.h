// Typed coordinate frames: WGS84 geodetic, ECEF, and local ENU tangent frames.
// A frame is a type, never a flag. Conversions follow NIMA TR8350.2 (WGS84) and
// the closed-form ECEF->geodetic of Vermeille (J. Geodesy 2002).
#pragma once
#include <Eigen/Core>

namespace pdnav::geo {

struct Wgs84 {
  static constexpr double a_m = 6378137.0;                  // semi-major axis
  static constexpr double f = 1.0 / 298.257223563;          // flattening
  static constexpr double b_m = a_m * (1.0 - f);            // semi-minor axis
  static constexpr double e2 = f * (2.0 - f);               // first eccentricity squared
  static constexpr double omega_e_radps = 7.2921151467e-5;  // Earth rotation rate
  static constexpr double gm_m3ps2 = 3.986005e14;           // GPS value, IS-GPS-200
};

/// Geodetic position: latitude/longitude in radians, height above the WGS84 ellipsoid.
struct Geodetic {
  double lat_rad = 0.0;
  double lon_rad = 0.0;
  double h_m = 0.0;
  static Geodetic from_deg(double lat_deg, double lon_deg, double h_m);
  double lat_deg() const;
  double lon_deg() const;
};

/// Earth-centred, Earth-fixed Cartesian position (WGS84).
struct Ecef {
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();
  Ecef() = default;
  explicit Ecef(const Eigen::Vector3d& p) : p_m(p) {}
  Ecef(double x_m, double y_m, double z_m) : p_m(x_m, y_m, z_m) {}
};

/// Local east/north/up position relative to a LocalFrame origin.
struct Enu {
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();
  Enu() = default;
  explicit Enu(const Eigen::Vector3d& p) : p_m(p) {}
  Enu(double e_m, double n_m, double u_m) : p_m(e_m, n_m, u_m) {}
  double e_m() const { return p_m.x(); }
  double n_m() const { return p_m.y(); }
  double u_m() const { return p_m.z(); }
};

Ecef to_ecef(const Geodetic& g);
Geodetic to_geodetic(const Ecef& x);

/// Rotation matrix taking ECEF vectors into ENU at the given geodetic position.
Eigen::Matrix3d ecef_to_enu_rotation(const Geodetic& origin);

/// A local tangent (ENU) frame anchored at a geodetic origin. All engines work in one.
class LocalFrame {
 public:
  LocalFrame() = default;
  explicit LocalFrame(const Geodetic& origin);
  const Geodetic& origin() const { return origin_; }
  Enu to_enu(const Ecef& x) const;
  Enu to_enu(const Geodetic& g) const;
  Ecef to_ecef(const Enu& e) const;
  Geodetic to_geodetic(const Enu& e) const;
  /// ECEF vector (e.g. velocity, displacement) into ENU components.
  Eigen::Vector3d rotate_to_enu(const Eigen::Vector3d& v_ecef) const { return r_ecef_to_enu_ * v_ecef; }
  Eigen::Vector3d rotate_to_ecef(const Eigen::Vector3d& v_enu) const { return r_ecef_to_enu_.transpose() * v_enu; }
  /// Covariance (3x3) from ECEF into ENU.
  Eigen::Matrix3d cov_to_enu(const Eigen::Matrix3d& cov_ecef) const;

 private:
  Geodetic origin_;
  Ecef origin_ecef_;
  Eigen::Matrix3d r_ecef_to_enu_ = Eigen::Matrix3d::Identity();
};

/// Great-circle-free local distance helper: horizontal distance between two geodetic
/// points through the ENU frame of the first (accurate to mm over tens of km).
double horizontal_distance_m(const Geodetic& a, const Geodetic& b);

}  // namespace pdnav::geo
