// Phone-session simulator (docs/simulator.md).
#include "pdnav/phonesim/phone_session.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>

#include "pdnav/geo/frames.h"
#include "pdnav/geo/time.h"
#include "pdnav/geo/wmm.h"
#include "pdnav/sim/world.h"
#include "pdnav/gnss/atmosphere.h"
#include "pdnav/gnss/measurements.h"
#include "pdnav/gnss/solver_synthetic.h"

namespace pdnav::phonesim {
namespace {

using sim::gauss;
using sim::Rng;
using sim::uniform;

constexpr double kGravity = 9.80665;
constexpr double kGeoidUndulationM = 50.0;  // EGM96 over the Pyrenees (~50 m): DEM heights are orthometric
constexpr TimeNs kT0Ns = 10 * kNsPerS;       // first sample, elapsedRealtimeNanos

// ------------------------------------------------------------------ path on the graph
struct Path {
  std::vector<Eigen::Vector2d> pts;    // DEM frame
  std::vector<double> s;               // cumulative distance
  std::vector<bool> urban;             // of the piece starting at pts[k]
  double length() const { return s.empty() ? 0.0 : s.back(); }
  // Point at distance d and the piece index.
  Eigen::Vector2d at(double d, std::size_t* piece = nullptr) const {
    d = std::clamp(d, 0.0, length());
    const auto it = std::upper_bound(s.begin(), s.end(), d);
    std::size_t k = it == s.begin() ? 0 : static_cast<std::size_t>(it - s.begin() - 1);
    if (k + 1 >= pts.size()) k = pts.size() - 2;
    if (piece) *piece = k;
    const double len = s[k + 1] - s[k];
    const double f = len > 0 ? (d - s[k]) / len : 0.0;
    return pts[k] + f * (pts[k + 1] - pts[k]);
  }
};

bool urban_class(const std::string& h) {
  static const char* kUrban[] = {"residential", "service", "living_street", "pedestrian", "primary", "secondary",
                                 "tertiary", "unclassified", "trunk", "steps", "footway", "sidewalk", "cycleway"};
  for (const char* u : kUrban)
    if (h == u) return true;
  return false;
}

bool inside(const terrain::Dem& dem, const Eigen::Vector2d& p, double margin) {
  return p.x() > dem.min_e_m() + margin && p.x() < dem.max_e_m() - margin && p.y() > dem.min_n_m() + margin &&
         p.y() < dem.max_n_m() - margin && dem.at_local(p.x(), p.y()).valid();
}

Path random_path(const terrain::Dem& dem, const route::WalkGraph& g, double target_m, double margin, Rng& rng) {
  if (g.segment_count() == 0) throw std::runtime_error("simulate-session: empty walkway graph");
  std::vector<Eigen::Vector2d> node_dem(g.node_count());
  for (std::size_t i = 0; i < g.node_count(); ++i) {
    const Eigen::Vector2d& p = g.node_en_m(static_cast<std::int32_t>(i));
    node_dem[i] = dem.to_local(g.frame().to_geodetic(geo::Enu(p.x(), p.y(), 0.0)));
  }
  std::uniform_int_distribution<std::size_t> pick(0, g.segment_count() - 1);
  for (int attempt = 0; attempt < 500; ++attempt) {
    auto seg = static_cast<std::int32_t>(pick(rng));
    if (!inside(dem, node_dem[g.segment(seg).from], margin)) continue;
    Path p;
    p.pts.push_back(node_dem[g.segment(seg).from]);
    p.s.push_back(0.0);
    std::map<std::int32_t, int> visits;
    bool ok = true;
    while (p.length() < target_m) {
      const auto& sg = g.segment(seg);
      const Eigen::Vector2d b = node_dem[sg.to];
      if (!inside(dem, b, margin)) { ok = false; break; }
      p.urban.push_back(urban_class(g.edge(sg.edge).highway));
      p.s.push_back(p.length() + (b - p.pts.back()).norm());
      p.pts.push_back(b);
      ++visits[seg / 2];
      std::vector<std::int32_t> next;
      for (const auto o : g.out_segments(sg.to))
        if (o != route::WalkGraph::reverse(seg)) next.push_back(o);
      if (next.empty()) next.push_back(route::WalkGraph::reverse(seg));  // dead end: walk back
      // Prefer pieces walked fewer times (a hiker does not circle one block forever).
      std::vector<double> w;
      for (const auto o : next) w.push_back(1.0 / (1.0 + 4.0 * visits[o / 2]));
      seg = next[std::discrete_distribution<std::size_t>(w.begin(), w.end())(rng)];
      if (p.pts.size() > 200000) { ok = false; break; }
    }
    if (ok && p.length() >= target_m) {
      p.urban.push_back(p.urban.empty() ? false : p.urban.back());
      return p;
    }
  }
  throw std::runtime_error("simulate-session: no walk of " + std::to_string(static_cast<int>(target_m)) +
                           " m found on the graph inside the DEM tile (edge margin " +
                           std::to_string(static_cast<int>(margin)) + " m)");
}

// ------------------------------------------------------------------ helpers
double slope_deg(const terrain::Dem& dem, double e, double n) {
  const double d = 30.0;
  const double hx1 = dem.at_local(e + d, n).elevation_m, hx0 = dem.at_local(e - d, n).elevation_m;
  const double hy1 = dem.at_local(e, n + d).elevation_m, hy0 = dem.at_local(e, n - d).elevation_m;
  const double gx = (hx1 - hx0) / (2 * d), gy = (hy1 - hy0) / (2 * d);
  if (!std::isfinite(gx) || !std::isfinite(gy)) return 0.0;
  return std::atan(std::hypot(gx, gy)) * kRadToDeg;
}

/// Terrain horizon elevation (rad) seen from (e, n, h) towards azimuth az (DEM ray march).
double horizon_rad(const terrain::Dem& dem, double e, double n, double h, double az) {
  double best = -kPi / 2;
  const double se = std::sin(az), ce = std::cos(az);
  for (double d = 30.0; d < 8000.0; d *= 1.12) {
    const terrain::DemSample s = dem.at_local(e + d * se, n + d * ce);
    if (!s.valid()) break;
    const double drop = d * d / (2.0 * 6371e3);
    best = std::max(best, std::atan2(s.elevation_m - drop - h, d));
  }
  return best;
}

RotationVectorSample rotation_for_heading(TimeNs t_ns, std::int64_t utc_ms, double magnetic_heading_rad) {
  RotationVectorSample out;
  out.t_ns = t_ns;
  out.utc_ms = utc_ms;
  out.quat_xyzw = sim::chest_mount_quat_xyzw(magnetic_heading_rad);
  out.heading_accuracy_rad = 10.0 * kDegToRad;
  return out;
}

MetaSample meta(const std::string& key, const std::string& value) { return {0, key, value}; }

std::string num(double v, int digits = 12) {
  std::ostringstream os;
  os.precision(digits);
  os << v;
  return os.str();
}

/// GPS time span of the nav data: hours (GPS ns, whole hours) at which >= 6 satellites have a
/// usable broadcast ephemeris.
std::vector<TimeNs> usable_hours(const gnss::EphemerisStore& eph) {
  std::vector<TimeNs> out;
  const std::vector<gnss::SatId> sats = eph.satellites();
  if (sats.empty()) return out;
  // Coarse search for any usable time (4 h steps over 1999-2040), then hours around it.
  const TimeNs kHour = 3600 * kNsPerS;
  const TimeNs begin = 19LL * 52 * geo::kNsPerWeek, end = 62LL * 52 * geo::kNsPerWeek;
  std::vector<TimeNs> coarse;
  for (TimeNs t = begin; t < end; t += 4 * kHour)
    for (std::size_t k = 0; k < sats.size(); k += std::max<std::size_t>(1, sats.size() / 4))
      if (eph.state(sats[k], t)) { coarse.push_back(t); break; }
  for (const TimeNs c : coarse)
    for (TimeNs t = c - 4 * kHour; t <= c + 4 * kHour; t += kHour) {
      int n = 0;
      for (const auto& s : sats)
        if (s.sys == gnss::Constellation::kGps || s.sys == gnss::Constellation::kGalileo) n += eph.state(s, t) ? 1 : 0;
      if (n >= 20 && (out.empty() || out.back() < t)) out.push_back(t);
    }
  return out;
}

// ------------------------------------------------------------------ GNSS channel state
struct Channel {
  bool tracked = false;
  double lock_start_s = -1.0;
  double reacquire_at_s = -1.0;
  double adr_offset_m = 0.0;      // integer ambiguity and arbitrary start
  double orbit_err_m = 0.0;
  double mp_f1 = 0, mp_f2 = 0, mp_p1 = 0, mp_p2 = 0;
  double nlos_m = 0.0, nlos_until_s = -1.0;
};

/// Slant delay (m) of a horizontal gradient g (east, north; m of vertical delay per km) of the
/// vertical ionospheric delay, evaluated at the pierce point of a satellite at (az, el), with the
/// broadcast model's pierce-point angle and obliquity (gnss::klobuchar_pierce_point).
double iono_gradient_slant_m(const Eigen::Vector2d& g_m_per_km, double az_rad, double el_rad) {
  const gnss::PiercePoint ipp = gnss::klobuchar_pierce_point(el_rad);
  const double d_km = std::max(0.0, ipp.earth_angle_sc) * kPi * 6371.0;
  return ipp.obliquity * d_km * (g_m_per_km.x() * std::sin(az_rad) + g_m_per_km.y() * std::cos(az_rad));
}

}  // namespace

std::int64_t session_unix_ms(const PhoneSession& s, TimeNs t_ns) {
  return geo::gps_ns_to_unix_ms(s.gps_start_ns + (t_ns - kT0Ns));
}

PhoneSession simulate_session(const terrain::Dem& dem, const route::WalkGraph& graph, const gnss::EphemerisStore& eph,
                              const SessionOptions& o, std::uint64_t seed) {
  if (!(o.outage_min_s >= 0 && o.outage_max_s >= o.outage_min_s && o.lead_s > 0 && o.tail_s > 0))
    throw std::invalid_argument("simulate-session: need 0 <= outage-min <= outage-max and positive lead/tail");
  if (!(o.imu_rate_hz > 0 && o.rotation_rate_hz > 0 && o.baro_rate_hz > 0 && o.gnss_rate_hz > 0))
    throw std::invalid_argument("simulate-session: sensor rates must be positive");
  Rng rng(seed);
  PhoneSession ses;
  ses.seed = seed;
  const double outage_s = uniform(rng, o.outage_min_s, o.outage_max_s + 1e-9);
  const double total_s = o.lead_s + outage_s + o.tail_s;

  // GPS start time: a random hour of the nav files' day, whole seconds.
  const std::vector<TimeNs> hours = usable_hours(eph);
  if (hours.empty())
    throw std::runtime_error("simulate-session: the navigation files give no time with >= 20 usable GPS/Galileo "
                             "ephemerides (need a whole-day broadcast file, e.g. hour1180.21n)");
  {
    std::vector<TimeNs> ok;  // the session must end inside the usable span
    for (const TimeNs h : hours)
      // + 1 h: the start is up to 3000 s after the hour.
      if (std::find(hours.begin(), hours.end(), h + static_cast<TimeNs>(std::ceil(total_s / 3600.0) + 1) * 3600 * kNsPerS) != hours.end())
        ok.push_back(h);
    const std::vector<TimeNs>& from = ok.empty() ? hours : ok;
    ses.gps_start_ns = from[std::uniform_int_distribution<std::size_t>(0, from.size() - 1)(rng)] +
                       static_cast<TimeNs>(uniform(rng, 0, 3000)) * kNsPerS;
  }

  const Path path = random_path(dem, graph, 1.35 * 2.0 * total_s + 200.0, o.edge_margin_m, rng);

  // World error processes.
  const double nominal_step_m = 0.415 * o.user_height_m;  // the APT model the PDR applies
  const sim::Stride stride(o.stride, nominal_step_m, rng);
  std::vector<sim::MagneticAnomaly> anomalies;
  {
    std::vector<Eigen::Vector2d> urban_pts, rural_pts;
    for (std::size_t k = 0; k + 1 < path.pts.size(); ++k) {
      auto a = sim::anomalies_along({path.pts[k], path.pts[k + 1]},
                                    path.urban[k] ? o.anomalies_per_km_urban : o.anomalies_per_km_rural, o.heading, rng);
      anomalies.insert(anomalies.end(), a.begin(), a.end());
    }
  }
  sim::HeadingError heading_err(o.heading, anomalies, rng);
  const sim::BaroWorld baro(o.baro, total_s + 60.0, rng);
  const sim::DemError dem_err(
      o.dem_error, dem.min_e_m(), dem.min_n_m(), dem.max_e_m(), dem.max_n_m(),
      [&dem](double e, double n) { return slope_deg(dem, e, n); },
      [&dem](double e, double n) { return dem.at_local(e, n).elevation_m; }, rng);
  auto ground = [&](const Eigen::Vector2d& p) { return dem.at_local(p.x(), p.y()).elevation_m - dem_err.error_m(p.x(), p.y()); };

  // Scripted outage and degraded segments.
  const double out_start = o.lead_s, out_end = o.lead_s + outage_s;
  ses.outage_start_ns = kT0Ns + s_to_ns(out_start);
  ses.outage_end_ns = kT0Ns + s_to_ns(out_end);
  std::vector<sim::Interval> degraded;
  for (int k = 0, tries = 0; k < o.degraded_segments && tries < 200; ++tries) {
    const double dur = uniform(rng, o.degraded_min_s, o.degraded_max_s + 1e-9);
    const double st = uniform(rng, 120.0, std::max(121.0, total_s - dur));
    const bool hits_outage = st < out_end + 20.0 && st + dur > out_start - 20.0;
    bool overlap = hits_outage;
    for (const auto& d : degraded) overlap = overlap || (st < d.end_s && st + dur > d.start_s);
    if (overlap) continue;
    degraded.push_back({st, st + dur});
    ++k;
  }
  for (const auto& d : degraded) ses.degraded.emplace_back(kT0Ns + s_to_ns(d.start_s), kT0Ns + s_to_ns(d.end_s));
  auto in_degraded = [&](double t) {
    for (const auto& d : degraded)
      if (t >= d.start_s && t < d.end_s) return true;
    return false;
  };

  // ---------------------------------------------------------------- steps (truth)
  struct StepT { double t_s; Eigen::Vector2d p; double heading; };
  std::vector<StepT> steps;
  {
    double d = 0.0, t = 2.0;
    Eigen::Vector2d prev = path.at(0.0);
    steps.push_back({t, prev, 0.0});
    std::size_t piece = 0, side_piece = static_cast<std::size_t>(-1);
    double side = 0.0;
    while (t < total_s) {
      const Eigen::Vector2d ahead = path.at(d + 2.0);
      const double grade = (ground(ahead) - ground(path.at(d))) / 2.0;
      const double len = stride.length_m(t, std::isfinite(grade) ? grade : 0.0, rng);
      t += stride.period_s(std::isfinite(grade) ? grade : 0.0, rng);
      d += len;
      if (d >= path.length()) break;
      Eigen::Vector2d p = path.at(d, &piece);
      if (piece != side_piece) side_piece = piece, side = std::clamp(gauss(rng, 0.8), -2.0, 2.0);
      const Eigen::Vector2d dir = (path.pts[piece + 1] - path.pts[piece]).normalized();
      p += side * Eigen::Vector2d(-dir.y(), dir.x());
      const Eigen::Vector2d step = p - prev;
      const double h = step.norm() > 1e-6 ? wrap_two_pi(std::atan2(step.x(), step.y())) : steps.back().heading;
      steps.push_back({t, p, h});
      prev = p;
    }
    if (steps.size() < 10) throw std::runtime_error("simulate-session: walk too short");
    steps[0].heading = steps[1].heading;
  }
  // Truth at any time: linear between steps; unwrapped heading for the gyro.
  std::vector<double> unwrapped(steps.size());
  unwrapped[0] = steps[0].heading;
  for (std::size_t k = 1; k < steps.size(); ++k) unwrapped[k] = unwrapped[k - 1] + wrap_pi(steps[k].heading - steps[k - 1].heading);
  auto locate = [&](double t, std::size_t* k_out, double* f_out) {
    auto it = std::upper_bound(steps.begin(), steps.end(), t, [](double x, const StepT& s) { return x < s.t_s; });
    std::size_t k = it == steps.begin() ? 0 : static_cast<std::size_t>(it - steps.begin() - 1);
    if (k + 1 >= steps.size()) k = steps.size() - 2;
    const double f = std::clamp((t - steps[k].t_s) / (steps[k + 1].t_s - steps[k].t_s), 0.0, 1.0);
    *k_out = k;
    *f_out = f;
  };
  auto pos_at = [&](double t) {
    std::size_t k;
    double f;
    locate(t, &k, &f);
    return Eigen::Vector2d(steps[k].p + f * (steps[k + 1].p - steps[k].p));
  };
  auto vel_at = [&](double t) {
    std::size_t k;
    double f;
    locate(t, &k, &f);
    return Eigen::Vector2d((steps[k + 1].p - steps[k].p) / (steps[k + 1].t_s - steps[k].t_s));
  };
  // Heading turns between the step headings over the step's second half (body rotation).
  auto heading_at = [&](double t) {
    std::size_t k;
    double f;
    locate(t, &k, &f);
    const double w = std::clamp((f - 0.5) * 2.0, 0.0, 1.0);
    return unwrapped[k] + w * (unwrapped[k + 1] - unwrapped[k]);
  };
  const double sim_end_s = steps.back().t_s;

  // ---------------------------------------------------------------- timeline
  ses.samples.reserve(static_cast<std::size_t>(sim_end_s * 150));
  const double t0_s = ns_to_s(kT0Ns);
  auto tns = [&](double t_s) { return kT0Ns + static_cast<TimeNs>(std::llround(t_s * 1e9)); };
  auto utc = [&](double t_s) { return geo::gps_ns_to_unix_ms(ses.gps_start_ns + static_cast<TimeNs>(std::llround(t_s * 1e9))); };
  (void)t0_s;
  const geo::Geodetic start_g = dem.to_geodetic(steps[0].p.x(), steps[0].p.y());
  const double declination = geo::magnetic_declination_rad(start_g, utc(0.0));

  std::vector<Sample> meta_lines;
  meta_lines.emplace_back(meta("UserHeightMeters", num(o.user_height_m)));
  meta_lines.emplace_back(meta("DemSourceSha256", dem.info().source_sha256));
  meta_lines.emplace_back(meta("HeadingReference", "magnetic (rotation vector, chest mount, camera forward)"));
  meta_lines.emplace_back(meta("Simulator", "pdnav simulate --session seed " + std::to_string(seed)));
  if (o.declare_start) {
    meta_lines.emplace_back(meta("StartLatitudeDegrees", num(start_g.lat_deg())));
    meta_lines.emplace_back(meta("StartLongitudeDegrees", num(start_g.lon_deg())));
    meta_lines.emplace_back(meta("StartSigmaMeters", "5"));
  }
  for (auto& m : meta_lines) std::get<MetaSample>(m).t_ns = kT0Ns;

  // Events are generated per stream and merged by time at the end (stable: streams in order).
  std::vector<std::pair<double, Sample>> ev;
  ev.reserve(static_cast<std::size_t>(sim_end_s * 140));

  // IMU: gyro yaw rate about phone +Y (= up), accel with gravity and the step bounce.
  if (o.write_accel_gyro) {
    const double dt = 1.0 / o.imu_rate_hz;
    const double gyro_bias = gauss(rng, 0.003);
    const double bounce = uniform(rng, 1.5, 2.5);
    for (double t = 2.0; t < sim_end_s; t += dt) {
      std::size_t k;
      double f;
      locate(t, &k, &f);
      const double rate = (heading_at(t + 0.5 * dt) - heading_at(t - 0.5 * dt)) / dt;  // clockwise
      GyroSample g;
      g.t_ns = tns(t);
      g.utc_ms = utc(t);
      g.rate_radps = Eigen::Vector3d(gauss(rng, 0.01), -rate + gyro_bias + gauss(rng, 0.01), gauss(rng, 0.01));
      AccelSample a;
      a.t_ns = g.t_ns;
      a.utc_ms = g.utc_ms;
      // The trunk as an inverted pendulum: the vertical acceleration peaks at each heel strike
      // (the lowest point of the arc), the body slows down while it rises to mid-stance and speeds
      // up as it falls to the next strike, a_forward = -0.6 sin: the forward acceleration leads
      // the vertical one by a quarter step, as measured on 42 of the 43 real ILC walks
      // (docs/pdr.md). Forward is the camera side, phone -Z: a_z = +0.6 sin.
      const double vert = bounce * std::cos(2.0 * kPi * f);
      a.acc_mps2 = Eigen::Vector3d(gauss(rng, 0.15), kGravity + vert + gauss(rng, 0.15),
                                   0.6 * std::sin(2.0 * kPi * f) + gauss(rng, 0.15));
      ev.emplace_back(t, a);
      ev.emplace_back(t, g);
    }
  }
  // Rotation vector: true heading + world heading error, reported magnetic.
  double bias_at_outage = kNaN;
  {
    const double dt = 1.0 / o.rotation_rate_hz;
    for (double t = 2.0; t < sim_end_s; t += dt) {
      const double err = heading_err.advance(t, pos_at(t), rng);
      if (!std::isfinite(bias_at_outage) && t >= out_start) bias_at_outage = heading_err.bias_rad();
      ev.emplace_back(t, rotation_for_heading(tns(t), utc(t), wrap_two_pi(heading_at(t) + err - declination)));
    }
  }
  // Step events at the (true) heel strikes; truth rows with them.
  for (std::size_t k = 1; k < steps.size(); ++k) {
    StepDetectorSample sd;
    sd.t_ns = tns(steps[k].t_s);
    sd.utc_ms = utc(steps[k].t_s);
    ev.emplace_back(steps[k].t_s, sd);
    const geo::Geodetic g = dem.to_geodetic(steps[k].p.x(), steps[k].p.y());
    TruthSample tr;
    tr.t_ns = sd.t_ns;
    tr.lat_deg = g.lat_deg();
    tr.lon_deg = g.lon_deg();
    tr.h_m = ground(steps[k].p);
    tr.heading_deg = rad_to_deg(steps[k].heading);
    ev.emplace_back(steps[k].t_s + 1e-7, tr);
    TruthPoint tp;
    tp.t_ns = sd.t_ns;
    tp.en_m = steps[k].p;
    tp.h_m = tr.h_m;
    tp.heading_rad = steps[k].heading;
    tp.outage = steps[k].t_s >= out_start && steps[k].t_s < out_end;
    tp.degraded = in_degraded(steps[k].t_s) || dem_err.forest(steps[k].p.x(), steps[k].p.y());
    ses.truth.push_back(tp);
    ses.stats.length_m += (steps[k].p - steps[k - 1].p).norm();
    if (dem_err.forest(steps[k].p.x(), steps[k].p.y())) ses.stats.forest_fraction += 1.0;
  }
  ses.stats.steps = static_cast<std::int64_t>(steps.size() - 1);
  ses.stats.forest_fraction /= std::max<double>(1.0, static_cast<double>(ses.stats.steps));
  // Barometer.
  {
    const double dt = 1.0 / o.baro_rate_hz;
    for (double t = 2.0; t < sim_end_s; t += dt) {
      PressureSample p;
      p.t_ns = tns(t);
      p.utc_ms = utc(t);
      p.pressure_pa = baro.pressure_pa(t, ground(pos_at(t)) + o.phone_height_m, rng);
      ev.emplace_back(t, p);
    }
  }

  // ---------------------------------------------------------------- GNSS
  const GnssWorldOptions& go = o.gnss;
  std::vector<gnss::SatId> sats;
  for (const auto& s : eph.satellites())
    if (s.sys == gnss::Constellation::kGps || s.sys == gnss::Constellation::kGalileo) sats.push_back(s);
  std::map<gnss::SatId, Channel> ch;
  for (const auto& s : sats) {
    Channel c;
    c.orbit_err_m = gauss(rng, go.orbit_clock_sd_m);
    c.mp_f1 = 1.0 / uniform(rng, 8.0, 40.0);
    c.mp_f2 = 1.0 / uniform(rng, 40.0, 150.0);
    c.mp_p1 = uniform(rng, 0, 2 * kPi);
    c.mp_p2 = uniform(rng, 0, 2 * kPi);
    ch[s] = c;
  }
  const double iono_scale = std::max(0.2, 1.0 + gauss(rng, go.iono_scale_sd));
  // Its own stream of the seed: the gradient does not reshuffle the session's other draws.
  Rng iono_rng(seed ^ 0x9e3779b97f4a7c15ULL);
  const Eigen::Vector2d iono_gradient_m_per_km(gauss(iono_rng, go.iono_gradient_sd_m_per_km),
                                               gauss(iono_rng, go.iono_gradient_sd_m_per_km));
  ses.stats.iono_gradient_m_per_km = iono_gradient_m_per_km;
  const double tropo_scale = 1.0 + gauss(rng, go.tropo_scale_sd);
  const double drift0 = std::clamp(gauss(rng, go.clock_drift_sd_nsps), -200.0, 200.0);
  double drift_nsps = drift0, clock_ns = uniform(rng, -500.0, 500.0);
  const std::int64_t hw_offset_ns = 3 * kNsPerS + static_cast<std::int64_t>(uniform(rng, 0, 1e9));
  const TimeNs gps_epoch0 = (ses.gps_start_ns / kNsPerS + 3) * kNsPerS;  // first whole GPS second after t = 0
  const double epoch0_s = ns_to_s(gps_epoch0 - ses.gps_start_ns);
  const double clock0 = clock_ns;
  std::int64_t full_bias = 0;
  bool have_full_bias = false;
  const gnss::KlobucharParams* klob = eph.klobuchar();
  Eigen::Vector2d fix_err = Eigen::Vector2d::Zero();
  double sats_sum = 0.0;
  bool prev_outage = false;
  const double gnss_dt = 1.0 / o.gnss_rate_hz;
  double last_t = epoch0_s;
  for (double t = epoch0_s; t < sim_end_s; t += gnss_dt) {
    const double dt = t - last_t;
    last_t = t;
    drift_nsps += gauss(rng, go.clock_drift_walk_nsps_per_sqrt_s * std::sqrt(std::max(dt, 0.0)));
    clock_ns += drift_nsps * dt;
    const bool outage = t >= out_start && t < out_end;
    const bool degr = in_degraded(t);
    if (outage) {
      for (auto& [id, c] : ch) c.tracked = false, c.reacquire_at_s = -1.0;
      prev_outage = true;
      continue;
    }
    const TimeNs gps_ns = ses.gps_start_ns + static_cast<TimeNs>(std::llround(t * 1e9));
    const Eigen::Vector2d p2 = pos_at(t);
    const bool forest = dem_err.forest(p2.x(), p2.y());
    const double h_ground = ground(p2);
    const double h_rx = h_ground + o.phone_height_m;
    const geo::Geodetic g_rx = [&] {
      geo::Geodetic g = dem.to_geodetic(p2.x(), p2.y());
      g.h_m = h_rx + kGeoidUndulationM;
      return g;
    }();
    const geo::Ecef rx = geo::to_ecef(g_rx);
    const Eigen::Vector2d v2 = vel_at(t);
    const Eigen::Vector3d v_ecef = geo::ecef_to_enu_rotation(g_rx).transpose() * Eigen::Vector3d(v2.x(), v2.y(), 0.0);
    const double walk_heading = std::atan2(v2.x(), v2.y());
    const double tow_s = static_cast<double>(gps_ns % geo::kNsPerWeek) * 1e-9;

    // Clock fields (consistent: pseudorange and ADR share the drifting hardware clock).
    const TimeNs t_ns = tns(t);
    const std::int64_t time_nanos = t_ns + hw_offset_ns + std::llround(clock_ns - clock0);
    if (!have_full_bias) {
      full_bias = time_nanos - gps_ns - std::llround(clock_ns);
      have_full_bias = true;
    }
    const double bias_nanos = static_cast<double>(time_nanos - full_bias - gps_ns) - clock_ns;  // |.| < 1 ns

    std::vector<GnssRawSample> rows;
    for (const auto& id : sats) {
      Channel& c = ch[id];
      // Geometry: transmit time and state.
      double tau = 0.07;
      std::optional<gnss::SatState> st;
      for (int it = 0; it < 3; ++it) {
        st = eph.state(id, gps_ns - static_cast<TimeNs>(std::llround(tau * 1e9)));
        if (!st) break;
        tau = gnss::sagnac_range_m(st->pos.p_m, rx.p_m) / kSpeedOfLight_mps;
      }
      if (!st) { c.tracked = false; continue; }
      const double rho = tau * kSpeedOfLight_mps;
      const gnss::AzEl ae = gnss::azimuth_elevation(rx, st->pos);
      if (ae.el_rad < 5.0 * kDegToRad) { c.tracked = false; continue; }
      const double horizon = horizon_rad(dem, p2.x(), p2.y(), h_rx, ae.az_rad);
      double extra_loss = 0.0, extra_bias = 0.0;
      if (ae.el_rad < horizon - go.terrain_mask_margin_rad) {
        ++ses.stats.masked_by_terrain;
        c.tracked = false;
        continue;
      }
      if (ae.el_rad < horizon + go.terrain_mask_margin_rad) extra_loss += 10.0, extra_bias += uniform(rng, 1.0, 5.0);
      // Degraded segments: low satellites behind walls / trunks; NLOS for some of the rest.
      if (degr && ae.el_rad < 25.0 * kDegToRad && uniform(rng, 0, 1) < 0.5) { c.tracked = false; continue; }
      if (degr && ae.el_rad < 45.0 * kDegToRad) {
        if (t >= c.nlos_until_s) {
          c.nlos_m = uniform(rng, 0, 1) < go.nlos_probability ? uniform(rng, go.nlos_min_m, go.nlos_max_m) : 0.0;
          c.nlos_until_s = t + uniform(rng, 15.0, 45.0);
        }
      } else {
        c.nlos_m = 0.0;
        c.nlos_until_s = -1.0;
      }
      // C/N0.
      const double rel_az = std::abs(wrap_pi(ae.az_rad - walk_heading));
      double cn0 = go.cn0_horizon_dbhz + (go.cn0_zenith_dbhz - go.cn0_horizon_dbhz) * std::sqrt(std::sin(ae.el_rad));
      if (rel_az > 120.0 * kDegToRad) cn0 -= go.body_block_db * std::cos(ae.el_rad);
      if (forest) cn0 -= go.foliage_loss_db;
      if (degr) cn0 -= go.urban_loss_db;
      if (c.nlos_m > 0) cn0 -= go.nlos_cn0_loss_db;
      cn0 += gauss(rng, go.cn0_fading_db) - extra_loss;
      if (cn0 < go.track_min_cn0_dbhz) { c.tracked = false; continue; }
      // (Re)acquisition.
      if (!c.tracked) {
        if (c.reacquire_at_s < 0) c.reacquire_at_s = t + (prev_outage ? uniform(rng, go.reacquire_min_s, go.reacquire_max_s) : 1.0);
        if (t < c.reacquire_at_s) continue;
        c.tracked = true;
        c.reacquire_at_s = -1.0;
        c.lock_start_s = t;
        c.adr_offset_m = std::floor(uniform(rng, -1e5, 1e5)) * (kSpeedOfLight_mps / 1575.42e6) - rho;  // ADR starts near 0
      }
      // Pseudorange errors.
      const double iono = (klob ? kSpeedOfLight_mps * gnss::klobuchar_delay_s(*klob, g_rx, ae.az_rad, ae.el_rad, tow_s)
                                : 5.0 / std::sqrt(std::max(0.05, std::sin(ae.el_rad)))) * iono_scale +
                         iono_gradient_slant_m(iono_gradient_m_per_km, ae.az_rad, ae.el_rad);
      const double tropo = gnss::saastamoinen_delay_m(g_rx, ae.el_rad) * tropo_scale;
      const double white_sd = go.code_sigma_at_40_m * std::pow(10.0, -(cn0 - 40.0) / 20.0);
      const double mp_amp = (degr || forest ? go.multipath_degraded_m : go.multipath_open_m) * std::exp(-ae.el_rad / (25.0 * kDegToRad));
      const double mp = mp_amp * (std::sin(2 * kPi * c.mp_f1 * t + c.mp_p1) + 0.5 * std::sin(2 * kPi * c.mp_f2 * t + c.mp_p2)) / 1.118;
      if (c.nlos_m > 0) ++ses.stats.nlos_rows;
      const double code_err = iono + tropo + c.orbit_err_m + mp + c.nlos_m + extra_bias + gauss(rng, white_sd);
      const double sat_clock_m = kSpeedOfLight_mps * (st->clock_bias_s - st->group_delay_s);
      const double pr_minus_rx_clock = rho - sat_clock_m + code_err;  // pseudorange without the receiver clock
      GnssRawSample r;
      r.t_ns = t_ns;
      r.utc_ms = geo::gps_ns_to_unix_ms(gps_ns);
      r.time_nanos = time_nanos;
      r.leap_second = geo::leap_seconds_at_gps_ns(gps_ns);
      r.time_uncertainty_nanos = 0.0;
      r.full_bias_nanos = full_bias;
      r.bias_nanos = bias_nanos;
      r.bias_uncertainty_nanos = 20.0;
      r.drift_nanos_per_second = drift_nsps + gauss(rng, 1.0);
      r.drift_uncertainty_nanos_per_second = 3.0;
      r.hardware_clock_discontinuity_count = 0;
      r.svid = id.prn;
      r.time_offset_nanos = 0.0;
      r.constellation_type = static_cast<int>(id.sys);
      r.state = gnss::state_bit::kCodeLock | gnss::state_bit::kBitSync | gnss::state_bit::kSubframeSync |
                gnss::state_bit::kTowDecoded | gnss::state_bit::kTowKnown;
      if (id.sys == gnss::Constellation::kGalileo)
        r.state |= gnss::state_bit::kGalE1bcCodeLock | gnss::state_bit::kGalE1c2ndCodeLock | gnss::state_bit::kGalE1bPageSync;
      const std::int64_t sv_ns = gps_ns - std::llround(pr_minus_rx_clock / kSpeedOfLight_mps * 1e9);
      r.received_sv_time_nanos = ((sv_ns % geo::kNsPerWeek) + geo::kNsPerWeek) % geo::kNsPerWeek;
      r.received_sv_time_uncertainty_nanos =
          std::max<std::int64_t>(1, std::llround(go.reported_sigma_factor * white_sd / kSpeedOfLight_mps * 1e9));
      r.cn0_dbhz = std::round(cn0 * 10.0) / 10.0;
      const double rate_sd = 0.04 * std::pow(10.0, -(cn0 - 40.0) / 20.0);
      r.pseudorange_rate_mps = gnss::range_rate_mps(*st, rx.p_m, v_ecef) - kSpeedOfLight_mps * st->clock_drift_sps +
                               drift_nsps * 1e-9 * kSpeedOfLight_mps + gauss(rng, rate_sd);
      r.pseudorange_rate_uncertainty_mps = rate_sd;
      // Carrier phase (ADR): same clock, iono advance, mm noise, slips.
      if (cn0 >= go.adr_min_cn0_dbhz) {
        const double lambda = kSpeedOfLight_mps / 1575.42e6;
        std::int64_t adr_state = gnss::adr_bit::kValid;
        if (c.lock_start_s == t) adr_state |= gnss::adr_bit::kReset;
        const double p_slip = go.cycle_slip_per_epoch_at_30 * std::pow(10.0, -(cn0 - 30.0) / 10.0) * (degr ? 3.0 : 1.0);
        if (c.lock_start_s != t && uniform(rng, 0, 1) < p_slip) {
          const double k = std::round(uniform(rng, -20.0, 20.0));
          c.adr_offset_m += (k == 0 ? 1.0 : k) * lambda;
          ++ses.stats.cycle_slips;
          if (uniform(rng, 0, 1) >= go.undetected_slip_fraction) adr_state |= gnss::adr_bit::kCycleSlip;
        }
        const double adr_sd = go.adr_noise_at_40_m * std::pow(10.0, -(cn0 - 40.0) / 20.0);
        r.accumulated_delta_range_state = adr_state;
        r.accumulated_delta_range_m = rho - sat_clock_m + clock_ns * 1e-9 * kSpeedOfLight_mps - iono + tropo +
                                      c.orbit_err_m + c.adr_offset_m + 0.02 * mp / std::max(0.1, mp_amp) +
                                      gauss(rng, adr_sd);
        r.accumulated_delta_range_uncertainty_m = adr_sd;
      } else {
        r.accumulated_delta_range_state = 0;
        c.lock_start_s = t;  // phase lock lost: next valid ADR is a reset
      }
      r.carrier_frequency_hz = 1575.42e6;
      r.code_type = "C";
      rows.push_back(r);
    }
    prev_outage = false;
    ses.stats.raw_rows += static_cast<std::int64_t>(rows.size());
    sats_sum += static_cast<double>(rows.size());
    ++ses.stats.gnss_epochs;
    for (auto& r : rows) ev.emplace_back(t, std::move(r));
    // Chipset fix: low-passed error, larger and over-confident when degraded.
    const double sd = (degr || forest) ? go.fix_error_degraded_m : go.fix_error_open_m;
    const double a = std::exp(-gnss_dt / go.fix_tau_s);
    fix_err = a * fix_err + std::sqrt(1 - a * a) * Eigen::Vector2d(gauss(rng, sd), gauss(rng, sd));
    if (ses.stats.gnss_epochs > 5 && ev.size() > 0) {
      int tracked = 0;
      for (const auto& [id, c] : ch) tracked += c.tracked ? 1 : 0;
      if (tracked >= 4) {
        const Eigen::Vector2d fp = p2 + fix_err;
        const geo::Geodetic fg = dem.to_geodetic(fp.x(), fp.y());
        FixSample f;
        f.t_ns = t_ns + 50 * kNsPerMs;
        f.utc_ms = geo::gps_ns_to_unix_ms(gps_ns);
        f.provider = "GPS";
        f.lat_deg = fg.lat_deg();
        f.lon_deg = fg.lon_deg();
        f.alt_m = h_rx + kGeoidUndulationM + gauss(rng, 1.5 * sd);
        f.speed_mps = v2.norm();
        f.bearing_deg = rad_to_deg(wrap_two_pi(walk_heading));
        f.accuracy_m = (degr || forest ? 0.6 : 1.1) * 1.5 * sd;  // 68 % radius of the (claimed) error
        f.vertical_accuracy_m = 2.0 * sd;
        f.speed_accuracy_mps = 0.3;
        f.bearing_accuracy_deg = 15.0;
        ev.emplace_back(t + 0.05, f);
        ++ses.stats.fix_rows;
      }
    }
  }
  ses.stats.mean_sats_tracked = ses.stats.gnss_epochs > 0 ? sats_sum / static_cast<double>(ses.stats.gnss_epochs) : 0.0;
  ses.stats.walker_stride_scale = stride.walker_scale();
  ses.stats.heading_bias_at_outage_deg = std::isfinite(bias_at_outage) ? rad_to_deg(bias_at_outage) : 0.0;
  ses.stats.phone_shifts = static_cast<std::int64_t>(heading_err.shifts());
  ses.stats.duration_s = sim_end_s;

  std::stable_sort(ev.begin(), ev.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  ses.samples = std::move(meta_lines);
  ses.samples.reserve(ev.size() + ses.samples.size());
  for (auto& e : ev) ses.samples.push_back(std::move(e.second));
  return ses;
}

}  // namespace pdnav::phonesim
