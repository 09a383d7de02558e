#include "pdnav/gnss/solver_metrics.h"

#include <algorithm>
#include <cmath>

namespace pdnav::gnss {
namespace {

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
  a.tdcp_rms_enu_m = rms_axes(tdcp);
  a.doppler_rms_enu_m = rms_axes(dopp);
  return a;
}

}  // namespace pdnav::gnss
