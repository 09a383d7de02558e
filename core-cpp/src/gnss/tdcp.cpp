#include "pdnav/gnss/tdcp.h"

#include <cmath>
#include <map>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "pdnav/gnss/atmosphere.h"
#include "pdnav/gnss/spp.h"

namespace pdnav::gnss {
namespace {

struct LinRow {
  SatId sat;
  Eigen::Vector3d los = Eigen::Vector3d::Zero();  // unit receiver -> satellite
  double y = 0.0;                                  // reduced observation
  double var = 1.0;
};

/// Satellite position in the receive-time ECEF frame (Sagnac) and its line of sight.
Eigen::Vector3d sat_at_receive(const SatState& st, const Eigen::Vector3d& rx) {
  Eigen::Vector3d s = st.pos.p_m;
  for (int k = 0; k < 2; ++k) s = rotate_for_travel_time(st.pos.p_m, (s - rx).norm() / kSpeedOfLight_mps);
  return s;
}

struct WlsOut {
  bool ok = false;
  std::string reason;
  Eigen::Vector4d x = Eigen::Vector4d::Zero();
  Eigen::Matrix4d cov = Eigen::Matrix4d::Identity();
  std::vector<SatId> used, excluded;
  bool self_checked = true;
};

/// Weighted LS of y = -los . d + clock with chi-square FDE (exclude worst, repeat).
WlsOut robust_wls(std::vector<LinRow> rows, const TdcpOptions& opt, std::map<std::string, std::int64_t>& ex,
                  const char* fde_reason) {
  WlsOut out;
  for (;;) {
    const auto n = static_cast<Eigen::Index>(rows.size());
    if (n < 4) { out.reason = "fewer than 4 satellites"; return out; }
    Eigen::MatrixXd h(n, 4);
    Eigen::VectorXd y(n), w(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const LinRow& r = rows[static_cast<std::size_t>(i)];
      h.row(i) << -r.los.transpose(), 1.0;
      y(i) = r.y;
      w(i) = 1.0 / r.var;
    }
    const Eigen::Matrix4d nm = h.transpose() * w.asDiagonal() * h;
    const Eigen::LDLT<Eigen::Matrix4d> ldlt(nm);
    if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > opt.min_rcond)) { out.reason = "singular geometry"; return out; }
    const Eigen::Matrix4d hh = (h.transpose() * h);
    const Eigen::FullPivLU<Eigen::Matrix4d> lu(hh);
    if (!lu.isInvertible() || !(std::sqrt(lu.inverse().trace()) < opt.max_gdop)) { out.reason = "singular geometry (GDOP)"; return out; }
    out.x = ldlt.solve(h.transpose() * w.asDiagonal() * y);
    out.cov = ldlt.solve(Eigen::Matrix4d::Identity());
    if (!out.x.allFinite()) { out.reason = "numerical failure"; return out; }
    const Eigen::VectorXd res = y - h * out.x;
    const Eigen::VectorXd nres = res.array().square() * w.array();
    const int dof = static_cast<int>(n) - 4;
    const bool fails = dof >= 1 && nres.sum() > chi_square_quantile(opt.fde_false_alarm, dof);
    if (!fails || dof < 2 || static_cast<int>(out.excluded.size()) >= opt.max_fde_exclusions) {
      for (const LinRow& r : rows) out.used.push_back(r.sat);
      out.ok = true;
      out.self_checked = dof >= 1 && !fails;
      return out;
    }
    Eigen::Index worst = 0;
    nres.maxCoeff(&worst);
    out.excluded.push_back(rows[static_cast<std::size_t>(worst)].sat);
    ++ex[fde_reason];
    rows.erase(rows.begin() + worst);
  }
}

bool above_mask(const Eigen::Vector3d& rx, const Eigen::Vector3d& sat, double mask_deg) {
  return azimuth_elevation(geo::Ecef(rx), geo::Ecef(sat)).el_rad >= deg_to_rad(mask_deg);
}

double snr_variance(double a, double b, double cn0_dbhz) { return a + b * std::pow(10.0, -cn0_dbhz / 10.0); }

DisplacementSolution finish(const WlsOut& w, const char* source, double dt_s, double scale,
                            std::map<std::string, std::int64_t>& ex) {
  DisplacementSolution d;
  d.source = source;
  d.dt_s = dt_s;
  d.excluded = ex;
  d.excluded_fde = w.excluded;
  if (!w.ok) { d.reason = w.reason; return d; }
  d.ok = true;
  d.disp_ecef_m = w.x.head<3>() * scale;
  d.clock_change_m = w.x(3) * scale;
  d.cov_ecef_m2 = w.cov.topLeftCorner<3, 3>() * scale * scale;
  d.clock_change_var_m2 = w.cov(3, 3) * scale * scale;
  d.used = w.used;
  d.self_checked = w.self_checked;
  return d;
}

}  // namespace

DisplacementSolution solve_tdcp(const std::vector<CarrierObservation>& epoch1,
                                const std::vector<CarrierObservation>& epoch2, double dt_s,
                                const geo::Ecef& rx_ecef, const TdcpOptions& opt) {
  std::map<std::string, std::int64_t> ex;
  std::map<SatId, const CarrierObservation*> first;
  for (const auto& o : epoch1) first[o.sat] = &o;
  const Eigen::Vector3d rx = rx_ecef.p_m;
  std::vector<LinRow> rows;
  if (!(dt_s > 0.0) || !rx.allFinite()) {
    DisplacementSolution d;
    d.source = "tdcp";
    d.reason = "bad interval or position";
    return d;
  }
  for (const auto& o2 : epoch2) {
    const auto it = first.find(o2.sat);
    if (it == first.end() || !std::isfinite(o2.adr_m) || !std::isfinite(it->second->adr_m)) continue;
    const CarrierObservation& o1 = *it->second;
    if (!same_signal(o1, o2)) { ++ex["tdcp: signal changed between epochs"]; continue; }
    const double adr_rate = (o2.adr_m - o1.adr_m) / dt_s;
    if (std::isfinite(o1.pr_rate_mps) && std::isfinite(o2.pr_rate_mps) &&
        std::fabs(adr_rate - 0.5 * (o1.pr_rate_mps + o2.pr_rate_mps)) > opt.max_rate_mismatch_mps) {
      ++ex["tdcp: ADR rate vs pseudorange rate > 3 m/s"];
      continue;
    }
    const Eigen::Vector3d s1 = sat_at_receive(o1.state, rx), s2 = sat_at_receive(o2.state, rx);
    if (!s1.allFinite() || !s2.allFinite()) { ++ex["tdcp: non-finite satellite state"]; continue; }
    if (!above_mask(rx, s2, opt.elevation_mask_deg)) { ++ex["tdcp: below elevation mask"]; continue; }
    LinRow r;
    r.sat = o2.sat;
    r.los = (s2 - rx).normalized();
    const double sat_clock_change_m = kSpeedOfLight_mps * (o2.state.clock_bias_s - o1.state.clock_bias_s);
    r.y = (o2.adr_m - o1.adr_m) + sat_clock_change_m - ((s2 - rx).norm() - (s1 - rx).norm());
    r.var = snr_variance(opt.snr_a_mm2, opt.snr_b_mm2, 0.5 * (o1.cn0_dbhz + o2.cn0_dbhz)) * 1e-6;
    rows.push_back(r);
  }
  const WlsOut w = robust_wls(rows, opt, ex, "tdcp: FDE residual test");
  return finish(w, "tdcp", dt_s, 1.0, ex);
}

DisplacementSolution solve_doppler(const std::vector<CarrierObservation>& epoch, double dt_s,
                                   const geo::Ecef& rx_ecef, const TdcpOptions& opt) {
  std::map<std::string, std::int64_t> ex;
  const Eigen::Vector3d rx = rx_ecef.p_m;
  std::vector<LinRow> rows;
  if (!(dt_s > 0.0) || !rx.allFinite()) {
    DisplacementSolution d;
    d.source = "doppler";
    d.reason = "bad interval or position";
    return d;
  }
  for (const auto& o : epoch) {
    if (!std::isfinite(o.pr_rate_mps)) continue;
    const Eigen::Vector3d s = sat_at_receive(o.state, rx);
    if (!s.allFinite() || !o.state.vel_mps.allFinite()) { ++ex["doppler: non-finite satellite state"]; continue; }
    if (!above_mask(rx, s, opt.elevation_mask_deg)) { ++ex["doppler: below elevation mask"]; continue; }
    LinRow r;
    r.sat = o.sat;
    r.los = (s - rx).normalized();
    const Eigen::Vector3d sat_vel = rotate_for_travel_time(o.state.vel_mps, (s - rx).norm() / kSpeedOfLight_mps);
    r.y = o.pr_rate_mps - sat_vel.dot(r.los) + kSpeedOfLight_mps * o.state.clock_drift_sps;
    const double cn0_var = doppler_cn0_variance_m2ps2(opt, o.cn0_dbhz);
    r.var = std::isfinite(o.pr_rate_sigma_mps) && o.pr_rate_sigma_mps > 0.0
                ? std::max(o.pr_rate_sigma_mps * o.pr_rate_sigma_mps, opt.doppler_a_m2ps2) : cn0_var;
    rows.push_back(r);
  }
  const WlsOut w = robust_wls(rows, opt, ex, "doppler: FDE residual test");
  return finish(w, "doppler", dt_s, dt_s, ex);
}

double doppler_cn0_variance_m2ps2(const TdcpOptions& opt, double cn0_dbhz) {
  return snr_variance(opt.doppler_a_m2ps2, opt.doppler_b_m2ps2, cn0_dbhz);
}

bool same_signal(const CarrierObservation& a, const CarrierObservation& b) {
  if (std::isfinite(a.carrier_hz) && std::isfinite(b.carrier_hz) && std::fabs(a.carrier_hz - b.carrier_hz) > 1e3)
    return false;
  if (std::isfinite(a.carrier_hz) != std::isfinite(b.carrier_hz)) return false;
  return a.code_type.empty() || b.code_type.empty() || a.code_type == b.code_type;
}

}  // namespace pdnav::gnss
