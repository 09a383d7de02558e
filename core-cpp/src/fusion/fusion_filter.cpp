#include "pdnav/fusion/fusion_filter.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "reason_text.h"

namespace pdnav::fusion {

namespace {
/// Upper-tail standard normal quantile, Abramowitz & Stegun 26.2.23 (|error| < 4.5e-4).
double normal_quantile(double p) {
  const double q = p < 0.5 ? p : 1.0 - p;
  const double t = std::sqrt(-2.0 * std::log(q));
  const double z = t - (2.515517 + 0.802853 * t + 0.010328 * t * t) / (1.0 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t);
  return p < 0.5 ? -z : z;
}

using detail::fmt;
}  // namespace

double chi2_quantile(int dof, double p) {
  const double k = std::max(1, dof);
  const double z = normal_quantile(p);
  const double a = 2.0 / (9.0 * k);
  const double v = 1.0 - a + z * std::sqrt(a);
  return k * v * v * v;
}

void FusionFilter::initialize(const Eigen::Vector2d& en_m, double sigma_m, TimeNs t_ns) {
  x_.setZero();
  x_.head<2>() = en_m;
  x_.tail<2>() = en_m;
  p_.setZero();
  const double v = sigma_m * sigma_m;
  p_(0, 0) = p_(1, 1) = v;
  p_(2, 2) = opt_.initial_heading_bias_sigma_rad * opt_.initial_heading_bias_sigma_rad;
  p_(3, 3) = opt_.initial_scale_sigma * opt_.initial_scale_sigma;
  p_.block<2, 2>(4, 4) = p_.block<2, 2>(0, 0);
  p_.block<2, 2>(0, 4) = p_.block<2, 2>(0, 0);
  p_.block<2, 2>(4, 0) = p_.block<2, 2>(0, 0);
  t_ns_ = t_ns;
  last_step_ns_ = t_ns;
  clone_ok_ = false;
  recent_.clear();
  rejected_.clear();
  reacq_.clear();
  scale_calibrated_ = false;
  initialized_ = true;
}

void FusionFilter::symmetrize() { p_ = 0.5 * (p_ + p_.transpose()).eval(); }

void FusionFilter::advance_to(TimeNs t_ns) {
  if (!initialized_ || t_ns <= t_ns_) return;
  // undetected motion: only the part of (t_ns_, t_ns] beyond undetected_after_s since the last step
  const TimeNs quiet_from = last_step_ns_ + static_cast<TimeNs>(opt_.undetected_after_s * 1e9);
  const TimeNs a = std::max(t_ns_, quiet_from);
  if (t_ns > a) {
    // (a, t_ns]: while motion sensors ran, steps were observed and none came (standing,
    // shuffling); beyond blind_after_s after the last of their samples the motion is unobserved
    const TimeNs blind_start = !track_sensing_ ? t_ns
                               : last_sensing_ns_ < 0 ? a
                                                      : last_sensing_ns_ + static_cast<TimeNs>(opt_.blind_after_s * 1e9);
    const TimeNs b = std::clamp(blind_start, a, t_ns);
    const double q = opt_.undetected_motion_q_m2ps * static_cast<double>(b - a) * 1e-9 +
                     opt_.blind_motion_q_m2ps * static_cast<double>(t_ns - b) * 1e-9;
    p_(0, 0) += q;
    p_(1, 1) += q;
  }
  const double dt_all = static_cast<double>(t_ns - t_ns_) * 1e-9;
  // first-order Gauss-Markov residual states: decay towards 0, variance towards the stationary one
  if (heading_bias_gauss_markov())
    gauss_markov_step(2, dt_all, opt_.heading_bias_tau_s, heading_stationary_var_);
  p_(2, 2) += opt_.heading_bias_rw_rad2ps * dt_all;
  if (opt_.scale_tau_s > 0.0)
    gauss_markov_step(3, dt_all, opt_.scale_tau_s, scale_stationary_var());
  else
    p_(3, 3) += opt_.scale_rw_1ps * dt_all;  // the random walk only without the Gauss-Markov model
  t_ns_ = t_ns;
}

void FusionFilter::gauss_markov_step(int k, double dt_s, double tau_s, double stationary_var) {
  const double phi = std::exp(-dt_s / tau_s);
  x_(k) *= phi;
  for (int i = 0; i < 6; ++i)
    if (i != k) p_(k, i) *= phi, p_(i, k) *= phi;
  p_(k, k) = phi * phi * p_(k, k) + stationary_var * (1.0 - phi * phi);
}

void FusionFilter::predict(const PdrStep& s) {
  if (!initialized_ || !std::isfinite(s.length_m) || !std::isfinite(s.heading_rad)) return;
  const bool gm = opt_.heading_bias_tau_s > 0.0;
  if (gm && std::isfinite(s.heading_sigma_rad) && s.heading_sigma_rad > 0.0)
    heading_stationary_var_ = std::min(kPi, s.heading_sigma_rad) * std::min(kPi, s.heading_sigma_rad);
  advance_to(s.t_ns);
  const double psi = s.heading_rad - x_(2);
  const double len = (1.0 + x_(3)) * s.length_m;
  const double sp = std::sin(psi), cp = std::cos(psi);
  const Eigen::Vector2d d(len * sp, len * cp);
  Mat6 f = Mat6::Identity();
  f(0, 2) = -len * cp;
  f(1, 2) = len * sp;
  f(0, 3) = s.length_m * sp;
  f(1, 3) = s.length_m * cp;
  const double sl = std::max(opt_.min_step_length_sigma_m, std::isfinite(s.length_sigma_m) ? s.length_sigma_m : 0.0);
  const double sh = gm ? opt_.min_step_heading_sigma_rad
                      : std::max(opt_.min_step_heading_sigma_rad, std::isfinite(s.heading_sigma_rad) ? s.heading_sigma_rad : 0.0);
  Eigen::Matrix2d g;
  g << sp, len * cp, cp, -len * sp;
  const Eigen::Matrix2d q = g * Eigen::Vector2d(sl * sl, sh * sh).asDiagonal() * g.transpose();
  x_.head<2>() += d;
  p_ = (f * p_ * f.transpose()).eval();
  p_.topLeftCorner<2, 2>() += q;
  symmetrize();
  last_step_ns_ = s.t_ns;
  recent_.push_back({s.t_ns, d, q.trace() * 0.5});
  while (recent_.size() > 64 || (!recent_.empty() && recent_.front().t_ns < s.t_ns - 30 * kNsPerS)) recent_.pop_front();
}

void FusionFilter::set_residual_uncertainty(double var_b, double var_s) {
  if (!initialized_) return;
  // fold the old residual estimate into nothing: the new calibration replaces it
  scale_calibrated_ = true;
  x_(2) = 0.0;
  x_(3) = 0.0;
  for (int i = 0; i < 6; ++i) {
    if (i == 2 || i == 3) continue;
    p_(2, i) = p_(i, 2) = 0.0;
    p_(3, i) = p_(i, 3) = 0.0;
  }
  p_(2, 3) = p_(3, 2) = 0.0;
  p_(2, 2) = std::max(var_b, 1e-8);
  p_(3, 3) = std::max(var_s, 1e-8);
}

namespace {
/// Variance of a first-order Gauss-Markov process (stationary variance var, correlation time
/// tau_s) now, about its mean over the window_s before: var g(W / tau) with
/// g(u) = 1 - 2 (1 - e^-u) / u + 2 (u - 1 + e^-u) / u^2 (the autocovariance integrated over the window).
double gm_var_about_window_mean(double var, double window_s, double tau_s) {
  const double u = window_s / tau_s;
  const double eu = std::exp(-u);
  const double g = u < 1e-3 ? u / 3.0 : 1.0 - 2.0 * (1.0 - eu) / u + 2.0 * (u - 1.0 + eu) / (u * u);
  return std::clamp(g, 0.0, 1.0) * var;
}
}  // namespace

double FusionFilter::heading_bias_var_after_window(double fit_var, double window_s) const {
  if (!heading_bias_gauss_markov() || !(window_s > 0.0)) return fit_var;
  return fit_var + gm_var_about_window_mean(heading_stationary_var_, window_s, opt_.heading_bias_tau_s);
}

double FusionFilter::heading_bias_expected(double calibrated_rad, double age_s) const {
  if (!heading_bias_gauss_markov() || !(age_s > 0.0)) return calibrated_rad;
  return calibrated_rad * std::exp(-age_s / opt_.heading_bias_tau_s);
}

double FusionFilter::scale_within_walk_var() const {
  const double s = opt_.scale_within_walk_sigma > 0.0 ? opt_.scale_within_walk_sigma : opt_.initial_scale_sigma;
  return s * s;
}

double FusionFilter::scale_stationary_var() const {
  return scale_calibrated_ ? scale_within_walk_var() : opt_.initial_scale_sigma * opt_.initial_scale_sigma;
}

double FusionFilter::scale_var_after_window(double fit_var, double window_s) const {
  if (!(opt_.scale_tau_s > 0.0) || !(window_s > 0.0)) return fit_var;
  // the window's scale wanders within the walk (the fit has learnt the walker's constant)
  return fit_var + gm_var_about_window_mean(scale_within_walk_var(), window_s, opt_.scale_tau_s);
}

void FusionFilter::after(TimeNs t_ns, Eigen::Vector2d* d, double* var) const {
  d->setZero();
  *var = 0.0;
  for (const Recent& r : recent_)
    if (r.t_ns > t_ns) {
      *d += r.d_en_m;
      *var += r.var_m2;
    }
}

void FusionFilter::apply_position(const Eigen::Vector2d& z, const Eigen::Matrix2d& r) {
  Eigen::Matrix<double, 2, 6> h = Eigen::Matrix<double, 2, 6>::Zero();
  h(0, 0) = h(1, 1) = 1.0;
  const Eigen::Matrix2d s = h * p_ * h.transpose() + r;
  Eigen::Matrix<double, 6, 2> k = p_ * h.transpose() * s.inverse();
  if (opt_.consider_pdr_states_on_position) k.middleRows<2>(2).setZero();  // Schmidt: consider states
  x_ += k * (z - h * x_);
  const Mat6 ikh = Mat6::Identity() - k * h;
  p_ = (ikh * p_ * ikh.transpose() + k * r * k.transpose()).eval();  // Joseph form
  symmetrize();
  // correlated-error floor: smallest eigenvalue of P_pos >= fraction x the smallest of R
  const Eigen::Matrix2d pp = p_.topLeftCorner<2, 2>();
  const double tr = pp.trace(), det = pp.determinant();
  const double lmin = 0.5 * tr - std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
  const double rtr = r.trace(), rdet = r.determinant();
  const double rmin = 0.5 * rtr - std::sqrt(std::max(0.0, 0.25 * rtr * rtr - rdet));
  const double floor = (floor_fraction_ >= 0.0 ? floor_fraction_ : opt_.position_floor_fraction) * rmin;
  if (lmin < floor) {
    p_(0, 0) += floor - lmin;
    p_(1, 1) += floor - lmin;
  }
}

bool FusionFilter::agree(const std::vector<Held>& h, Eigen::Vector2d* mean_nu) const {
  Eigen::Matrix2d w_sum = Eigen::Matrix2d::Zero();
  Eigen::Vector2d wz = Eigen::Vector2d::Zero();
  for (const Held& x : h) {
    const Eigen::Matrix2d w = x.r.inverse();
    w_sum += w;
    wz += w * x.nu;
  }
  const Eigen::Vector2d m = w_sum.inverse() * wz;
  double chi2 = 0.0;
  for (const Held& x : h) chi2 += (x.nu - m).dot(x.r.inverse() * (x.nu - m));
  *mean_nu = m;
  return chi2 <= chi2_quantile(2 * (static_cast<int>(h.size()) - 1), opt_.agreement_p);
}

bool FusionFilter::carry_to_last_step(TimeNs t_ns, const Eigen::Vector2d& z_en_m, const Eigen::Matrix2d& r_in,
                                      Eigen::Vector2d* z, Eigen::Matrix2d* r, PositionUpdateResult* res) {
  if (!initialized_ || !z_en_m.allFinite() || !r_in.allFinite() || !(r_in.determinant() > 0.0)) {
    res->reason = "invalid measurement";
    return false;
  }
  advance_to(t_ns);
  Eigen::Vector2d d_after;
  double var_after = 0.0;
  after(t_ns, &d_after, &var_after);
  *z = z_en_m + d_after;  // the measurement carried to the last step
  *r = r_in + var_after * Eigen::Matrix2d::Identity();
  return true;
}

PositionUpdateResult FusionFilter::update_position(TimeNs t_ns, const Eigen::Vector2d& z_en_m, const Eigen::Matrix2d& r_in,
                                                   bool use_gate_policy, double floor_fraction) {
  PositionUpdateResult res;
  floor_fraction_ = floor_fraction;
  Eigen::Vector2d z;
  Eigen::Matrix2d r;
  if (!carry_to_last_step(t_ns, z_en_m, r_in, &z, &r, &res)) return res;
  const Eigen::Vector2d nu = z - x_.head<2>();
  const Eigen::Matrix2d s = p_.topLeftCorner<2, 2>() + r;
  res.nis = nu.dot(s.inverse() * nu);
  res.innovation_m = nu.norm();
  if (!use_gate_policy) {
    if (res.nis > opt_.gate_chi2) {
      res.reason = "rejected: innovation " + fmt(res.innovation_m) + " m = " + fmt(std::sqrt(res.nis)) + " sigma";
      return res;
    }
    apply_position(z, r);
    res.accepted = true;
    res.reason = "accepted";
    return res;
  }
  const bool outage = last_accept_ns_ < 0 || t_ns - last_accept_ns_ > static_cast<TimeNs>(opt_.reacquire_after_s * 1e9);
  const Held held{t_ns, z, nu, r};
  if (res.nis <= opt_.gate_chi2) {
    rejected_.clear();
    if (outage && opt_.reacquire_epochs > 1) {
      reacq_.push_back(held);
      while (reacq_.size() > static_cast<std::size_t>(opt_.reacquire_epochs)) reacq_.erase(reacq_.begin());
      Eigen::Vector2d m;
      if (reacq_.size() < static_cast<std::size_t>(opt_.reacquire_epochs) || !agree(reacq_, &m)) {
        res.reason = "re-acquisition: waiting for " + std::to_string(opt_.reacquire_epochs) + " agreeing epochs";
        return res;
      }
      res.reacquired = true;
      res.reason = std::string(last_accept_ns_ < 0 ? "acquired: " : "re-acquired: ") + std::to_string(reacq_.size()) + " agreeing epochs, offset " + fmt(m.norm()) + " m";
      reacq_.clear();
    } else {
      res.reason = "accepted";
    }
    apply_position(z, r);
    res.accepted = true;
    last_accept_ns_ = t_ns;
    return res;
  }
  // failed the gate: hold it; consistent disagreement over a window is a real correction
  reacq_.clear();
  rejected_.push_back(held);
  const TimeNs win = static_cast<TimeNs>(opt_.confirm_window_s * 1e9);
  while (!rejected_.empty() && rejected_.front().t_ns < t_ns - win) rejected_.erase(rejected_.begin());
  while (rejected_.size() > static_cast<std::size_t>(opt_.confirm_epochs)) rejected_.erase(rejected_.begin());
  Eigen::Vector2d m;
  if (rejected_.size() >= static_cast<std::size_t>(opt_.confirm_epochs) && agree(rejected_, &m)) {
    // the prediction, not GNSS, is wrong: widen the position covariance by the agreed offset
    p_.topLeftCorner<2, 2>() += m * m.transpose();
    p_.block<2, 2>(4, 4) += m * m.transpose();
    apply_position(z, r);
    res.accepted = true;
    res.forced = true;
    res.reacquired = outage;
    res.reason = "GNSS disagreed consistently for " + std::to_string(rejected_.size()) + " epochs by " + fmt(m.norm()) +
                 " m: accepted as a real correction";
    rejected_.clear();
    last_accept_ns_ = t_ns;
    return res;
  }
  res.reason = "rejected: innovation " + fmt(res.innovation_m) + " m = " + fmt(std::sqrt(res.nis)) + " sigma (" +
               std::to_string(rejected_.size()) + " in a row)";
  return res;
}

PositionUpdateResult FusionFilter::update_position_ci(TimeNs t_ns, const Eigen::Vector2d& z_en_m,
                                                      const Eigen::Matrix2d& r_in) {
  PositionUpdateResult res;
  Eigen::Vector2d z;
  Eigen::Matrix2d r;
  if (!carry_to_last_step(t_ns, z_en_m, r_in, &z, &r, &res)) return res;
  const Eigen::Vector2d nu = z - x_.head<2>();
  const Eigen::Matrix2d pp = p_.topLeftCorner<2, 2>();
  res.nis = nu.dot((pp + r).inverse() * nu);
  res.innovation_m = nu.norm();
  if (res.nis > opt_.gate_chi2) {
    res.reason = "rejected: innovation " + fmt(res.innovation_m) + " m = " + fmt(std::sqrt(res.nis)) + " sigma";
    return res;
  }
  if (!(pp.determinant() > 0.0)) {
    res.reason = "invalid filter covariance";
    return res;
  }
  // w minimising det((w Pp^-1 + (1 - w) R^-1)^-1), i.e. maximising det(w Pp^-1 + (1 - w) R^-1):
  // log det is concave in w, golden-section search on [0, 1]
  const Eigen::Matrix2d pi = pp.inverse(), ri = r.inverse();
  auto f = [&](double w) { return (w * pi + (1.0 - w) * ri).determinant(); };
  double a = 0.0, b = 1.0;
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - g * (b - a), d = a + g * (b - a), fc = f(c), fd = f(d);
  for (int i = 0; i < 40; ++i) {
    if (fc > fd) b = d, d = c, fd = fc, c = b - g * (b - a), fc = f(c);
    else a = c, c = d, fc = fd, d = a + g * (b - a), fd = f(d);
  }
  const double w = std::clamp(0.5 * (a + b), 0.0, 1.0);
  constexpr double kMaxW = 0.999;  // the measurement adds (almost) nothing: not used
  if (w >= kMaxW) {
    res.accepted = true;
    res.reason = "accepted (covariance intersection: no information beyond the prediction)";
    return res;
  }
  const double w_eff = std::max(w, 1e-3);
  const double sw = 1.0 / std::sqrt(w_eff);
  for (int i = 0; i < 6; ++i) {
    if (i < 2) continue;
    p_(0, i) *= sw, p_(1, i) *= sw, p_(i, 0) *= sw, p_(i, 1) *= sw;
  }
  p_.topLeftCorner<2, 2>() /= w_eff;
  const double fl = floor_fraction_;
  floor_fraction_ = 0.0;  // no correlated-error floor: the intersection is already conservative
  apply_position(z, r / (1.0 - w_eff));
  floor_fraction_ = fl;
  res.accepted = true;
  res.reason = "accepted (covariance intersection, w " + fmt(w, 2) + ")";
  return res;
}

bool FusionFilter::update_scale(TimeNs t_ns, double ds, double var, double* nis_out) {
  if (!initialized_ || !std::isfinite(ds) || !(var > 0.0) || !std::isfinite(var)) return false;
  advance_to(t_ns);
  const double nu = ds - x_(3);
  const double s = p_(3, 3) + var;
  const double nis = nu * nu / s;
  if (nis_out) *nis_out = nis;
  if (nis > opt_.scale_gate_chi2) return false;
  // only ds moves (Schmidt: the position is the position measurements' business; the map's turns
  // already reached it through the route engine's estimate); the Joseph form keeps P right
  Vec6 k = Vec6::Zero();
  k(3) = p_(3, 3) / s;
  x_ += k * nu;
  Mat6 ikh = Mat6::Identity();
  ikh.col(3) -= k;
  p_ = (ikh * p_ * ikh.transpose() + var * k * k.transpose()).eval();
  symmetrize();
  return true;
}

bool FusionFilter::update_displacement(TimeNs t_ns, TimeNs from_ns, const Eigen::Vector2d& d_en_m, const Eigen::Matrix2d& r_in,
                                       double* nis_out) {
  if (!initialized_ || !clone_ok_ || std::llabs(from_ns - clone_t_ns_) > 50 * kNsPerMs || !d_en_m.allFinite() ||
      !r_in.allFinite())
    return false;
  advance_to(t_ns);
  Eigen::Vector2d d_after;
  double var_after = 0.0;
  after(t_ns, &d_after, &var_after);
  const Eigen::Vector2d z = d_en_m + d_after;
  const Eigen::Matrix2d r = r_in + var_after * Eigen::Matrix2d::Identity();
  Eigen::Matrix<double, 2, 6> h = Eigen::Matrix<double, 2, 6>::Zero();
  h(0, 0) = h(1, 1) = 1.0;
  h(0, 4) = h(1, 5) = -1.0;
  const Eigen::Vector2d nu = z - h * x_;
  const Eigen::Matrix2d s = h * p_ * h.transpose() + r;
  const double nis = nu.dot(s.inverse() * nu);
  if (nis_out) *nis_out = nis;
  if (nis > opt_.displacement_gate_chi2) return false;
  const Eigen::Matrix<double, 6, 2> k = p_ * h.transpose() * s.inverse();
  x_ += k * nu;
  const Mat6 ikh = Mat6::Identity() - k * h;
  p_ = (ikh * p_ * ikh.transpose() + k * r * k.transpose()).eval();
  symmetrize();
  return true;
}

void FusionFilter::clone(TimeNs t_ns) {
  if (!initialized_) return;
  Eigen::Vector2d d_after;
  double var_after = 0.0;
  after(t_ns, &d_after, &var_after);
  // clone = position at t_ns = current - steps after t_ns (their noise is added on use)
  x_.tail<2>() = x_.head<2>() - d_after;
  p_.block<2, 6>(4, 0) = p_.block<2, 6>(0, 0);
  p_.block<6, 2>(0, 4) = p_.block<6, 2>(0, 0);
  p_.block<2, 2>(4, 4) = p_.block<2, 2>(0, 0);
  clone_t_ns_ = t_ns;
  clone_ok_ = true;
}

AidAssociation associate(const Eigen::Vector2d& x_en_m, const Eigen::Matrix2d& p_m2,
                         const std::vector<AidHypothesis>& hypotheses) {
  AidAssociation out;
  double best = 0.0, second = 0.0;
  for (std::size_t k = 0; k < hypotheses.size(); ++k) {
    const AidHypothesis& h = hypotheses[k];
    const Eigen::Matrix2d s = p_m2 + h.r_m2;
    const double det = s.determinant();
    if (!(det > 0.0) || !(h.weight > 0.0) || !h.z_en_m.allFinite()) continue;
    const Eigen::Vector2d nu = h.z_en_m - x_en_m;
    const double w = h.weight * std::exp(-0.5 * nu.dot(s.inverse() * nu)) / std::sqrt(det);
    if (w > best) {
      second = best;
      best = w;
      out.index = static_cast<int>(k);
    } else if (w > second) {
      second = w;
    }
  }
  if (out.index >= 0 && best > 0.0) out.runner_up = second / best;
  else out.index = -1;
  return out;
}

}  // namespace pdnav::fusion
