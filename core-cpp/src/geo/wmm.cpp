// World Magnetic Model evaluation (WMM2025 Technical Report, Sec. 1.2, eq. 7-19).
#include "pdnav/geo/wmm.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pdnav::geo {
namespace detail {
extern const WmmCoefficient kWmm2025Coefficients[];
extern const std::size_t kWmm2025CoefficientCount;
extern const WmmCoefficient kWmm2020Coefficients[];
extern const std::size_t kWmm2020CoefficientCount;
extern const WmmCoefficient kWmm2015v2Coefficients[];
extern const std::size_t kWmm2015v2CoefficientCount;
}  // namespace detail

namespace {

constexpr double kGeomagneticRadiusKm = 6371.2;  // WMM reference radius a (eq. 10)

[[noreturn]] void fail(const std::string& name, int line, const std::string& reason) {
  throw std::runtime_error(name + ":" + std::to_string(line) + ": " + reason);
}

/// Index of (n, m) in a triangular table with n in [0, n_max], m in [0, n].
int tri(int n, int m) { return n * (n + 1) / 2 + m; }

/// Schmidt semi-normalised associated Legendre functions P_n^m(sin phi') and their
/// derivatives with respect to the geocentric latitude phi' (Technical Report eq. 10-11).
void legendre(int n_max, double sin_lat, double cos_lat, std::vector<double>& p,
              std::vector<double>& dp) {
  const auto size = static_cast<std::size_t>(tri(n_max + 1, 0));
  p.assign(size, 0.0);
  dp.assign(size, 0.0);
  // Unnormalised functions without the Condon-Shortley phase, then Schmidt factors.
  p[0] = 1.0;
  for (int n = 1; n <= n_max; ++n) {
    p[tri(n, n)] = (2.0 * n - 1.0) * cos_lat * p[tri(n - 1, n - 1)];
    for (int m = 0; m < n; ++m) {
      const double pn2 = (n - 2 >= m) ? p[tri(n - 2, m)] : 0.0;
      p[tri(n, m)] = ((2.0 * n - 1.0) * sin_lat * p[tri(n - 1, m)] - (n + m - 1.0) * pn2) / (n - m);
    }
  }
  for (int n = 1; n <= n_max; ++n) {
    for (int m = 0; m <= n; ++m) {
      const double pn1 = (n - 1 >= m) ? p[tri(n - 1, m)] : 0.0;
      // (1 - x^2) dP/dx = (n + m) P_{n-1}^m - n x P_n^m, and d/dphi' = cos(phi') d/dx.
      dp[tri(n, m)] = ((n + m) * pn1 - n * sin_lat * p[tri(n, m)]) / cos_lat;
    }
  }
  for (int n = 1; n <= n_max; ++n) {
    double ratio = 1.0;  // (n-m)!/(n+m)!
    for (int m = 1; m <= n; ++m) {
      ratio /= static_cast<double>((n + m) * (n - m + 1));
      const double schmidt = std::sqrt(2.0 * ratio);
      p[tri(n, m)] *= schmidt;
      dp[tri(n, m)] *= schmidt;
    }
  }
}

struct Spherical {
  double lat_rad;  // geocentric latitude phi'
  double r_km;
};

/// Geodetic -> geocentric spherical (Technical Report eq. 7-8), WGS84 ellipsoid.
Spherical to_spherical(const Geodetic& g) {
  const double a_km = Wgs84::a_m / 1000.0;
  const double h_km = g.h_m / 1000.0;
  const double s = std::sin(g.lat_rad);
  const double rc = a_km / std::sqrt(1.0 - Wgs84::e2 * s * s);
  const double p = (rc + h_km) * std::cos(g.lat_rad);
  const double z = (rc * (1.0 - Wgs84::e2) + h_km) * s;
  return {std::atan2(z, p), std::hypot(p, z)};
}

bool is_terminator(const std::string& line) {
  return line.size() >= 4 && line.compare(0, 4, "9999") == 0;
}

}  // namespace

namespace {
WmmModel embedded_model(double epoch, const char* name, const char* release, const WmmCoefficient* c,
                        std::size_t n) {
  WmmModel m;
  m.epoch_year = epoch;
  m.name = name;
  m.release_date = release;
  m.coefficients.assign(c, c + n);
  for (const auto& k : m.coefficients) m.n_max = std::max(m.n_max, k.n);
  return m;
}
}  // namespace

const WmmModel& WmmModel::wmm2025() {
  static const WmmModel model = embedded_model(2025.0, "WMM-2025", "11/13/2024", detail::kWmm2025Coefficients,
                                               detail::kWmm2025CoefficientCount);
  return model;
}

const WmmModel& WmmModel::wmm2020() {
  static const WmmModel model = embedded_model(2020.0, "WMM-2020", "12/10/2019", detail::kWmm2020Coefficients,
                                               detail::kWmm2020CoefficientCount);
  return model;
}

const WmmModel& WmmModel::wmm2015() {
  static const WmmModel model = embedded_model(2015.0, "WMM-2015v2", "09/18/2018", detail::kWmm2015v2Coefficients,
                                               detail::kWmm2015v2CoefficientCount);
  return model;
}

std::vector<const WmmModel*> WmmModel::embedded() { return {&wmm2015(), &wmm2020(), &wmm2025()}; }

WmmModel WmmModel::parse_cof(std::istream& in, const std::string& name) {
  WmmModel model;
  std::string line;
  int line_no = 0;
  bool have_header = false;
  bool terminated = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (is_terminator(line.substr(line.find_first_not_of(" \t")))) {
      terminated = true;
      break;
    }
    std::istringstream ls(line);
    if (!have_header) {
      if (!(ls >> model.epoch_year >> model.name)) fail(name, line_no, "bad header, want 'epoch name date'");
      ls >> model.release_date;
      have_header = true;
      continue;
    }
    WmmCoefficient c;
    if (!(ls >> c.n >> c.m >> c.g_nt >> c.h_nt >> c.g_dot_ntpyr >> c.h_dot_ntpyr)) {
      fail(name, line_no, "bad coefficient line, want 'n m g h g_dot h_dot'");
    }
    if (c.n < 1 || c.m < 0 || c.m > c.n || c.n > 1000) fail(name, line_no, "degree/order out of range");
    model.n_max = std::max(model.n_max, c.n);
    model.coefficients.push_back(c);
  }
  if (!have_header) fail(name, line_no, "empty coefficient file");
  if (model.coefficients.empty()) fail(name, line_no, "no coefficients");
  if (!terminated) fail(name, line_no, "missing '9999...' terminator line (truncated file?)");
  return model;
}

WmmModel WmmModel::load_cof(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path, 0, "cannot open coefficient file");
  return parse_cof(in, path);
}

MagneticField wmm_field(const WmmModel& model, const Geodetic& where, double decimal_year) {
  constexpr double kPoleGuard = 1e-9;
  Geodetic g = where;
  g.lat_rad = std::clamp(g.lat_rad, -kPi / 2 + kPoleGuard, kPi / 2 - kPoleGuard);
  const Spherical sph = to_spherical(g);
  const double sin_lat = std::sin(sph.lat_rad);
  const double cos_lat = std::cos(sph.lat_rad);
  std::vector<double> p, dp;
  legendre(model.n_max, sin_lat, cos_lat, p, dp);

  const double dt = decimal_year - model.epoch_year;
  const double ratio = kGeomagneticRadiusKm / sph.r_km;
  double x = 0.0, y = 0.0, z = 0.0;  // geocentric north, east, down (eq. 10-11)
  for (const auto& c : model.coefficients) {
    const double gnm = c.g_nt + dt * c.g_dot_ntpyr;  // eq. 9
    const double hnm = c.h_nt + dt * c.h_dot_ntpyr;
    const double ml = c.m * g.lon_rad;
    const double cos_ml = std::cos(ml), sin_ml = std::sin(ml);
    const double scale = std::pow(ratio, c.n + 2);
    const int k = tri(c.n, c.m);
    x -= scale * (gnm * cos_ml + hnm * sin_ml) * dp[k];
    y += scale * c.m * (gnm * sin_ml - hnm * cos_ml) * p[k] / cos_lat;
    z -= scale * (c.n + 1) * (gnm * cos_ml + hnm * sin_ml) * p[k];
  }
  // Rotate from geocentric to geodetic components (eq. 17).
  const double psi = sph.lat_rad - g.lat_rad;
  MagneticField f;
  f.x_nt = x * std::cos(psi) - z * std::sin(psi);
  f.y_nt = y;
  f.z_nt = x * std::sin(psi) + z * std::cos(psi);
  f.h_nt = std::hypot(f.x_nt, f.y_nt);
  f.f_nt = std::hypot(f.h_nt, f.z_nt);
  f.declination_rad = std::atan2(f.y_nt, f.x_nt);
  f.inclination_rad = std::atan2(f.z_nt, f.h_nt);
  return f;
}

namespace {
/// Days from 1970-01-01 to year-01-01 of the proleptic Gregorian calendar.
std::int64_t days_to_year_start(std::int64_t year) {
  const std::int64_t y = year - 1;
  const auto leap_days = [](std::int64_t yy) { return yy / 4 - yy / 100 + yy / 400; };
  return (year - 1970) * 365 + (leap_days(y) - leap_days(1969));
}
bool is_leap(std::int64_t y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }
}  // namespace

double decimal_year_from_unix_ms(std::int64_t unix_ms) {
  constexpr std::int64_t kMsPerDay = 86'400'000;
  const std::int64_t days = unix_ms >= 0 ? unix_ms / kMsPerDay : -((-unix_ms + kMsPerDay - 1) / kMsPerDay);
  std::int64_t year = 1970 + days / 365;
  while (days_to_year_start(year) > days) --year;
  while (days_to_year_start(year + 1) <= days) ++year;
  const double start_ms = static_cast<double>(days_to_year_start(year)) * kMsPerDay;
  const double len_ms = (is_leap(year) ? 366.0 : 365.0) * kMsPerDay;
  return static_cast<double>(year) + (static_cast<double>(unix_ms) - start_ms) / len_ms;
}

Declination declination_at(const Geodetic& where, std::int64_t unix_ms) {
  const auto models = WmmModel::embedded();
  Declination d;
  const WmmModel* model = models.back();
  if (unix_ms == std::numeric_limits<std::int64_t>::min()) {
    d.decimal_year = model->epoch_year;
    d.warning = "no UTC time in the log: declination from " + model->name + " at its epoch";
  } else {
    d.decimal_year = decimal_year_from_unix_ms(unix_ms);
    const double y = d.decimal_year;
    bool inside = false;
    for (const WmmModel* m : models) {
      if (y >= m->epoch_year && y < m->epoch_year + kWmmValidityYears) {
        model = m;
        inside = true;
      }
    }
    if (!inside) {
      // Nearest span: the oldest model before its epoch, the newest after its end.
      model = y < models.front()->epoch_year ? models.front() : models.back();
      d.extrapolated = true;
      const double years_out = y < model->epoch_year ? model->epoch_year - y : y - (model->epoch_year + kWmmValidityYears);
      char buf[160];
      std::snprintf(buf, sizeof buf, "date %.2f is %.1f years outside every WMM span (%.0f-%.0f): %s extrapolated",
                    y, years_out, models.front()->epoch_year, models.back()->epoch_year + kWmmValidityYears,
                    model->name.c_str());
      d.warning = buf;
    }
  }
  d.model = model->name;
  d.declination_rad = wmm_field(*model, where, d.decimal_year).declination_rad;
  return d;
}

double magnetic_declination_rad(const Geodetic& where, std::int64_t unix_ms) {
  return declination_at(where, unix_ms).declination_rad;
}

}  // namespace pdnav::geo
