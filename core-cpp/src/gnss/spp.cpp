#include "pdnav/gnss/spp.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "pdnav/geo/units.h"
#include "pdnav/gnss/kalman.h"

namespace pdnav::gnss {
namespace {

constexpr double kL1Hz = 1575.42e6;
constexpr double kNearSurfaceMinM = 6.0e6;   // iterate is "on Earth" between these radii
constexpr double kNearSurfaceMaxM = 7.0e6;

/// A receiver clock: one per clock group and band (an L5 code has the receiver's L1-L5 bias).
struct ClockKey {
  Constellation sys = Constellation::kGps;
  SignalBand band = SignalBand::kL1;
  bool operator<(const ClockKey& o) const { return sys != o.sys ? sys < o.sys : band < o.band; }
  bool operator==(const ClockKey& o) const { return sys == o.sys && band == o.band; }
};

/// Unknowns: x, y, z, clock of the reference, one ISB per other clock key.
struct Layout {
  ClockKey ref;
  std::map<ClockKey, int> isb_col;  // clock key -> column (>= 4)
  int cols = 4;
};

}  // namespace

Constellation clock_group(Constellation sys) {
  return sys == Constellation::kQzss ? Constellation::kGps : sys;
}

namespace {

ClockKey clock_key(const SppObservation& o) {
  return ClockKey{clock_group(o.sat.sys), code_band(o.iono_free, o.carrier_hz)};
}

Layout make_layout(const std::vector<const SppObservation*>& obs) {
  std::map<ClockKey, int> count;
  for (const auto* o : obs) ++count[clock_key(*o)];
  Layout l;
  // GPS L1 when present (the clock the KF and the fusion layer follow), else GPS L5, else the first
  const ClockKey gps_l1{Constellation::kGps, SignalBand::kL1}, gps_l5{Constellation::kGps, SignalBand::kL5};
  l.ref = count.count(gps_l1) ? gps_l1 : count.count(gps_l5) ? gps_l5 : count.begin()->first;
  for (const auto& [key, n] : count) {
    if (key == l.ref) continue;
    l.isb_col[key] = l.cols++;
  }
  return l;
}

int isb_col(const Layout& l, const SppObservation& o) {
  const ClockKey k = clock_key(o);
  return k == l.ref ? -1 : l.isb_col.at(k);
}

struct Row {
  double residual_m = 0.0;   // measured - modelled
  Eigen::Vector3d los = Eigen::Vector3d::Zero();  // unit vector receiver -> satellite
  double var_m2 = 1.0;
  double el_rad = kPi / 2;
  double az_rad = 0.0;
  bool masked = false;
};

/// Broadcast group delay for this signal. GPS/QZSS L1 C/A: TGD; L5: (f1/f5)^2 TGD (IS-GPS-200
/// 20.3.3.3.3.2 scaling, the ISC_L5 of CNAV is not in RINEX 3 LNAV). Galileo: BGD scaled the same
/// way for E5a. BeiDou: TGD1 is the B1I delay (BDS-SIS-ICD-B1I 5.2.4.10); it must not be applied
/// to B1C (1575.42 MHz), whose TGD_B1Cp is only in CNAV1 (not in RINEX 3 nav), so B1C gets none.
double signal_group_delay_s(const SppObservation& o) {
  const double g = o.state.group_delay_s;
  if (o.sat.sys == Constellation::kGlonass) return 0.0;
  if (o.sat.sys == Constellation::kBeidou) return std::fabs(o.carrier_hz - 1561.098e6) < 1e6 ? g : 0.0;
  if (std::fabs(o.carrier_hz - kL1Hz) < 1e6) return g;
  return g * (kL1Hz / o.carrier_hz) * (kL1Hz / o.carrier_hz);
}

/// Model of one pseudorange at the iterate x (ECEF + clocks).
Row model_row(const SppObservation& o, const Eigen::VectorXd& x, const Layout& l, double tow_s,
              const KlobucharParams* klob, const SppOptions& opt) {
  Row r;
  const Eigen::Vector3d rx = x.head<3>();
  Eigen::Vector3d sat = o.state.pos.p_m;
  double range = (sat - rx).norm();
  for (int k = 0; k < 2; ++k) {  // travel time depends on the rotated position; converges at once
    sat = rotate_for_travel_time(o.state.pos.p_m, range / kSpeedOfLight_mps);
    range = (sat - rx).norm();
  }
  r.los = (sat - rx) / range;
  double clock = x(3);
  if (isb_col(l, o) >= 0) clock += x(isb_col(l, o));
  double atmo_m = 0.0;
  const double radius = rx.norm();
  if (radius > kNearSurfaceMinM && radius < kNearSurfaceMaxM) {
    const geo::Ecef rx_ecef(rx);
    const AzEl ae = azimuth_elevation(rx_ecef, geo::Ecef(sat));
    r.el_rad = ae.el_rad;
    r.az_rad = ae.az_rad;
    r.masked = ae.el_rad < deg_to_rad(opt.elevation_mask_deg);
    const geo::Geodetic g = geo::to_geodetic(rx_ecef);
    if (opt.ionosphere && klob != nullptr && ae.el_rad > 0.0 && !o.iono_free) {
      const double scale = std::pow(kL1Hz / o.carrier_hz, 2);
      atmo_m += scale * kSpeedOfLight_mps * klobuchar_delay_s(*klob, g, ae.az_rad, ae.el_rad, tow_s);
    }
    if (opt.troposphere && ae.el_rad > 0.0) atmo_m += saastamoinen_delay_m(g, ae.el_rad);
  }
  const double sat_clock_m = kSpeedOfLight_mps * (o.state.clock_bias_s - (o.iono_free ? 0.0 : signal_group_delay_s(o)));
  r.residual_m = o.pseudorange_m - (range + clock - sat_clock_m + atmo_m);
  r.var_m2 = o.var_scale * code_variance_m2(opt.code_noise, o.sat.sys, o.carrier_hz, o.iono_free, o.cn0_dbhz,
                                            o.cn0_l5_dbhz, r.el_rad, o.white_var_ratio);
  return r;
}

struct LsResult {
  bool ok = false;
  std::string reason;
  Eigen::VectorXd x;
  Eigen::MatrixXd cov;           // (H^T W H)^-1
  std::vector<Row> rows;
  int iterations = 0;
};

/// Gauss-Newton on the given observations; masked satellites are dropped from the fit.
/// `var_scale` (may be null) multiplies each observation's variance (robust reweighting).
LsResult iterate_ls(const std::vector<const SppObservation*>& obs, const Layout& l, Eigen::VectorXd x,
                    double tow_s, const KlobucharParams* klob, const SppOptions& opt,
                    const std::vector<double>* var_scale = nullptr) {
  LsResult res;
  const int n = static_cast<int>(obs.size());
  for (int it = 0; it < opt.max_iterations; ++it) {
    res.rows.clear();
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(n, l.cols);
    Eigen::VectorXd y = Eigen::VectorXd::Zero(n), w = Eigen::VectorXd::Zero(n);
    int used = 0;
    for (int i = 0; i < n; ++i) {
      res.rows.push_back(model_row(*obs[i], x, l, tow_s, klob, opt));
      if (var_scale != nullptr) res.rows.back().var_m2 *= (*var_scale)[static_cast<std::size_t>(i)];
      const Row& r = res.rows.back();
      if (r.masked) continue;
      h.block<1, 3>(i, 0) = -r.los.transpose();
      h(i, 3) = 1.0;
      if (isb_col(l, *obs[i]) >= 0) h(i, isb_col(l, *obs[i])) = 1.0;
      y(i) = r.residual_m;
      w(i) = 1.0 / r.var_m2;
      ++used;
    }
    if (used < l.cols) { res.reason = "fewer satellites than unknowns"; return res; }
    const Eigen::MatrixXd n_mat = h.transpose() * w.asDiagonal() * h;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(n_mat);
    if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > opt.min_rcond)) { res.reason = "singular geometry"; return res; }
    const Eigen::VectorXd dx = ldlt.solve(h.transpose() * w.asDiagonal() * y);
    if (!dx.allFinite()) { res.reason = "numerical failure"; return res; }
    x += dx;
    res.iterations = it + 1;
    if (dx.head<3>().norm() < opt.convergence_m && x.head<3>().norm() > kNearSurfaceMinM) {
      res.cov = ldlt.solve(Eigen::MatrixXd::Identity(l.cols, l.cols));
      // final rows at the converged state
      for (int i = 0; i < n; ++i) {
        res.rows[static_cast<std::size_t>(i)] = model_row(*obs[i], x, l, tow_s, klob, opt);
        if (var_scale != nullptr) res.rows[static_cast<std::size_t>(i)].var_m2 *= (*var_scale)[static_cast<std::size_t>(i)];
      }
      res.x = x;
      res.ok = true;
      return res;
    }
  }
  res.reason = "least squares did not converge";
  return res;
}

Eigen::VectorXd initial_state(const Layout& l, const geo::Ecef& initial) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(l.cols);
  if (initial.p_m.allFinite()) x.head<3>() = initial.p_m;
  return x;
}

/// Drops satellites whose system has a single satellite (it only determines its own ISB).
std::vector<const SppObservation*> usable(const std::vector<SppObservation>& obs, const SppOptions& opt,
                                          std::map<std::string, std::int64_t>& excluded) {
  std::map<ClockKey, int> count;
  for (const auto& o : obs) ++count[clock_key(o)];
  std::vector<const SppObservation*> out;
  for (const auto& o : obs) {
    if (!std::isfinite(o.pseudorange_m) || !o.state.pos.p_m.allFinite() || !std::isfinite(o.cn0_dbhz)) {
      ++excluded["spp: non-finite input"];
      continue;
    }
    if (opt.drop_single_sat_systems && count[clock_key(o)] == 1 && count.size() > 1) {
      ++excluded["spp: single satellite of its system"];
      continue;
    }
    out.push_back(&o);
  }
  return out;
}

/// Classical (unweighted) DOPs from the geometry; false when the geometry is singular.
bool fill_dop(const LsResult& ls, const std::vector<const SppObservation*>& obs, const Layout& l, SppSolution& s) {
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(obs.size()), l.cols);
  Eigen::Index k = 0;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const Row& r = ls.rows[i];
    if (r.masked) continue;
    h.block<1, 3>(k, 0) = -r.los.transpose();
    h(k, 3) = 1.0;
    if (isb_col(l, *obs[i]) >= 0) h(k, isb_col(l, *obs[i])) = 1.0;
    ++k;
  }
  const Eigen::MatrixXd n_mat = h.topRows(k).transpose() * h.topRows(k);
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(n_mat);
  if (!lu.isInvertible()) return false;
  const Eigen::MatrixXd q = lu.inverse();
  const Eigen::Matrix3d r = geo::ecef_to_enu_rotation(geo::to_geodetic(s.pos));
  const Eigen::Matrix3d q_enu = r * q.topLeftCorner<3, 3>() * r.transpose();
  s.gdop = std::sqrt(std::max(0.0, q.trace()));
  s.pdop = std::sqrt(std::max(0.0, q_enu.trace()));
  s.hdop = std::sqrt(std::max(0.0, q_enu(0, 0) + q_enu(1, 1)));
  s.vdop = std::sqrt(std::max(0.0, q_enu(2, 2)));
  return std::isfinite(s.gdop);
}

SppSolution to_solution(const LsResult& ls, const std::vector<const SppObservation*>& obs, const Layout& l) {
  SppSolution s;
  s.ok = true;
  s.pos = geo::Ecef(ls.x.head<3>());
  s.clock_m = ls.x(3);
  s.clock_system = l.ref.sys;
  s.clock_band = l.ref.band;
  for (const auto& [key, col] : l.isb_col) (key.band == SignalBand::kL1 ? s.isb_m : s.isb_l5_m)[key.sys] = ls.x(col);
  s.pos_cov_ecef = ls.cov.topLeftCorner<3, 3>();
  s.clock_var_m2 = ls.cov(3, 3);
  s.iterations = ls.iterations;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const Row& r = ls.rows[i];
    if (r.masked) continue;
    s.used.push_back(obs[i]->sat);
    s.residuals_m.push_back(r.residual_m);
    s.elevations_rad.push_back(r.el_rad);
    s.chi2 += r.residual_m * r.residual_m / r.var_m2;
  }
  return s;
}

/// Index (into obs) of the unmasked satellite with the largest normalised residual.
std::size_t worst_satellite(const LsResult& ls) {
  std::size_t worst = 0;
  double worst_v = -1.0;
  for (std::size_t i = 0; i < ls.rows.size(); ++i) {
    if (ls.rows[i].masked) continue;
    const double v = ls.rows[i].residual_m * ls.rows[i].residual_m / ls.rows[i].var_m2;
    if (v > worst_v) { worst_v = v; worst = i; }
  }
  return worst;
}

/// Standardised residuals t_i = v_i / sqrt(Q_vv,ii), Q_vv = W^-1 - H N^-1 H' (Baarda's w-test
/// statistic); 0 for masked rows.
std::vector<double> standardised_residuals(const LsResult& ls, const std::vector<const SppObservation*>& obs,
                                           const Layout& l) {
  std::vector<double> t(obs.size(), 0.0);
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const Row& r = ls.rows[i];
    if (r.masked) continue;
    Eigen::VectorXd h = Eigen::VectorXd::Zero(l.cols);
    h.head<3>() = -r.los;
    h(3) = 1.0;
    if (isb_col(l, *obs[i]) >= 0) h(isb_col(l, *obs[i])) = 1.0;
    const double qvv = r.var_m2 - h.dot(ls.cov * h);
    t[i] = r.residual_m / std::sqrt(std::max(qvv, 1e-6 * r.var_m2));
  }
  return t;
}

struct SubsetFit {
  bool ok = false;
  double ratio = 0.0;  // chi2 / quantile: < 1 passes the test
};

/// Refit without the satellites `drop` (indices into obs) and apply the chi-square test.
SubsetFit fit_without(const std::vector<const SppObservation*>& obs, const std::vector<std::size_t>& drop,
                      const Eigen::VectorXd& x0, double tow_s, const KlobucharParams* klob, const SppOptions& opt) {
  std::vector<const SppObservation*> sub;
  for (std::size_t i = 0; i < obs.size(); ++i)
    if (std::find(drop.begin(), drop.end(), i) == drop.end()) sub.push_back(obs[i]);
  const Layout l = make_layout(sub);
  SubsetFit f;
  if (static_cast<int>(sub.size()) < l.cols + 1) return f;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(l.cols);
  x.head<4>() = x0.head<4>();
  const LsResult ls = iterate_ls(sub, l, x, tow_s, klob, opt);
  if (!ls.ok) return f;
  double chi2 = 0.0;
  int used = 0;
  for (const Row& r : ls.rows) {
    if (r.masked) continue;
    chi2 += r.residual_m * r.residual_m / r.var_m2;
    ++used;
  }
  const int dof = used - l.cols;
  if (dof < 1) return f;
  f.ok = true;
  f.ratio = chi2 / chi_square_quantile(opt.fde_false_alarm, dof);
  return f;
}

/// The satellites to exclude (indices into obs) when the full set fails the chi-square test:
/// leave-one-out on the `fde_candidates` worst standardised residuals; if none passes, every
/// pair of them; the passing subset with the smallest chi2/quantile wins. If nothing passes,
/// the single exclusion with the smallest ratio (the loop then goes on).
std::vector<std::size_t> subset_exclusion(const LsResult& ls, const std::vector<const SppObservation*>& obs,
                                          const Layout& l, double tow_s, const KlobucharParams* klob,
                                          const SppOptions& opt, int room) {
  const std::vector<double> t = standardised_residuals(ls, obs, l);
  std::vector<std::size_t> cand;
  for (std::size_t i = 0; i < obs.size(); ++i)
    if (!ls.rows[i].masked) cand.push_back(i);
  std::sort(cand.begin(), cand.end(), [&](std::size_t a, std::size_t b) { return std::fabs(t[a]) > std::fabs(t[b]); });
  if (static_cast<int>(cand.size()) > opt.fde_candidates) cand.resize(static_cast<std::size_t>(std::max(opt.fde_candidates, 1)));
  std::vector<std::size_t> best_single;
  double best_single_ratio = std::numeric_limits<double>::infinity();
  for (std::size_t c : cand) {
    const SubsetFit f = fit_without(obs, {c}, ls.x, tow_s, klob, opt);
    if (f.ok && f.ratio < best_single_ratio) { best_single_ratio = f.ratio; best_single = {c}; }
  }
  if (best_single_ratio < 1.0 || room < 2) return best_single.empty() ? std::vector<std::size_t>{worst_satellite(ls)} : best_single;
  std::vector<std::size_t> best_pair;
  double best_pair_ratio = 1.0;
  for (std::size_t a = 0; a < cand.size(); ++a)
    for (std::size_t b = a + 1; b < cand.size(); ++b) {
      const SubsetFit f = fit_without(obs, {cand[a], cand[b]}, ls.x, tow_s, klob, opt);
      if (f.ok && f.ratio < best_pair_ratio) { best_pair_ratio = f.ratio; best_pair = {cand[a], cand[b]}; }
    }
  if (!best_pair.empty()) return best_pair;
  return best_single.empty() ? std::vector<std::size_t>{worst_satellite(ls)} : best_single;
}

/// Upper quantile z of the standard normal: P(Z > z) = p (bisection on erfc).
double normal_upper_quantile(double p) {
  double lo = -10.0, hi = 10.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (0.5 * std::erfc(mid / std::sqrt(2.0)) > p) lo = mid; else hi = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

std::vector<TruthResidual> residuals_at_truth(const std::vector<SppObservation>& obs, const geo::Ecef& truth,
                                              double gps_tow_s, const KlobucharParams* klob, const SppOptions& opt,
                                              const TruthResidualOptions& ropt) {
  std::vector<const SppObservation*> all;
  for (const auto& o : obs)
    if (std::isfinite(o.pseudorange_m) && o.state.pos.p_m.allFinite() && std::isfinite(o.cn0_dbhz)) all.push_back(&o);
  std::vector<TruthResidual> out;
  if (all.empty() || !truth.p_m.allFinite()) return out;
  const Layout l = make_layout(all);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(l.cols);  // clocks 0: estimated below
  x.head<3>() = truth.p_m;
  std::map<ClockKey, int> count;
  std::vector<Eigen::Vector3d> los;
  std::vector<ClockKey> keys;
  for (const SppObservation* o : all) {
    const Row r = model_row(*o, x, l, gps_tow_s, klob, opt);
    if (r.masked || !std::isfinite(r.residual_m)) continue;
    ++count[clock_key(*o)];
    out.push_back(TruthResidual{o->sat, o->carrier_hz, o->cn0_dbhz, r.el_rad, r.az_rad, r.residual_m, 0});
    los.push_back(r.los);
    keys.push_back(clock_key(*o));
  }
  // unknowns: one clock per kept group, then the height offset (when estimated)
  std::map<ClockKey, int> col;
  for (const auto& [g, n] : count) if (n >= std::max(2, ropt.min_group)) col.emplace(g, static_cast<int>(col.size()));
  const int p = static_cast<int>(col.size()) + (ropt.estimate_height ? 1 : 0);
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < out.size(); ++i) if (col.count(keys[i])) rows.push_back(i);
  const int n = static_cast<int>(rows.size());
  if (col.empty() || n <= p) return {};
  const Eigen::Vector3d up = truth.p_m.normalized();
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(n, p);
  Eigen::VectorXd y(n), w = Eigen::VectorXd::Ones(n), e(n);
  for (int k = 0; k < n; ++k) {
    const TruthResidual& t = out[rows[static_cast<std::size_t>(k)]];
    h(k, col.at(keys[rows[static_cast<std::size_t>(k)]])) = 1.0;
    if (ropt.estimate_height) h(k, p - 1) = -los[rows[static_cast<std::size_t>(k)]].dot(up);
    y(k) = t.residual_m;
  }
  // least absolute deviations by iteratively reweighted least squares (w = 1 / max(|e|, 0.1 m)):
  // the clocks follow the median satellite, not the multipath tails; 20 reweightings, then the
  // solution with the last weights
  Eigen::VectorXd sol;
  for (int pass = 0;; ++pass) {
    const Eigen::MatrixXd hw = w.asDiagonal() * h;
    sol = (h.transpose() * hw).ldlt().solve(hw.transpose() * y);
    if (pass == 20) break;
    e = y - h * sol;
    for (int k = 0; k < n; ++k) w(k) = 1.0 / std::max(std::fabs(e(k)), 0.1);
  }
  // Each residual against its group's clock from the *other* satellites (leave-one-out median
  // of the height-corrected codes): no residual is forced to zero by the fit, and the variance
  // the median adds is divided out: var(median of m) = sigma^2 / 2 for m = 2, ~pi sigma^2 / (2 m)
  // beyond (Kenney & Keeping 1962, the median's asymptotic variance).
  Eigen::VectorXd yh = y;
  if (ropt.estimate_height) yh -= h.col(p - 1) * sol(p - 1);
  std::vector<TruthResidual> kept;
  for (int k = 0; k < n; ++k) {
    TruthResidual t = out[rows[static_cast<std::size_t>(k)]];
    const ClockKey g = keys[rows[static_cast<std::size_t>(k)]];
    std::vector<double> others;
    for (int j = 0; j < n; ++j)
      if (j != k && keys[rows[static_cast<std::size_t>(j)]] == g) others.push_back(yh(j));
    const std::size_t m = others.size();
    std::nth_element(others.begin(), others.begin() + static_cast<std::ptrdiff_t>(m / 2), others.end());
    double clock = others[m / 2];
    if (m % 2 == 0) clock = 0.5 * (clock + *std::max_element(others.begin(), others.begin() + static_cast<std::ptrdiff_t>(m / 2)));
    const double added = m == 2 ? 0.5 : kPi / (2.0 * static_cast<double>(m));
    t.residual_m = (yh(k) - clock) / std::sqrt(1.0 + added);
    t.group_size = count.at(g);
    kept.push_back(t);
  }
  return kept;
}

double chi_square_quantile(double p_false_alarm, int dof) {
  if (dof < 1 || !(p_false_alarm > 0.0 && p_false_alarm < 1.0)) return kNaN;
  if (dof == 1) { const double z = normal_upper_quantile(0.5 * p_false_alarm); return z * z; }  // exact
  if (dof == 2) return -2.0 * std::log(p_false_alarm);                                              // exact
  const double z = normal_upper_quantile(p_false_alarm);
  const double k = dof;
  const double t = 1.0 - 2.0 / (9.0 * k) + z * std::sqrt(2.0 / (9.0 * k));
  return k * t * t * t;
}

Eigen::Vector3d rotate_for_travel_time(const Eigen::Vector3d& sat_ecef_m, double travel_s) {
  const double a = geo::Wgs84::omega_e_radps * travel_s;
  const double c = std::cos(a), s = std::sin(a);
  return {c * sat_ecef_m.x() + s * sat_ecef_m.y(), -s * sat_ecef_m.x() + c * sat_ecef_m.y(), sat_ecef_m.z()};
}

std::map<Constellation, int> SppSolution::used_by_sys() const {
  std::map<Constellation, int> m;
  for (const SatId& s : used) ++m[s.sys];
  return m;
}

SppSolution solve_spp(const std::vector<SppObservation>& all, const geo::Ecef& initial, double gps_tow_s,
                      const KlobucharParams* klob, const SppOptions& opt) {
  std::map<std::string, std::int64_t> excluded;
  std::vector<const SppObservation*> obs = usable(all, opt, excluded);
  std::vector<SatId> fde;
  auto fail = [&](const std::string& why) {
    SppSolution s;
    s.reason = why;
    s.excluded = excluded;
    s.excluded_fde = fde;
    return s;
  };
  if (obs.size() < 4) return fail("fewer than 4 satellites");
  // the mask needs a position: a first fit without it, then drop low satellites and refit
  SppOptions no_mask = opt;
  no_mask.elevation_mask_deg = -90.0;
  geo::Ecef start = initial;
  {
    const Layout l0 = make_layout(obs);
    if (static_cast<int>(obs.size()) < l0.cols) return fail("fewer satellites than unknowns");
    const LsResult coarse = iterate_ls(obs, l0, initial_state(l0, initial), gps_tow_s, klob, no_mask);
    if (!coarse.ok) return fail(coarse.reason);
    start = geo::Ecef(coarse.x.head<3>());
    std::vector<const SppObservation*> kept;
    for (std::size_t i = 0; i < obs.size(); ++i) {
      if (coarse.rows[i].el_rad < deg_to_rad(opt.elevation_mask_deg)) ++excluded["spp: below elevation mask"];
      else kept.push_back(obs[i]);
    }
    obs = kept;
    if (obs.size() < 4) return fail("fewer than 4 satellites above the mask");
  }
  for (;;) {
    const Layout l = make_layout(obs);
    if (static_cast<int>(obs.size()) < l.cols) return fail("fewer satellites than unknowns");
    const LsResult ls = iterate_ls(obs, l, initial_state(l, start), gps_tow_s, klob, no_mask);
    if (!ls.ok) return fail(ls.reason);
    int used = 0;
    for (const Row& r : ls.rows) used += r.masked ? 0 : 1;
    SppSolution s = to_solution(ls, obs, l);
    if (!fill_dop(ls, obs, l, s) || !(s.gdop < opt.max_gdop)) return fail("singular geometry (GDOP)");
    const int dof = used - l.cols;
    const bool test_fails = dof >= 1 && s.chi2 > chi_square_quantile(opt.fde_false_alarm, dof);
    if (!test_fails && opt.robust_igg3 && dof >= 1) {
      // IGG-III reweighting of the consistent set (moderate multipath the test lets through)
      std::vector<double> scale(obs.size(), 1.0);
      LsResult cur = ls;
      bool changed = false;
      for (int pass = 0; pass < 5; ++pass) {
        const std::vector<double> t = standardised_residuals(cur, obs, l);
        bool moved = false;
        for (std::size_t i = 0; i < obs.size(); ++i) {
          if (cur.rows[i].masked) continue;
          // a zero weight becomes a 1e4 variance factor (100 sigma): kept in the geometry, no pull
          const double w = std::max(igg3_weight(t[i], opt.igg_k0, opt.igg_k1), 1e-4);
          const double ns = scale[i] / w;
          if (std::fabs(ns / scale[i] - 1.0) > 1e-3) moved = true;
          scale[i] = std::min(ns, 1e4);
        }
        if (!moved) break;
        const LsResult next = iterate_ls(obs, l, cur.x, gps_tow_s, klob, no_mask, &scale);
        if (!next.ok) break;
        cur = next;
        changed = true;
      }
      if (changed) {
        SppSolution r = to_solution(cur, obs, l);
        if (fill_dop(cur, obs, l, r) && r.gdop < opt.max_gdop) {
          for (double v : scale) r.downweighted += v > 1.0 + 1e-9 ? 1 : 0;
          if (r.downweighted > 0) excluded["spp: IGG-III down-weighted"] += r.downweighted;
          s = r;
        }
      }
    }
    if (!test_fails || static_cast<int>(fde.size()) >= opt.max_fde_exclusions || dof < 2) {
      s.excluded = excluded;
      s.excluded_fde = fde;
      if (test_fails) {
        // no consistent subset was found: the fix cannot be trusted (counted by the caller)
        s.ok = false;
        s.reason = dof < 2 ? "residual test failed, too few satellites to exclude"
                           : "residual test failed after exclusions";
      }
      return s;
    }
    std::vector<std::size_t> drop;
    if (opt.fde == SppFde::kSubsets)
      drop = subset_exclusion(ls, obs, l, gps_tow_s, klob, opt, std::min(opt.max_fde_exclusions - static_cast<int>(fde.size()), dof - 1));
    else
      drop = {worst_satellite(ls)};
    std::sort(drop.rbegin(), drop.rend());  // erase from the back
    for (std::size_t i : drop) {
      fde.push_back(obs[i]->sat);
      ++excluded["spp: FDE residual test"];
      obs.erase(obs.begin() + static_cast<std::ptrdiff_t>(i));
    }
  }
}

}  // namespace pdnav::gnss
