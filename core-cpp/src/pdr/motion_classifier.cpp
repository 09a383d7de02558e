// Motion classifier (docs/pdr.md, "Motion classifier").
#include "pdnav/pdr/motion_classifier.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "autocorrelation.h"

namespace pdnav::pdr {

const char* to_string(MotionState m) {
  switch (m) {
    case MotionState::kWalking: return "walking";
    case MotionState::kHandling: return "handling";
    case MotionState::kVehicle: return "vehicle";
    case MotionState::kStanding: break;
  }
  return "standing";
}

MotionClassifier::MotionClassifier(const MotionClassifierOptions& options)
    : opt_(options),
      acc_(options.window_s),
      gyro_(options.window_s, Eigen::Matrix3d::Zero()),
      field_rate_sq_(options.window_s, 0.0),
      kin_h_(options.kinematic_window_s, Eigen::Vector3d::Zero()) {}

void MotionClassifier::feed(const AccelSample& s) {
  const double m = s.acc_mps2.norm();
  if (!std::isfinite(m) || (last_acc_ns_ >= 0 && s.t_ns <= last_acc_ns_)) return;
  last_acc_ns_ = s.t_ns;
  acc_.push(s.t_ns, m);
  kinematic_accel(s);
  vehicle_sample(s.t_ns, m, nullptr);
  if (acc_.size() < 4) return;
  update(s.t_ns);
}

void MotionClassifier::feed(const GyroSample& s) {
  if (!s.rate_radps.allFinite() || (last_gyro_ns_ >= 0 && s.t_ns <= last_gyro_ns_)) return;
  kinematic_gyro(s);  // (reads the previous sample's time)
  last_gyro_ns_ = s.t_ns;
  vehicle_sample(s.t_ns, kNaN, &s.rate_radps);
  gyro_.push(s.t_ns, s.rate_radps * s.rate_radps.transpose());
  const Eigen::Matrix3d c = gyro_.sum() / static_cast<double>(gyro_.size());
  rate_rms_ = std::sqrt(std::max(0.0, c.trace()));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(c, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d ev = es.eigenvalues();  // ascending
  spread_ = ev[2] > 1e-12 ? std::max(0.0, ev[1]) / ev[2] : 0.0;
  update(s.t_ns);
}

void MotionClassifier::feed_field_rate(TimeNs t_ns, const Eigen::Vector3d& rate_radps) {
  if (!(opt_.field_rate_fraction > 0.0) || !rate_radps.allFinite()) return;
  if (last_field_rate_ns_ >= 0 && t_ns <= last_field_rate_ns_) return;
  if (last_field_rate_ns_ >= 0 && !live(last_field_rate_ns_, t_ns)) field_rate_sq_.clear();  // a gap: the window restarts
  last_field_rate_ns_ = t_ns;
  // the strikes' coherence (running exit) reads it as it reads a gyroscope
  vehicle_sample(t_ns, kNaN, &rate_radps);
  field_rate_sq_.push(t_ns, rate_radps.squaredNorm());
  update(t_ns);
}

void MotionClassifier::update(TimeNs t_ns) {
  const bool gyro_live = live(last_gyro_ns_, t_ns) && gyro_.size() >= 4;
  // the handling tests with the rates scaled by f (1: handling, suspect_fraction: suspicion)
  const auto turns_like_handling = [&](double f) {
    return gyro_live && ((rate_rms_ > f * opt_.handling_rate_radps && spread_ > opt_.axis_spread_min) ||
                         rate_rms_ > f * opt_.extreme_rate_radps);
  };
  // without a gyroscope, the rate square to the field (feed_field_rate): its RMS alone, and no
  // suspicion (the runs reach suspect_fraction of the test: MotionClassifierOptions::field_rate_fraction)
  const bool field_live = !gyro_live && live(last_field_rate_ns_, t_ns) && field_rate_sq_.size() >= 4;
  const bool field_turns_like_handling =
      field_live && std::sqrt(std::max(0.0, field_rate_sq_.sum() / static_cast<double>(field_rate_sq_.size()))) >
                        opt_.extreme_rate_radps * opt_.field_rate_fraction;
  const double sigma = acc_.size() >= 4 ? acc_.sigma() : 0.0;  // of |a| over the last window
  // running: turns like handling, but with periodic foot strikes and a rotation that keeps
  // their rhythm (MotionClassifierOptions::running_min_coherence): gait, not handling. The
  // strikes' periodicity enters a run; the rhythm keeps it, and the hold_s after it as for handling.
  const bool keeps_rhythm = opt_.vehicle && opt_.running_min_coherence > 0.0 &&
                            sigma >= opt_.running_min_sigma_mps2 && gait_coherence_ >= opt_.running_min_coherence;
  running_state_ = keeps_rhythm && (running_state_ || gait_corr_ >= opt_.gait_exit_min);
  const bool handling_now = turns_like_handling(1.0) || field_turns_like_handling;
  if (running_state_ && handling_now) running_last_ns_ = t_ns;
  const bool gait = running_state_ || ran_within_hold(t_ns);
  handling_raw_ = !gait && handling_now;
  suspect_ = !gait && turns_like_handling(opt_.suspect_fraction);
  // a session's first second (or after a gyro gap): no full window of evidence either way
  young_ = !gyro_.empty() && gyro_.covered_s() < 0.8 * opt_.window_s;
  if (handling_raw_) handling_last_ns_ = t_ns;
  const bool handling = handling_last_ns_ >= 0 && ns_to_s(t_ns - handling_last_ns_) <= opt_.hold_s;
  if (handling) {
    state_ = MotionState::kHandling;
    if (!span_open_) {
      // the features look back one window: the motion began up to a window earlier
      spans_.push_back(MotionSpan{t_ns - s_to_ns(opt_.window_s), t_ns, MotionState::kHandling});
      if (spans_.size() > 256) spans_.pop_front();
      span_open_ = true;
    }
    spans_.back().t_end_ns = t_ns;
    return;
  }
  span_open_ = false;
  if (vehicle_) {
    state_ = MotionState::kVehicle;
    return;
  }
  const bool still = sigma < opt_.standing_sigma_mps2 && (!gyro_live || rate_rms_ < opt_.standing_rate_radps);
  state_ = still ? MotionState::kStanding : MotionState::kWalking;
}

namespace {
bool inside(const std::deque<MotionSpan>& spans, TimeNs t_ns) {
  for (auto it = spans.rbegin(); it != spans.rend(); ++it) {
    if (t_ns >= it->t_start_ns && t_ns <= it->t_end_ns) return true;
    if (it->t_end_ns < t_ns) break;
  }
  return false;
}
}  // namespace

bool MotionClassifier::handling_at(TimeNs t_ns) const { return inside(spans_, t_ns); }

bool MotionClassifier::vehicle_at(TimeNs t_ns) const { return inside(vehicle_spans_, t_ns); }

void MotionClassifier::vehicle_sample(TimeNs t_ns, double acc_norm, const Eigen::Vector3d* gyro) {
  if (!opt_.vehicle) return;
  const TimeNs bin_ns = s_to_ns(opt_.vehicle_bin_s);
  if (bin_origin_ns_ < 0) bin_origin_ns_ = t_ns;
  const std::int64_t index = (t_ns - bin_origin_ns_) / bin_ns;
  if (index < cur_bin_index_) return;  // the other sensor's older sample: ignore it here
  if (cur_bin_index_ < 0) cur_bin_index_ = index;
  if (index > cur_bin_index_) {
    const std::size_t window_bins = static_cast<std::size_t>(std::lround(opt_.vehicle_window_s / opt_.vehicle_bin_s));
    if (static_cast<double>(index - cur_bin_index_) * opt_.vehicle_bin_s > opt_.gyro_timeout_s) {
      bins_.clear();  // a gap: the window restarts (the score and the state are kept)
    } else {
      for (std::int64_t k = cur_bin_index_; k < index; ++k) {
        // an empty bin (a late sensor) repeats the previous mean so the lag grid stays uniform
        Bin b = k == cur_bin_index_ ? cur_bin_ : Bin{};
        if (b.n == 0 && !bins_.empty()) {
          const Bin& p = bins_.back();
          if (p.n > 0) b.n = 1, b.sum = p.sum / p.n, b.sq = b.sum * b.sum;
        }
        bins_.push_back(b);
        if (bins_.size() > window_bins) bins_.pop_front();
        if (static_cast<double>(++bins_since_eval_) * opt_.vehicle_bin_s >= opt_.vehicle_eval_s - 1e-9 && bins_.size() == window_bins) {
          bins_since_eval_ = 0;
          vehicle_evaluate(bin_origin_ns_ + (k + 1) * bin_ns);
        }
      }
    }
    cur_bin_ = Bin{};
    cur_bin_index_ = index;
  }
  if (std::isfinite(acc_norm)) ++cur_bin_.n, cur_bin_.sum += acc_norm, cur_bin_.sq += acc_norm * acc_norm;
  if (gyro != nullptr) ++cur_bin_.gyro_n, cur_bin_.gyro_sq += gyro->squaredNorm(), cur_bin_.gyro_sum += *gyro;
}

void MotionClassifier::vehicle_evaluate(TimeNs t_ns) {
  const std::size_t n = bins_.size();
  // 1 s sub-windows: sigma of the raw |a| samples
  const std::size_t sub = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(1.0 / opt_.vehicle_bin_s)));
  double min_sigma = 1e300, max_sigma = 0.0;
  for (std::size_t a = 0; a + sub <= n; a += sub) {
    double cnt = 0, sum = 0, sq = 0;
    for (std::size_t i = a; i < a + sub; ++i) cnt += bins_[i].n, sum += bins_[i].sum, sq += bins_[i].sq;
    const double sigma = cnt > 1 ? std::sqrt(std::max(0.0, sq / cnt - (sum / cnt) * (sum / cnt))) : 0.0;
    min_sigma = std::min(min_sigma, sigma);
    max_sigma = std::max(max_sigma, sigma);
  }
  // normalised (Pearson) autocorrelation of the bin means over the gait lags
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = bins_[i].n > 0 ? bins_[i].sum / bins_[i].n : (i ? x[i - 1] : 0.0);
  const auto lag_min = static_cast<std::size_t>(std::lround(opt_.gait_lag_min_s / opt_.vehicle_bin_s));
  const auto lag_max = std::min(n - 2, static_cast<std::size_t>(std::lround(opt_.gait_lag_max_s / opt_.vehicle_bin_s)));
  const detail::BestLag periodic = detail::best_autocorrelation(x, lag_min, lag_max);
  const double corr = periodic.corr;
  const std::size_t best_lag = periodic.lag;
  gait_corr_ = corr;
  // gait coherence: the angular-rate vector (bin means) repeats at the |a| lag or twice it
  double coherence = 0.0;
  if (best_lag > 0 && opt_.running_min_coherence > 0.0) {
    std::vector<Eigen::Vector3d> w(n, Eigen::Vector3d::Zero());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      w[i] = bins_[i].gyro_n > 0 ? Eigen::Vector3d(bins_[i].gyro_sum / bins_[i].gyro_n) : (i ? w[i - 1] : w[i]);
      mean += w[i];
    }
    mean /= static_cast<double>(n);
    double var = 0.0;
    for (auto& v : w) v -= mean, var += v.squaredNorm();
    var /= static_cast<double>(n);
    const auto at_lag = [&](std::size_t lag) {
      if (lag >= n || var <= 1e-12) return -1.0;
      double r = 0.0;
      for (std::size_t i = 0; i + lag < n; ++i) r += w[i].dot(w[i + lag]);
      return r / static_cast<double>(n - lag) / var;
    };
    coherence = std::max(at_lag(best_lag), at_lag(2 * best_lag));
  }
  const double alpha = 1.0 - std::exp(-opt_.vehicle_eval_s / std::max(1e-3, opt_.running_coherence_tau_s));
  gait_coherence_ += alpha * (coherence - gait_coherence_);
  double gyro_cnt = 0, gyro_sq = 0;
  for (const Bin& b : bins_) gyro_cnt += b.gyro_n, gyro_sq += b.gyro_sq;
  const bool gyro_live = live(last_gyro_ns_, t_ns) && gyro_cnt >= 4;
  const double rate_rms = gyro_live ? std::sqrt(gyro_sq / gyro_cnt) : 0.0;

  if (vehicle_) {
    const bool gait = corr >= opt_.gait_exit_min && min_sigma >= opt_.gait_exit_sigma_mps2 &&
                      (!gyro_live || rate_rms >= opt_.gait_exit_rate_radps);
    if (gait) {
      vehicle_ = false;
      vehicle_score_s_ = 0.0;
      vehicle_spans_.back().t_end_ns = std::max(vehicle_spans_.back().t_start_ns, t_ns - s_to_ns(opt_.vehicle_exit_lookback_s));
    } else {
      vehicle_spans_.back().t_end_ns = t_ns;
    }
    return;
  }
  const bool evidence = corr < opt_.aperiodic_max && min_sigma >= opt_.vehicle_min_sigma_mps2 &&
                        max_sigma <= opt_.vehicle_max_sigma_mps2 && rate_rms <= opt_.vehicle_max_rate_radps;
  // kinematic evidence: a sustained horizontal acceleration while the phone turns slowly
  if (opt_.kinematic_min_mps2 > 0.0 && gyro_live && rate_rms <= opt_.vehicle_max_rate_radps && !kin_h_.empty() &&
      kin_h_.covered_s() >= 0.9 * opt_.kinematic_window_s) {
    const double a_h = kin_h_.sum().norm() / static_cast<double>(kin_h_.size());
    kinematic_max_mps2_ = std::max(kinematic_max_mps2_, a_h);
    if (a_h >= opt_.kinematic_min_mps2) kinematic_last_ns_ = t_ns;
  }
  if (evidence) {
    if (vehicle_score_s_ <= 0.0) evidence_start_ns_ = t_ns - s_to_ns(opt_.vehicle_window_s);
    vehicle_score_s_ += opt_.vehicle_eval_s;
  } else {
    vehicle_score_s_ = std::max(0.0, vehicle_score_s_ - opt_.vehicle_decay * opt_.vehicle_eval_s);
  }
  // no vehicle without a speed change or turn no walker makes (the score waits at the threshold
  // for one); without a gyroscope that evidence cannot be had, so the score never enters one
  const bool kinematic_ok = opt_.kinematic_min_mps2 <= 0.0 || kinematic_recent(t_ns);
  if (vehicle_score_s_ >= opt_.vehicle_enter_s && !kinematic_ok) vehicle_score_s_ = opt_.vehicle_enter_s;
  vehicle_max_score_s_ = std::max(vehicle_max_score_s_, vehicle_score_s_);
  if (vehicle_score_s_ >= opt_.vehicle_enter_s && kinematic_ok) {
    vehicle_ = true;
    vehicle_spans_.push_back(MotionSpan{evidence_start_ns_, t_ns, MotionState::kVehicle});
    if (vehicle_spans_.size() > 256) vehicle_spans_.pop_front();
  }
}

bool MotionClassifier::kinematic_recent(TimeNs t_ns) const {
  return kinematic_last_ns_ >= 0 && t_ns - kinematic_last_ns_ <= s_to_ns(opt_.kinematic_memory_s);
}

void MotionClassifier::kinematic_gyro(const GyroSample& s) {
  // a world-fixed vector seen from the turning phone: d up / dt = -omega x up
  if (kin_have_up_ && last_gyro_ns_ >= 0) {
    const double dt = ns_to_s(s.t_ns - last_gyro_ns_);
    if (dt > 0.0 && dt <= opt_.gyro_timeout_s) kin_up_ = (kin_up_ - dt * s.rate_radps.cross(kin_up_)).normalized();
  }
}

void MotionClassifier::kinematic_accel(const AccelSample& s) {
  if (opt_.kinematic_min_mps2 <= 0.0) return;
  const double m = s.acc_mps2.norm();
  if (!(m > 1.0)) return;  // free fall or a broken sample: no gravity direction
  const Eigen::Vector3d dir = s.acc_mps2 / m;
  const double dt = kin_acc_ns_ >= 0 ? ns_to_s(s.t_ns - kin_acc_ns_) : -1.0;
  kin_acc_ns_ = s.t_ns;
  // first sample, a gap, or no live gyroscope (the phone's turns can not be followed): gravity
  // restarts from the specific force and the window with it
  if (!kin_have_up_ || dt < 0.0 || dt > opt_.gyro_timeout_s || !live(last_gyro_ns_, s.t_ns)) {
    kin_up_ = dir;
    kin_have_up_ = true;
    kin_h_.clear();
    return;
  }
  // pulled toward the specific force with tau (the complementary filter of the tilt; gyro-propagated)
  kin_up_ = (kin_up_ + std::min(1.0, dt / opt_.kinematic_tilt_tau_s) * (dir - kin_up_)).normalized();
  kin_h_.push(s.t_ns, s.acc_mps2 - s.acc_mps2.dot(kin_up_) * kin_up_);
}

}  // namespace pdnav::pdr
