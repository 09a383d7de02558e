#include "pdnav/gnss/solver_metrics.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

#include "pdnav/geo/estimate.h"
#include "pdnav/geo/time.h"

namespace pdnav::gnss {
namespace {

/// The KF's horizontal error `e` (ENU at the truth) lies inside the 2-D 68 % ellipse of its
/// reported covariance: chi-square 2 dof at 0.68, -2 ln(0.32) = 2.279 (kOneSigmaM2, 2.2957,
/// is the 68.27 % of the other coverage figures; this one is kept as the GSDC bar was measured).
bool kf_inside_68(const EpochSolution& s, const geo::Enu& e) {
  return mahalanobis2(s.kf_cov_enu.topLeftCorner<2, 2>(), Eigen::Vector2d(e.e_m(), e.n_m())) <= 2.279;
}

double rms(const std::vector<double>& v) {
  if (v.empty()) return kNaN;
  double s = 0.0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

Eigen::Vector3d rms_axes(const std::vector<Eigen::Vector3d>& v) {
  if (v.empty()) return Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (const auto& x : v) s += x.cwiseProduct(x);
  return (s / static_cast<double>(v.size())).cwiseSqrt();
}

}  // namespace

double percentile(std::vector<double> v, double pct) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const double pos = std::clamp(pct, 0.0, 100.0) / 100.0 * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  const double f = pos - static_cast<double>(lo);
  return v[lo] * (1.0 - f) + v[hi] * f;
}

StaticAccuracy evaluate_static(const std::vector<EpochSolution>& sols, const geo::Geodetic& truth) {
  const geo::LocalFrame frame(truth);
  std::vector<double> spp_h, spp_v, kf_h, kf_v;
  std::vector<Eigen::Vector3d> tdcp, dopp;
  int inside = 0;
  for (const EpochSolution& s : sols) {
    if (s.spp_ok) {
      const geo::Enu e = frame.to_enu(s.spp);
      spp_h.push_back(std::hypot(e.e_m(), e.n_m()));
      spp_v.push_back(e.u_m());
    }
    if (s.kf_ok) {
      const geo::Enu e = frame.to_enu(s.kf);
      kf_h.push_back(std::hypot(e.e_m(), e.n_m()));
      kf_v.push_back(e.u_m());
      inside += kf_inside_68(s, e);
    }
    if (!s.disp_source.empty() && std::fabs(s.disp_dt_s - 1.0) <= 0.1) {
      (s.disp_source == "tdcp" ? tdcp : dopp).push_back(s.tdcp_disp_m);
    }
  }
  StaticAccuracy a;
  a.spp_epochs = static_cast<int>(spp_h.size());
  a.kf_epochs = static_cast<int>(kf_h.size());
  a.tdcp_epochs = static_cast<int>(tdcp.size());
  a.doppler_epochs = static_cast<int>(dopp.size());
  a.spp_p50_h_m = percentile(spp_h, 50.0);
  a.spp_p95_h_m = percentile(spp_h, 95.0);
  a.spp_rms_h_m = rms(spp_h);
  a.spp_rms_v_m = rms(spp_v);
  a.kf_rms_h_m = rms(kf_h);
  a.kf_p50_h_m = percentile(kf_h, 50.0);
  a.kf_p95_h_m = percentile(kf_h, 95.0);
  a.kf_rms_v_m = rms(kf_v);
  a.kf_coverage68 = kf_h.empty() ? kNaN : static_cast<double>(inside) / static_cast<double>(kf_h.size());
  a.tdcp_rms_enu_m = rms_axes(tdcp);
  a.doppler_rms_enu_m = rms_axes(dopp);
  return a;
}

namespace {

std::vector<std::string> split_csv(const std::string& l) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : l) {
    if (c == ',') { out.push_back(cur); cur.clear(); }
    else if (c != '\r' && c != '"') cur += c;
  }
  out.push_back(cur);
  for (auto& f : out) {
    const auto b = f.find_first_not_of(" \t");
    f = b == std::string::npos ? std::string() : f.substr(b, f.find_last_not_of(" \t") - b + 1);
  }
  return out;
}

bool to_double(const std::string& f, double& v) {
  if (f.empty() || f.size() > 64) return false;
  char* end = nullptr;
  v = std::strtod(f.c_str(), &end);
  return end && *end == '\0' && std::isfinite(v);
}

}  // namespace

TruthTrack read_truth_csv(std::istream& in, const std::string& name) {
  std::string l;
  int line_no = 0;
  auto fail = [&](const std::string& why) { throw std::runtime_error(name + ":" + std::to_string(line_no) + ": " + why); };
  if (!std::getline(in, l)) fail("empty truth file");
  ++line_no;
  const auto head = split_csv(l);
  const char* want[4] = {"millisSinceGpsEpoch", "latDeg", "lngDeg", "heightAboveWgs84EllipsoidM"};
  int col[4] = {-1, -1, -1, -1};
  for (int k = 0; k < 4; ++k)
    for (std::size_t i = 0; i < head.size(); ++i)
      if (head[i] == want[k]) col[k] = static_cast<int>(i);
  for (int k = 0; k < 4; ++k)
    if (col[k] < 0) fail(std::string("truth CSV: no column '") + want[k] + "' in the header");
  TruthTrack t;
  while (std::getline(in, l)) {
    ++line_no;
    if (l.empty() || l == "\r") continue;
    const auto f = split_csv(l);
    double v[4];
    bool ok = true;
    for (int k = 0; k < 4 && ok; ++k)
      ok = static_cast<std::size_t>(col[k]) < f.size() && to_double(f[static_cast<std::size_t>(col[k])], v[k]);
    if (!ok || std::fabs(v[1]) > 90.0 || std::fabs(v[2]) > 180.0 || std::fabs(v[3]) > 1e5 || v[0] < 0 || v[0] > 1e14) {
      ++t.skipped_rows;
      continue;
    }
    TruthPoint p;
    p.gps_ns = static_cast<std::int64_t>(std::llround(v[0])) * kNsPerMs;
    p.pos = geo::Geodetic::from_deg(v[1], v[2], v[3]);
    t.points.push_back(p);
  }
  if (t.points.empty()) fail("truth CSV: no usable row");
  std::stable_sort(t.points.begin(), t.points.end(), [](const TruthPoint& a, const TruthPoint& b) { return a.gps_ns < b.gps_ns; });
  return t;
}

TruthTrack read_truth_csv_file(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ":0: cannot open");
  return read_truth_csv(f, path);
}

bool truth_at(const TruthTrack& t, std::int64_t gps_ns, geo::Geodetic& out, double max_gap_s) {
  const auto& p = t.points;
  if (p.empty()) return false;
  auto it = std::lower_bound(p.begin(), p.end(), gps_ns, [](const TruthPoint& a, std::int64_t x) { return a.gps_ns < x; });
  const double tol_ns = 2e6;  // 2 ms: a point this close is used as is
  if (it != p.end() && std::fabs(static_cast<double>(it->gps_ns - gps_ns)) <= tol_ns) { out = it->pos; return true; }
  if (it != p.begin() && std::fabs(static_cast<double>(std::prev(it)->gps_ns - gps_ns)) <= tol_ns) { out = std::prev(it)->pos; return true; }
  if (it == p.begin() || it == p.end()) return false;
  const TruthPoint& a = *std::prev(it);
  const TruthPoint& b = *it;
  const double span = static_cast<double>(b.gps_ns - a.gps_ns);
  if (!(span > 0) || span * 1e-9 > max_gap_s) return false;
  const double f = static_cast<double>(gps_ns - a.gps_ns) / span;
  const Eigen::Vector3d ea = geo::to_ecef(a.pos).p_m, eb = geo::to_ecef(b.pos).p_m;
  out = geo::to_geodetic(geo::Ecef(ea + f * (eb - ea)));
  return true;
}

TrackAccuracy evaluate_track(const std::vector<EpochSolution>& sols, const TruthTrack& truth) {
  std::vector<double> spp_h, kf_h;
  std::vector<Eigen::Vector3d> tdcp_err, dopp_err;
  int epochs = 0, inside = 0;
  for (const EpochSolution& s : sols) {
    geo::Geodetic g;
    if (!truth_at(truth, s.gps_ns, g)) continue;
    ++epochs;
    const geo::LocalFrame frame(g);
    geo::Geodetic before;
    if (!s.disp_source.empty() && std::fabs(s.disp_dt_s - 1.0) <= 0.1 &&
        truth_at(truth, s.gps_ns - std::llround(s.disp_dt_s * 1e9), before)) {
      const Eigen::Vector3d truth_disp = -frame.to_enu(before).p_m;  // from the earlier truth to this one
      (s.disp_source == "tdcp" ? tdcp_err : dopp_err).push_back(s.tdcp_disp_m - truth_disp);
    }
    if (s.spp_ok) {
      const geo::Enu e = frame.to_enu(s.spp);
      spp_h.push_back(std::hypot(e.e_m(), e.n_m()));
    }
    if (s.kf_ok) {
      const geo::Enu e = frame.to_enu(s.kf);
      kf_h.push_back(std::hypot(e.e_m(), e.n_m()));
      inside += kf_inside_68(s, e);
    }
  }
  auto fill = [&](TrackStats& t, const std::vector<double>& h) {
    t.epochs = epochs;
    t.solved = static_cast<int>(h.size());
    t.p50_h_m = percentile(h, 50.0);
    t.p95_h_m = percentile(h, 95.0);
    t.rms_h_m = rms(h);
    t.score_m = 0.5 * (t.p50_h_m + t.p95_h_m);
    t.availability = epochs > 0 ? static_cast<double>(h.size()) / epochs : kNaN;
  };
  TrackAccuracy a;
  fill(a.spp, spp_h);
  fill(a.kf, kf_h);
  a.kf.coverage68 = kf_h.empty() ? kNaN : static_cast<double>(inside) / static_cast<double>(kf_h.size());
  a.tdcp_epochs = static_cast<int>(tdcp_err.size());
  a.doppler_epochs = static_cast<int>(dopp_err.size());
  a.tdcp_err_rms_enu_m = rms_axes(tdcp_err);
  a.doppler_err_rms_enu_m = rms_axes(dopp_err);
  return a;
}

}  // namespace pdnav::gnss
